"""The installable zip dist/plume-<version>-linux-x64.zip (built by ``bash .ci/package``), tested
as an artist installs it, in a Blender whose user folders are empty temporary folders.

Run: blender_tests/run.py --blender {3.4,4.2,4.5,5.0,5.3} test_install_zip.py
The zip: $PLUME_ZIP, else the newest dist/plume-*-linux-x64.zip (none: every test fails).

- ZipLayoutTest (static, no Blender needed): an artist downloads one file and installs it in
  whichever Blender they run, 3.4 or 4.2 to 5.3, on any Linux from glibc 2.28 (Rocky 8) on. So the
  zip has one top folder plume/ that is both a 3.4 add-on (__init__.py with bl_info) and a 4.2+
  extension (blender_manifest.toml, Blender 4.2.0 up to a maximum above 5.3); one native module
  per CPython (3.11 for 3.4-5.0, 3.13 for 5.1-5.3), each self-contained (needs only glibc's own
  libraries, no search path, exports only PyInit__native, stripped) and asking for no glibc
  symbol version above 2.28; PLUME_BUILD.txt lists exactly the modules present; no lib/ folder.
  The floor check is itself shown to catch a Debian library that needs a newer glibc.
- IsolatedInstallTest: install_zip/installed_cases.py runs in the same Blender (``blender -b``
  or the bpy venv's Python) with BLENDER_USER_RESOURCES/SCRIPTS/CONFIG/EXTENSIONS/DATAFILES
  pointing at new empty folders (they must exist, or Blender falls back to ~/.config/blender), so
  the add-on installed by .ci/common.sh is invisible. There it installs the zip (3.4: Install
  add-on from file; 4.2+: Install from Disk into the "user_default" extension repository),
  enables it, checks that the add-on and the module for this Blender's Python come from the
  install and that no second OpenVDB / oneTBB / Blosc / OpenSubdiv is mapped (/proc/self/maps),
  bakes 32³ x 8 frames through plume.role_set / plume.bake and renders the last frame with
  Cycles. Each isolated test is reported here as one test.
- MissingModuleTest: an install that lacks the module for the artist's Python must say so in
  words, not fail with Python's bare "No module named plume._native". A copy of the zip without
  this Python's module (PLUME_BUILD.txt still listing it) is an incomplete install: "install
  plume-... again"; with the module also left out of PLUME_BUILD.txt it is a release that does
  not support this Python (as a future CPython 3.14 Blender meets): "this Blender runs Python
  3.X ... Use one of those Blenders". Checked in a clean plain CPython (env -i, each CPython
  of PYTHONS found here) and by installing and enabling those zips in an isolated Blender.

PNG renders: $PLUME_TEST_OUT (default /tmp/plume_test_out)/install_zip_<x.y.z>.png (and
_empty.png, the same frame without the smoke).
"""

import ast
import glob
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import zipfile

import bpy  # noqa: F401  (first, as inside Blender)

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "install_zip"))

import plume_zip  # noqa: E402  (the floor and ELF helpers .ci/package uses)
import pythons  # noqa: E402  (where each CPython is on this machine)
from helpers import run  # noqa: E402
from isolated import IsolatedRun  # noqa: E402

REPO = os.path.dirname(HERE)
#: The newest Blender the tests run: the manifest's (exclusive) maximum must be above it.
NEWEST_TESTED = (5, 3)
#: A Debian 12 library that needs a glibc newer than the floor (GLIBC_2.34), the first found.
NEWER_GLIBC_ELFS = ("/usr/lib/x86_64-linux-gnu/libopenvdb.so.10.0",
                    "/usr/lib/x86_64-linux-gnu/libblosc.so.1", "/usr/lib/x86_64-linux-gnu/libc.so.6")


def zip_path():
    """The zip under test, or None."""
    path = os.environ.get("PLUME_ZIP")
    if path:
        return path if os.path.isfile(path) else None
    found = glob.glob(os.path.join(REPO, "dist", "plume-*-linux-x64.zip"))
    return max(found, key=os.path.getmtime) if found else None


