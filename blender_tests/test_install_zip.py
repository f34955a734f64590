"""The installable zip dist/plume-<version>-linux-x64.zip (built by ``bash .ci/package``), tested
as an artist installs it, in a Blender whose user folders are empty temporary folders.

Run: blender_tests/run.py --blender {3.4,4.5,5.0} test_install_zip.py
The zip: $PLUME_ZIP, else the newest dist/plume-*-linux-x64.zip (none: every test fails).

- ZipLayoutTest (static, no Blender needed): one top folder plume/ that is both a 3.4 add-on
  (__init__.py with bl_info) and a 4.2+ extension (blender_manifest.toml); every NEEDED entry of
  every .so inside resolves inside the zip through RUNPATH ($ORIGIN/lib, $ORIGIN) or is on the
  system allow-list of blender_tests/install_zip/plume_zip.py.
- IsolatedInstallTest: install_zip/installed_cases.py runs in the same Blender (``blender
  -b`` or the bpy venv's Python) with BLENDER_USER_RESOURCES/SCRIPTS/CONFIG/EXTENSIONS/DATAFILES pointing at
  new empty folders (they must exist, or Blender falls back to ~/.config/blender), so the add-on
  installed by .ci/common.sh is invisible. There it installs the zip (3.4: Install add-on from
  file; 4.2+: Install from Disk into the "user_default" extension repository), enables it,
  checks where the add-on, _native and each bundled library were loaded from
  (/proc/self/maps), bakes 32³ x 8 frames through plume.role_set / plume.bake and renders the
  last frame with Cycles. Each isolated test is reported here as one test.
- MissingLibraryTest: a copy of the package with lib/libblosc.so.1 removed (and the libraries
  needing it told to ignore the system's copy, see the class) fails to load _native with an
  ImportError naming libblosc.so.1 (/usr/bin/python3, env -i); installed from a zip and enabled
  in an isolated Blender, the reported error names it too (Debian's 3.4.1 already holds the
  system libblosc, so there the add-on enables, which is asserted instead).

PNG renders: $PLUME_TEST_OUT (default /tmp/plume_test_out)/install_zip_<x.y.z>.png (and
_empty.png, the same frame without the smoke).
"""

import ast
import glob
import os
import re
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

import plume_zip  # noqa: E402  (the allow-list and ELF helpers .ci/package uses)
from helpers import run  # noqa: E402
from isolated import MISSING_LIB, IsolatedRun  # noqa: E402

REPO = os.path.dirname(HERE)
SYSTEM_PYTHON = "/usr/bin/python3"


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
        # Blender 3.4 "Install add-on from file": a package folder whose __init__.py has bl_info.
        with open(os.path.join(self.pkg, "__init__.py"), encoding="utf-8") as f:
            tree = ast.parse(f.read())
        bl_info = next(ast.literal_eval(n.value) for n in tree.body if isinstance(n, ast.Assign)
                       and any(getattr(t, "id", None) == "bl_info" for t in n.targets))
        self.assertLessEqual(tuple(bl_info["blender"]), (3, 4, 0))
        # Blender 4.2+ "Install from Disk": exactly one blender_manifest.toml, in the single top
        # folder (bl_pkg's pkg_zipfile_detect_subdir_or_none accepts "<dir>/blender_manifest.toml";
        # with a manifest found the zip is never treated as a legacy add-on).
        manifests = [n for n in names if n.endswith("blender_manifest.toml")]
        self.assertEqual(manifests, ["plume/blender_manifest.toml"])
        import tomllib
        with open(os.path.join(self.pkg, "blender_manifest.toml"), "rb") as f:
            manifest = tomllib.load(f)
        self.assertEqual(manifest["id"], "plume")
        self.assertEqual(manifest["type"], "add-on")
        self.assertIn("linux-x64", manifest["platforms"])
        version = ".".join(str(v) for v in bl_info["version"])
        self.assertEqual(manifest["version"], version, "manifest and bl_info versions differ")
        self.assertEqual(os.path.basename(path), f"plume-{version}-linux-x64.zip")
        natives = [n for n in names if re.fullmatch(r"plume/_native[^/]*\.so", n)]
        self.assertEqual(natives, ["plume/_native.cpython-311-x86_64-linux-gnu.so"])

    def test_needed_entries_resolve_inside_zip_or_allow_list(self):
        require_zip(self)
        problems, report = plume_zip.check_tree(self.pkg)
        for rel, r in sorted(report.items()):
            bundled = sorted(k for k, v in r["resolved"].items() if v not in (None, "(system)"))
            system = sorted(k for k, v in r["resolved"].items() if v == "(system)")
            print(f"  {rel}: RUNPATH {':'.join(r['runpath']) or '-'}; bundled {bundled}; "
                  f"system {system}")
        self.assertEqual(problems, [])
        libs = sorted(os.listdir(os.path.join(self.pkg, plume_zip.LIB_DIR)))
        self.assertIn("libopenvdb.so.10.0", libs)
        self.assertFalse(set(libs) & plume_zip.SYSTEM_LIBS, "allow-listed library bundled")
        # Nothing bundled that nothing needs, and each file carries the SONAME it is named by.
        needed = {s for r in report.values() for s in r["needed"]}
        self.assertEqual(set(libs) - needed, set())
        for name in libs:
            self.assertEqual(report[os.path.join(plume_zip.LIB_DIR, name)]["soname"], name)

    def test_runpath_values(self):
        require_zip(self)
        native = glob.glob(os.path.join(self.pkg, "_native*.so"))[0]
        info = plume_zip.elf_dynamic(native)
        self.assertEqual(info["runpath"], [plume_zip.NATIVE_RUNPATH])
        self.assertEqual(info["rpath"], [])
        libs = glob.glob(os.path.join(self.pkg, plume_zip.LIB_DIR, "*"))
        self.assertTrue(libs)
        for lib in libs:
            info = plume_zip.elf_dynamic(lib)
            self.assertEqual(info["runpath"], [plume_zip.LIB_RUNPATH], lib)
            self.assertEqual(info["rpath"], [], lib)
            sections = subprocess.run(["readelf", "-S", "-W", lib], capture_output=True,
                                      text=True).stdout
            self.assertNotIn(".symtab", sections, f"{lib} is not stripped")


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

    def test_each_bundled_library_mapped_once(self):
        self.check("test_3_each_bundled_library_mapped_once")

    def test_bake_and_render_from_installed_addon(self):
        self.check("test_4_bake_and_render_from_installed_addon")

    def test_isolated_blender_exit_code(self):
        require_zip(self)
        self.assertEqual(self.run_.rc, 0, "the isolated Blender failed; its output is above")