def require_zip(test):
    path = zip_path()
    if path is None:
        where = os.environ.get("PLUME_ZIP") or os.path.join(REPO, "dist", "plume-*-linux-x64.zip")
        test.fail(f"no installable zip ({where}): build it first with `bash .ci/package`")
    return path


def extract(zip_file, dest):
    """Extracts the zip, keeping the permission bits (zipfile drops them)."""
    with zipfile.ZipFile(zip_file) as zf:
        for info in zf.infolist():
            out = zf.extract(info, dest)
            mode = info.external_attr >> 16
            if mode and not info.is_dir():
                os.chmod(out, mode & 0o777)
    return dest


def version_tuple(text):
    return tuple(int(x) for x in text.split("."))


def fmt(version):
    return ".".join(str(x) for x in version)


def plain_python(version):
    """A plain CPython `version` (major, minor) on this machine, found as the bpy venvs' are
    (pythons.py: Debian's python3 for 3.11; $PLUME_PYTHON313, pyenv or PATH for 3.13), or None."""
    try:
        return pythons.python_for(fmt(version))
    except pythons.PythonNotFound as e:
        print(f"  no plain CPython {fmt(version)}: {e}")
        return None


def altered_zip(src, dst, drop_module, delist=False):
    """A copy of zip `src` at `dst` without the module file `drop_module`; with `delist` its
    PLUME_BUILD.txt no longer names it either (a release built without it)."""
    build_info = f"{plume_zip.PACKAGE}/{plume_zip.BUILD_INFO}"
    dropped = f"{plume_zip.PACKAGE}/{drop_module}"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        names = zin.namelist()
        assert dropped in names and build_info in names, names
        for info in zin.infolist():
            if info.filename == dropped:
                continue
            data = zin.read(info)
            if info.filename == build_info and delist:
                text = data.decode("utf-8")
                data = "".join(line for line in text.splitlines(True)
                               if line.strip() != f"module: {drop_module}").encode("utf-8")
                assert data != text.encode("utf-8")
            zout.writestr(info, data)
    return dst


# ---------------------------------------------------------------------------------------------
# Static checks of the zip.

class ZipLayoutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="plume_zip_static_")
        cls.zip = zip_path()
        if cls.zip:
            extract(cls.zip, cls.tmp)
        cls.pkg = os.path.join(cls.tmp, plume_zip.PACKAGE)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def elf_files(self):
        """Every ELF file of the package (relative path -> absolute path)."""
        out = {}
        for dirpath, _, files in os.walk(self.pkg):
            for name in files:
                path = os.path.join(dirpath, name)
                if not os.path.islink(path) and plume_zip.is_elf(path):
                    out[os.path.relpath(path, self.pkg)] = path
        return dict(sorted(out.items()))

    def bl_info(self):
        with open(os.path.join(self.pkg, "__init__.py"), encoding="utf-8") as f:
            tree = ast.parse(f.read())
        return next(ast.literal_eval(n.value) for n in tree.body if isinstance(n, ast.Assign)
                    and any(getattr(t, "id", None) == "bl_info" for t in n.targets))

    def manifest(self):
        import tomllib
        with open(os.path.join(self.pkg, "blender_manifest.toml"), "rb") as f:
            return tomllib.load(f)

    def test_one_top_folder_for_both_installers(self):
        path = require_zip(self)
        with zipfile.ZipFile(path) as zf:
            names = zf.namelist()
            infos = zf.infolist()
        print(f"  {path}: {os.path.getsize(path) / 1e6:.2f} MB, {len(names)} entries")
        self.assertEqual({n.split("/")[0] for n in names}, {"plume"}, "one top folder plume/")
        self.assertFalse([n for n in names if "__pycache__" in n or n.endswith(".pyc")])
        # No symbolic links (the extension installer and Windows unzip tools mishandle them).
        self.assertFalse([i.filename for i in infos if (i.external_attr >> 16) & 0o170000 ==
                          0o120000])
        # No lib/ folder of shared libraries any more: each module carries its own, statically.
        self.assertFalse([n for n in names if n.startswith("plume/lib/")], "a lib/ folder")
        # The manual the help buttons open (plume_manual.py; test_help.py checks its links).
        self.assertIn("plume/manual/index.html", names)
        # Blender 3.4 "Install add-on from file": a package folder whose __init__.py has bl_info.
        bl_info = self.bl_info()
        self.assertLessEqual(tuple(bl_info["blender"]), (3, 4, 0))
        # Blender 4.2+ "Install from Disk": exactly one blender_manifest.toml, in the single top
        # folder (bl_pkg's pkg_zipfile_detect_subdir_or_none accepts "<dir>/blender_manifest.toml";
        # with a manifest found the zip is never treated as a legacy add-on).
        manifests = [n for n in names if n.endswith("blender_manifest.toml")]
        self.assertEqual(manifests, ["plume/blender_manifest.toml"])
        manifest = self.manifest()
        self.assertEqual(manifest["id"], "plume")
        self.assertEqual(manifest["type"], "add-on")
        self.assertIn("linux-x64", manifest["platforms"])
        version = ".".join(str(v) for v in bl_info["version"])
        self.assertEqual(manifest["version"], version, "manifest and bl_info versions differ")
        self.assertEqual(os.path.basename(path), f"plume-{version}-linux-x64.zip")

    def test_manifest_blender_range(self):
        """Extensions install in 4.2.0 and every tested Blender up to 5.3 (the maximum is
        exclusive, so it must be above the newest tested)."""
        require_zip(self)
        manifest = self.manifest()
        print(f"  blender_version_min {manifest.get('blender_version_min')}, "
              f"blender_version_max {manifest.get('blender_version_max')}")
        self.assertEqual(manifest["blender_version_min"], "4.2.0")
        self.assertIn("blender_version_max", manifest)
        self.assertGreater(version_tuple(manifest["blender_version_max"]), NEWEST_TESTED)

    def test_native_modules_and_build_info(self):
        """One module per CPython of PYTHONS, and PLUME_BUILD.txt naming exactly those."""
        require_zip(self)
        natives = sorted(n for n in os.listdir(self.pkg) if n.startswith("_native"))
        expected = sorted(plume_zip.module_name(p) for p in plume_zip.PYTHONS)
        self.assertEqual(expected, ["_native.cpython-311-x86_64-linux-gnu.so",
                                    "_native.cpython-313-x86_64-linux-gnu.so"])
        self.assertEqual(natives, expected)
        with open(os.path.join(self.pkg, plume_zip.BUILD_INFO), encoding="utf-8") as f:
            lines = f.read().splitlines()
        print("  " + plume_zip.BUILD_INFO + ":\n" + "\n".join("    " + line for line in lines))
        self.assertEqual(lines[0], f"plume {self.manifest()['version']}")
        self.assertTrue(len(lines) >= 2 and lines[1].strip() and
                        not lines[1].startswith("module:"), "no build description line")
        self.assertEqual(plume_zip.build_info_modules(self.pkg), natives)
        self.assertEqual(sorted(line for line in lines if line.startswith("module:")),
                         [f"module: {n}" for n in natives])

    def test_every_elf_within_glibc_2_28_floor(self):
        require_zip(self)
        elfs = self.elf_files()
        self.assertTrue(elfs, "no ELF file in the package")
        for rel, path in elfs.items():
            needs = plume_zip.version_needs(path)
            print(f"  {rel}: highest " + (", ".join(f"{k}_{fmt(v)}" for k, v in sorted(
                needs.items())) or "none"))
            # Not vacuous: a module that needs no GLIBC version at all was misread.
            self.assertIn("GLIBC", needs, f"{rel}: no GLIBC version needed at all?")
            for family, v in needs.items():
                self.assertIn(family, plume_zip.VERSION_FLOOR, f"{rel}: needs {family}_{fmt(v)}")
                self.assertLessEqual(v, plume_zip.VERSION_FLOOR[family],
                                     f"{rel}: needs {family}_{fmt(v)}")
            self.assertNotIn("GLIBCXX", needs, f"{rel}: needs libstdc++ (libc++ is static)")

    def test_self_contained(self):
        require_zip(self)
        elfs = self.elf_files()
        # The modules are the only ELF files (no bundled shared library).
        self.assertEqual(sorted(elfs), sorted(plume_zip.module_name(p) for p in plume_zip.PYTHONS))
        for rel, path in elfs.items():
            info = plume_zip.elf_dynamic(path)
            exports = plume_zip.dynamic_exports(path)
            extra = sorted(exports - plume_zip.EXPORTS)
            print(f"  {rel}: NEEDED {', '.join(info['needed'])}; exports "
                  f"{sorted(exports & plume_zip.EXPORTS)} and {len(extra)} other symbols")
            self.assertIn("libc.so.6", info["needed"], rel)
            self.assertLessEqual(set(info["needed"]), plume_zip.SYSTEM_LIBS, rel)
            self.assertEqual(info["runpath"], [], rel)
            self.assertEqual(info["rpath"], [], rel)
            self.assertIn("PyInit__native", exports, rel)
            self.assertEqual(extra[:5], [], f"{rel} exports {len(extra)} other symbols")
            sections = subprocess.run(["readelf", "-S", "-W", path], capture_output=True,
                                      text=True, check=True).stdout
            self.assertIn(".dynsym", sections, rel)
            self.assertNotIn(".symtab", sections, f"{rel} is not stripped")

    def test_check_tree_clean(self):
        """What .ci/package checks before zipping finds nothing in the zip either."""
        require_zip(self)
        problems, report = plume_zip.check_tree(self.pkg)
        self.assertEqual(sorted(report), sorted(self.elf_files()))
        self.assertEqual(problems, [])

    def test_floor_check_catches_newer_glibc(self):
        """check_elf flags an ELF file that needs a glibc above 2.28 (a Debian 12 library, built
        against glibc 2.36): the floor checks above can fail."""
        path = next((p for p in NEWER_GLIBC_ELFS if os.path.isfile(p) and
                     plume_zip.version_needs(p).get("GLIBC", ()) > plume_zip.VERSION_FLOOR["GLIBC"]),
                    None)
        self.assertIsNotNone(path, f"none of {NEWER_GLIBC_ELFS} needs a glibc above 2.28")
        needs = plume_zip.version_needs(path)["GLIBC"]
        problems = plume_zip.check_elf(path)
        floor = [p for p in problems if "above the floor" in p]
        print(f"  {path}: needs GLIBC_{fmt(needs)}; check_elf: {floor}")
        self.assertTrue(any(f"GLIBC_{fmt(needs)}" in p for p in floor), problems)