# ---------------------------------------------------------------------------------------------
# A missing bundled library.

class MissingLibraryTest(unittest.TestCase):
    """On this build machine the Debian copy of every bundled library exists, and the loader
    falls back to it (ld.so.cache, /lib) when a bundled one is missing: that would hide the
    failure an artist without those packages sees. The broken copy therefore also marks the
    libraries that need the removed one with DF_1_NODEFLIB (``patchelf --no-default-lib``): the
    loader then skips ld.so.cache and the default folders for their dependencies, as on a machine
    without the system library, and only their RUNPATH ($ORIGIN) is searched. A control copy with
    the same flag and nothing removed must load, so the flag alone breaks nothing."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="plume_zip_missing_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def package_copy(self, name, remove):
        """The zip extracted into <tmp>/<name>/plume, altered as described above."""
        root = os.path.join(self.tmp, name)
        extract(require_zip(self), root)
        lib_dir = os.path.join(root, plume_zip.PACKAGE, plume_zip.LIB_DIR)
        dependents = [p for p in glob.glob(os.path.join(lib_dir, "*")) +
                      glob.glob(os.path.join(root, plume_zip.PACKAGE, "_native*.so"))
                      if MISSING_LIB in plume_zip.elf_dynamic(p)["needed"]]
        self.assertTrue(dependents, f"nothing needs {MISSING_LIB}")
        for p in dependents:
            subprocess.run(["patchelf", "--no-default-lib", p], check=True)
        if remove:
            os.remove(os.path.join(lib_dir, MISSING_LIB))
        return root

    def load_native(self, root):
        """The last stderr line of loading plume._native from `root` in a clean
        /usr/bin/python3 (the package's __init__, which needs bpy, is not run), or "loaded"."""
        code = ("import sys, types; pkg = types.ModuleType('plume'); "
                f"pkg.__path__ = [{os.path.join(root, plume_zip.PACKAGE)!r}]; "
                "sys.modules['plume'] = pkg; import plume._native; print('loaded')")
        proc = subprocess.run(["env", "-i", "PATH=/usr/bin:/bin", SYSTEM_PYTHON, "-c", code],
                              capture_output=True, text=True, timeout=120)
        lines = (proc.stderr.strip() or proc.stdout.strip()).splitlines()
        return lines[-1] if lines else f"rc {proc.returncode}, no output"

    def test_loader_error_names_missing_library(self):
        """The dynamic loader's ImportError, which the add-on's __init__ passes on."""
        require_zip(self)
        last = self.load_native(self.package_copy("control", remove=False))
        print(f"  control (nothing removed): {last}")
        self.assertEqual(last, "loaded")
        last = self.load_native(self.package_copy("broken", remove=True))
        print(f"  {MISSING_LIB} removed: {last}")
        self.assertTrue(last.startswith("ImportError: "), last)
        self.assertIn(f"{MISSING_LIB}: cannot open shared object file", last)

    def test_enable_in_blender_reports_missing_library(self):
        """An artist installs a zip that lacks the library and enables it: the error names it
        (except in Debian's 3.4.1, which already holds the system copy; asserted there)."""
        require_zip(self)
        root = self.package_copy("broken_zip", remove=True)
        broken = os.path.join(self.tmp, os.path.basename(require_zip(self)))
        subprocess.run(["zip", "-q", "-r", "-X", broken, plume_zip.PACKAGE], cwd=root, check=True)
        run_ = IsolatedRun(broken, "BrokenInstallTest")
        try:
            run_.check(self, "test_enable_reports_missing_library")
            self.assertEqual(run_.rc, 0)
        finally:
            run_.cleanup()


# ---------------------------------------------------------------------------------------------

if __name__ == "__main__":
    run(ZipLayoutTest, IsolatedInstallTest, MissingLibraryTest)