# ---------------------------------------------------------------------------------------------
# The isolated Blender (install_zip/installed_cases.py): install, load, bake, render.

class IsolatedInstallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.run_ = IsolatedRun(zip_path(), "InstalledAddonTest") if zip_path() else None

    @classmethod
    def tearDownClass(cls):
        if cls.run_:
            cls.run_.cleanup()

    def check(self, name):
        require_zip(self)
        self.run_.check(self, name)

    def test_installed_into_empty_user_folders(self):
        self.check("test_1_installed_into_empty_user_folders")

    def test_native_module_from_install(self):
        self.check("test_2_native_module_from_install")

    def test_no_second_openvdb_or_tbb(self):
        self.check("test_3_no_second_openvdb_or_tbb")

    def test_bake_and_render_from_installed_addon(self):
        self.check("test_4_bake_and_render_from_installed_addon")

    def test_isolated_blender_exit_code(self):
        require_zip(self)
        self.assertEqual(self.run_.rc, 0, "the isolated Blender failed; its output is above")


# ---------------------------------------------------------------------------------------------
# No module for the artist's Python.

class MissingModuleTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="plume_zip_missing_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def import_native(self, python, package_dir):
        """(stdout, last stderr line, stderr) of ``import plume.native`` from `package_dir` in
        a clean plain CPython (env -i; the package's __init__, which needs bpy, is not run)."""
        code = ("import os, sys, types; pkg = types.ModuleType('plume'); "
                f"pkg.__path__ = [{package_dir!r}]; sys.modules['plume'] = pkg; "
                "import plume.native; "
                "print('loaded', os.path.basename(plume.native._native.__file__))")
        proc = subprocess.run(["env", "-i", "PATH=/usr/bin:/bin", python, "-c", code],
                              capture_output=True, text=True, timeout=120)
        lines = proc.stderr.strip().splitlines()
        return proc.stdout.strip(), lines[-1] if lines else "", proc.stderr

    def check_plain_python(self, python):
        """For CPython `python`: the intact package loads its module; without it, with
        PLUME_BUILD.txt listing it, the ImportError says the install is incomplete; delisted
        too, it says which Python this is and which ones Plume is built for. This Blender's
        CPython must be found here (Debian's 3.11 is); another one missing skips."""
        zip_file = require_zip(self)
        exe = plain_python(python)
        print(f"  plain CPython {fmt(python)}: {exe}")
        if exe is None:  # the portable build needs both CPythons too: never skipped
            self.fail(f"no plain CPython {fmt(python)} on this machine "
                      "(blender_tests/pythons.py says where it looked)")
        mine = plume_zip.module_name(python)
        others = [p for p in plume_zip.PYTHONS if p != python]
        out, last, _ = self.import_native(exe, extract(zip_file, os.path.join(
            self.tmp, f"{fmt(python)}-intact")) + "/plume")
        print(f"  {fmt(python)} intact: {out or last}")
        self.assertEqual(out, f"loaded {mine}")
        for kind, delist in (("incomplete", False), ("unsupported", True)):
            broken = altered_zip(zip_file, os.path.join(self.tmp, f"{kind}.zip"), mine,
                                 delist)
            pkg = os.path.join(extract(broken, os.path.join(
                self.tmp, f"{fmt(python)}-{kind}")), "plume")
            out, last, err = self.import_native(exe, pkg)
            print(f"  {fmt(python)} {kind}: {last}")
            self.assertEqual(out, "")
            self.assertIn(f'File "{pkg}/native.py"', err)
            self.assertTrue(last.startswith("ImportError: Plume: "), last)
            if kind == "incomplete":
                self.assertIn("is incomplete", last)
                self.assertIn(mine, last)
                self.assertIn("install plume-", last)
            else:
                self.assertIn(f"this Blender runs Python {fmt(python)}", last)
                for other in others:
                    self.assertIn(f"Python {fmt(other)} (", last)
                self.assertIn("Use one of those Blenders", last)

    def enable_in_blender(self, method, delist):
        zip_file = require_zip(self)
        broken = altered_zip(zip_file, os.path.join(self.tmp, os.path.basename(zip_file)),
                             plume_zip.module_name(sys.version_info[:2]), delist)
        run_ = IsolatedRun(broken, f"BrokenInstallTest.{method}")
        try:
            run_.check(self, method)
            self.assertEqual(run_.rc, 0)
        finally:
            run_.cleanup()

    def test_enable_in_blender_reports_incomplete_install(self):
        """The zip without this Blender's module, PLUME_BUILD.txt still listing it."""
        self.enable_in_blender("test_enable_reports_incomplete_install", delist=False)

    def test_enable_in_blender_reports_unsupported_python(self):
        """The zip of a release built without a module for this Blender's Python."""
        self.enable_in_blender("test_enable_reports_unsupported_python", delist=True)


for _python in plume_zip.PYTHONS:  # test_plain_cpython_3_11_import_errors, ..._3_13_...
    setattr(MissingModuleTest, f"test_plain_cpython_{_python[0]}_{_python[1]}_import_errors",
            lambda self, python=_python: self.check_plain_python(python))


# ---------------------------------------------------------------------------------------------

if __name__ == "__main__":
    run(ZipLayoutTest, IsolatedInstallTest, MissingModuleTest)
