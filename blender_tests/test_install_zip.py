"""The installable zip dist/plume-<version>-linux-x64.zip (built by ``bash .ci/package``), tested
as an artist installs it, in a Blender whose user folders are empty temporary folders.

Run: blender_tests/run.py --blender {3.4,4.5,5.0} test_install_zip.py
The zip: $PLUME_ZIP, else the newest dist/plume-*-linux-x64.zip (none: every test fails).

- ZipLayoutTest (static, no Blender needed): one top folder plume/ that is both a 3.4 add-on
  (__init__.py with bl_info) and a 4.2+ extension (blender_manifest.toml); every NEEDED entry of
  every .so inside resolves inside the zip through RUNPATH ($ORIGIN/lib, $ORIGIN) or is on the
  system allow-list of blender_tests/install_zip/plume_zip.py.
- IsolatedInstallTest: this file re-runs itself in the same Blender (``blender -b`` or the bpy
  venv's Python) with BLENDER_USER_RESOURCES/SCRIPTS/CONFIG/EXTENSIONS/DATAFILES pointing at
  new empty folders (they must exist, or Blender falls back to ~/.config/blender), so the add-on
  installed by .ci/common.sh is invisible. There it installs the zip (3.4: Install add-on from
  file; 4.2+: Install from Disk into the "user_default" extension repository), enables it,
  checks where the add-on, _native and each bundled library were loaded from
  (/proc/self/maps), bakes 32³ x 8 frames through plume.role_set / plume.bake and renders the
  last frame with Cycles. Each isolated test is reported here as one test.
- MissingLibraryTest: a copy of the package with lib/libblosc.so.1 removed fails to import with
  an ImportError naming libblosc.so.1 (/usr/bin/python3, env -i).

PNG renders: $PLUME_TEST_OUT (default /tmp/plume_test_out)/install_zip_<x.y.z>.png (and
_empty.png, the same frame without the smoke).
"""

import ast
import glob
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
import unittest
import zipfile

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "install_zip"))

import plume_zip  # noqa: E402  (the allow-list and ELF helpers .ci/package uses)

REPO = os.path.dirname(HERE)
OUT_DIR = os.environ.get("PLUME_TEST_OUT", "/tmp/plume_test_out")
#: Set (to the results file) in the re-launched, isolated Blender.
ISOLATED_ENV = "PLUME_ZIP_ISOLATED"
VERSION = "%d.%d.%d" % bpy.app.version[:3]
#: Bake and render of the installed add-on: small, the machine has 2 cores.
RESOLUTION = 32
FRAMES = 8
SAMPLES = 8
#: As test_bake.py: mean |render - render without the smoke| over pixels and RGB must exceed half
#: an 8-bit level, and 1 % of the pixels must change by more than 4/255, or the smoke is missing.
MIN_MEAN_ABS_DIFF = 0.002
MIN_CHANGED_SHARE = 0.01
#: Libraries whose Debian system copies must not be the ones _native uses when Blender does not
#: already hold that soname (the bpy builds).
KEY_LIBS = ("libopenvdb.so.10.0", "libosdCPU.so.3.5.0", "libblosc.so.1", "liblog4cplus-2.0.so.3")
#: Removed from a copy of the package to check the error a missing library gives.
MISSING_LIB = "libblosc.so.1"
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


def debian_blender():
    """Debian's packaged Blender executable (links the system OpenVDB, TBB, OpenSubdiv...)."""
    return bool(bpy.app.binary_path) and bpy.app.version < (4, 2, 0)


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
# The isolated Blender: install, load, bake, render. Runs only when ISOLATED_ENV is set.

def mapped_files():
    """Real paths of every file mapped into this process."""
    with open("/proc/self/maps") as f:
        return {parts[5] for parts in (line.rstrip("\n").split(None, 5) for line in f)
                if len(parts) == 6 and parts[5].startswith("/")}


_soname_cache = {}


def soname_of(path):
    if path not in _soname_cache:
        try:
            _soname_cache[path] = plume_zip.elf_dynamic(path)["soname"]
        except plume_zip.PackagingError:
            _soname_cache[path] = None
    return _soname_cache[path]


def mapped_by_soname(files, sonames):
    """{soname: sorted paths} of the mapped files that carry one of `sonames`."""
    out = {s: [] for s in sonames}
    for path in sorted(files):
        base = os.path.basename(path)
        for s in sonames:
            if base.startswith(s.split(".so")[0] + ".so") and soname_of(path) == s:
                out[s].append(path)
    return out


def image_pixels(path):
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return px.reshape(h, w, 4)


def select_only(ob):
    vl = bpy.context.view_layer
    for o in vl.objects:
        o.select_set(False)
    if ob is not None:
        ob.select_set(True)
    vl.objects.active = ob


class InstalledAddonTest(unittest.TestCase):
    """Runs inside the isolated Blender; ordered by name (each needs the install)."""

    @classmethod
    def setUpClass(cls):
        import addon_utils
        cls.root = os.environ["PLUME_ZIP_ROOT"]
        cls.zip = os.environ["PLUME_ZIP_UNDER_TEST"]
        cls.user_paths_before = list(addon_utils.paths())
        import importlib.util
        cls.plume_importable_before = importlib.util.find_spec("plume") is not None
        cls.addons_before = {a.module for a in bpy.context.preferences.addons}
        cls.maps_before = mapped_files()
        cls.install_error = None
        t0 = time.perf_counter()
        try:
            if bpy.app.version < (4, 2, 0):
                cls.install_result = bpy.ops.preferences.addon_install(filepath=cls.zip)
                cls.enable_result = bpy.ops.preferences.addon_enable(module="plume")
            else:
                cls.install_result = bpy.ops.extensions.package_install_files(
                    filepath=cls.zip, repo="user_default", enable_on_install=True)
                cls.enable_result = None
        except Exception:
            cls.install_error = traceback.format_exc()
        cls.install_seconds = time.perf_counter() - t0
        print(f"  install + enable took {cls.install_seconds:.2f} s")
        cls.maps_after = mapped_files()
        new = {a.module for a in bpy.context.preferences.addons} - cls.addons_before
        cls.module_name = next((m for m in new if m.split(".")[-1] == "plume"), None)
        cls.module = sys.modules.get(cls.module_name) if cls.module_name else None

    def require_installed(self):
        if self.install_error:
            self.fail(f"installing {self.zip} failed:\n{self.install_error}")
        if self.module is None:
            self.fail(f"no plume add-on enabled after installing {self.zip}")

    def inside_root(self, path):
        return os.path.commonpath([os.path.realpath(path), os.path.realpath(self.root)]) == \
            os.path.realpath(self.root)

    def test_1_installed_into_empty_user_folders(self):
        # The regular installation (~/.config/blender/<x.y>/scripts/addons/plume) is invisible.
        print("  add-on paths before install:", self.user_paths_before)
        self.assertFalse([p for p in self.user_paths_before if ".config/blender" in p])
        self.assertFalse(self.plume_importable_before, "a plume package was importable before")
        self.require_installed()
        self.assertEqual(self.install_result, {'FINISHED'})
        if bpy.app.version < (4, 2, 0):
            self.assertEqual(self.enable_result, {'FINISHED'})
            self.assertEqual(self.module_name, "plume")
        else:  # installed as an extension, not as a legacy add-on
            self.assertEqual(self.module_name, "bl_ext.user_default.plume")
        print(f"  enabled {self.module_name} from {self.module.__file__}")
        self.assertTrue(self.inside_root(self.module.__file__), self.module.__file__)
        # The operators an artist clicks are the installed module's.
        cls = bpy.types.Operator.bl_rna_get_subclass_py(bpy.ops.plume.bake.idname())
        self.assertTrue(cls.__module__.startswith(self.module_name + "."), cls.__module__)

    def test_2_native_module_from_install(self):
        self.require_installed()
        native = self.module._native
        print(f"  _native: {native.__file__}")
        self.assertTrue(self.inside_root(native.__file__), native.__file__)
        self.assertEqual(os.path.dirname(native.__file__), os.path.dirname(self.module.__file__))
        self.assertTrue(os.path.realpath(native.__file__) in self.maps_after,
                        "_native is not mapped from its install folder")

    def test_3_each_bundled_library_mapped_once(self):
        """Each bundled soname is mapped from exactly one file after enabling: the install's own
        copy, unless the process already held that soname before (the loader then reuses it and
        never opens ours; no second copy of a soname is loaded)."""
        self.require_installed()
        lib_dir = os.path.join(os.path.dirname(self.module.__file__), plume_zip.LIB_DIR)
        sonames = sorted(os.listdir(lib_dir))
        before = mapped_by_soname(self.maps_before, sonames)
        after = mapped_by_soname(self.maps_after, sonames)
        ours, reused = [], []
        for s in sonames:
            print(f"  {s:30s} before: {before[s] or '-'}  after: {after[s]}")
            self.assertEqual(len(after[s]), 1, f"{s} mapped {len(after[s])} times: {after[s]}")
            if before[s]:
                self.assertEqual(after[s], before[s], f"{s} changed")
                reused.append(s)
            else:
                self.assertEqual(after[s], [os.path.realpath(os.path.join(lib_dir, s))])
                ours.append(s)
        print(f"  bundled copies in use: {ours}")
        print(f"  already in the process, reused: {reused}")
        system = [p for s in KEY_LIBS for p in after[s]
                  if p.startswith(("/usr/lib", "/lib"))]
        if debian_blender():
            # Debian's 3.4.1 itself links the system OpenVDB 10 / OpenSubdiv / Blosc / log4cplus
            # (and every other bundled soname): the bundle is inert there, and no second copy of
            # any of them is loaded.
            self.assertEqual(ours, [])
            self.assertEqual(len(system), len(KEY_LIBS), system)
        else:
            # The bpy builds carry other sonames (OpenVDB 12, OpenSubdiv 3.6): the key libraries
            # come from the install, never from the Debian system.
            self.assertEqual(system, [])
            self.assertTrue(set(KEY_LIBS) <= set(ours), ours)

    def test_4_bake_and_render_from_installed_addon(self):
        self.require_installed()
        import numpy as np
        for ob in list(bpy.data.objects):
            bpy.data.objects.remove(ob, do_unlink=True)
        cache = os.path.join(self.root, "cache")
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(0.0, 0.0, 0.35))
        source = bpy.context.active_object
        self.assertEqual(bpy.ops.plume.role_set(role='SOURCE'), {'FINISHED'})
        source.hide_render = True
        bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
        dom = bpy.context.active_object
        dom.name = "Domain"
        self.assertEqual(bpy.ops.plume.role_set(role='DOMAIN'), {'FINISHED'})
        d = dom.plume.domain
        d.resolution = RESOLUTION
        d.frame_start, d.frame_end = 1, FRAMES
        d.cache_directory = cache + "/"
        select_only(dom)
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        print(f"  bake {RESOLUTION}^3 x {FRAMES} frames took {time.perf_counter() - t0:.2f} s")
        vdbs = sorted(n for n in os.listdir(os.path.join(cache, "Domain")) if n.endswith(".vdb"))
        self.assertEqual(len(vdbs), FRAMES, vdbs)
        smoke = bpy.data.objects[d.volume_object]
        self.assertEqual(smoke.type, 'VOLUME')

        scene = bpy.context.scene
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scene.collection.objects.link(cam)
        cam.location = (0.0, -3.6, 0.9)
        cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
        scene.camera = cam
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
        sun.data.energy = 4.0
        sun.rotation_euler = (math.radians(40.0), math.radians(20.0), math.radians(-30.0))
        scene.collection.objects.link(sun)
        scene.render.engine = 'CYCLES'
        scene.cycles.device = 'CPU'
        scene.cycles.samples = SAMPLES
        scene.cycles.use_denoising = False
        scene.render.resolution_x, scene.render.resolution_y = 160, 120
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = 'PNG'
        scene.frame_set(FRAMES)
        self.assertTrue(smoke.data.grids.load(), smoke.data.grids.error_message)
        os.makedirs(OUT_DIR, exist_ok=True)
        paths = {}
        for visible in (True, False):
            smoke.hide_render = not visible
            path = os.path.join(OUT_DIR, f"install_zip_{VERSION}{'' if visible else '_empty'}.png")
            scene.render.filepath = path
            t0 = time.perf_counter()
            bpy.ops.render.render(write_still=True)
            print(f"  render ({'with' if visible else 'without'} smoke) took "
                  f"{time.perf_counter() - t0:.2f} s -> {path}")
            paths[visible] = path
        a = image_pixels(paths[True])[..., :3]
        b = image_pixels(paths[False])[..., :3]
        diff = np.abs(a - b)
        mean = float(diff.mean())
        changed = float((diff.max(axis=2) > 4.0 / 255.0).mean())
        print(f"  mean |smoke - empty| = {mean:.4f}, changed pixels = {changed:.1%}")
        self.assertGreater(mean, MIN_MEAN_ABS_DIFF)
        self.assertGreater(changed, MIN_CHANGED_SHARE)
        self.assertLess(float(a.mean()), 0.95, "render is white")


class BrokenInstallTest(unittest.TestCase):
    """Runs inside an isolated Blender given a zip whose lib/ lacks MISSING_LIB (and whose
    libraries needing it ignore the system's folders, see MissingLibraryTest)."""

    def test_enable_reports_missing_library(self):
        root = os.environ["PLUME_ZIP_ROOT"]
        zip_file = os.environ["PLUME_ZIP_UNDER_TEST"]
        before = {a.module for a in bpy.context.preferences.addons}
        maps_before = mapped_files()
        error = ""
        try:
            if bpy.app.version < (4, 2, 0):
                self.assertEqual(bpy.ops.preferences.addon_install(filepath=zip_file),
                                 {'FINISHED'})
                bpy.ops.preferences.addon_enable(module="plume")
            else:
                bpy.ops.extensions.package_install_files(
                    filepath=zip_file, repo="user_default", enable_on_install=True)
        except RuntimeError as e:  # an operator's {'ERROR'} report
            error = str(e)
        enabled = [m for m in {a.module for a in bpy.context.preferences.addons} - before
                   if m.split(".")[-1] == "plume"]
        print(f"  enabled: {enabled}; reported error: {error.strip().splitlines()[-1:]}")
        blosc = mapped_by_soname(mapped_files(), [MISSING_LIB])[MISSING_LIB]
        if mapped_by_soname(maps_before, [MISSING_LIB])[MISSING_LIB]:
            # Debian's 3.4.1 already holds the system's libopenvdb/libblosc: the loader never
            # looks for the bundled ones, and the add-on works without them.
            print(f"  {MISSING_LIB} was already loaded by Blender: {blosc}")
            self.assertTrue(debian_blender())
            self.assertEqual(len(enabled), 1, error)
            self.assertEqual(error, "")
        else:
            self.assertEqual(enabled, [], "the add-on enabled without " + MISSING_LIB)
            self.assertIn(f"{MISSING_LIB}: cannot open shared object file", error)
            self.assertIn("Plume: the native module _native cannot be loaded", error)
            self.assertEqual(blosc, [])
        self.assertTrue(root)


class _Recorder(unittest.TextTestResult):
    """Also keeps {test method name: (outcome, details)} for the parent process."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.outcomes = {}

    def addSuccess(self, test):
        super().addSuccess(test)
        self.outcomes[test._testMethodName] = ("pass", "")

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.outcomes[test._testMethodName] = ("fail", self.failures[-1][1])

    def addError(self, test, err):
        super().addError(test, err)
        if isinstance(test, unittest.TestCase):
            self.outcomes[test._testMethodName] = ("error", self.errors[-1][1])
        else:  # setUpClass
            self.outcomes["setUpClass"] = ("error", self.errors[-1][1])


def run_isolated(results_file, case):
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(case)
    runner = unittest.TextTestRunner(stream=sys.stdout, verbosity=2, resultclass=_Recorder)
    result = runner.run(suite)
    with open(results_file, "w") as f:
        json.dump(result.outcomes, f, indent=1)
    failed = len(result.failures) + len(result.errors)
    print(f"[isolated Blender {VERSION}] {result.testsRun - failed} of {result.testsRun} "
          "passed", flush=True)
    sys.exit(0 if failed == 0 else 1)


# ---------------------------------------------------------------------------------------------
# The parent side of the isolated Blender.

def isolated_command(script):
    """This Blender, headless and with factory settings, running `script`."""
    if bpy.app.binary_path and os.path.basename(bpy.app.binary_path).startswith("blender"):
        return [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                "--python", script]
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [sys.executable, "-c", boot, script]


class IsolatedRun:
    """This file re-run in this Blender with new empty user folders under `root`, installing
    `zip_file` and running the TestCase named `case`: (return code, outcomes by test name)."""

    def __init__(self, zip_file, case):
        self.root = tempfile.mkdtemp(prefix="plume_zip_install_")
        env = {k: v for k, v in os.environ.items()
               if not k.startswith("BLENDER_USER_") and k not in ("LD_LIBRARY_PATH", "PYTHONPATH")}
        for var, sub in (("BLENDER_USER_RESOURCES", "resources"), ("BLENDER_USER_CONFIG", "config"),
                         ("BLENDER_USER_SCRIPTS", "scripts"), ("BLENDER_USER_DATAFILES", "datafiles"),
                         ("BLENDER_USER_EXTENSIONS", "extensions")):
            env[var] = os.path.join(self.root, sub)
            os.makedirs(env[var])  # a missing folder makes Blender fall back to ~/.config/blender
        results = os.path.join(self.root, "results.json")
        env.update({ISOLATED_ENV: results, "PLUME_ZIP_CASE": case, "PLUME_ZIP_ROOT": self.root,
                    "PLUME_ZIP_UNDER_TEST": os.path.abspath(zip_file), "PLUME_TEST_OUT": OUT_DIR})
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(isolated_command(os.path.abspath(__file__)), env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  timeout=900)
            output, self.rc = proc.stdout, proc.returncode
        except subprocess.TimeoutExpired as e:
            output, self.rc = str(e.stdout or ""), "timeout"
        print(f"  ---- isolated Blender {VERSION}, {case} (rc {self.rc}, "
              f"{time.perf_counter() - t0:.1f} s) ----")
        for line in output.splitlines():
            if not line.startswith("Fra:"):  # Cycles progress lines
                print("  | " + line)
        self.outcomes = {}
        if os.path.exists(results):
            with open(results) as f:
                self.outcomes = json.load(f)

    def check(self, test, name):
        if "setUpClass" in self.outcomes:
            test.fail("isolated setUpClass failed:\n" + self.outcomes["setUpClass"][1])
        if name not in self.outcomes:
            test.fail(f"isolated Blender did not report {name} (rc {self.rc}); its output is "
                      "above")
        outcome, details = self.outcomes[name]
        if outcome != "pass":
            test.fail(f"isolated {name}: {outcome}\n{details}")

    def cleanup(self):
        shutil.rmtree(self.root, ignore_errors=True)


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

def run(*cases):
    """As helpers.run (not imported: helpers enables the regularly installed add-on): runs the
    TestCases or the names after "--", prints "N passed, N failed" last, exits 1 on failure."""
    loader = unittest.defaultTestLoader
    names = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if names:
        suite = loader.loadTestsFromNames(names, sys.modules[cases[0].__module__])
    else:
        suite = unittest.TestSuite(loader.loadTestsFromTestCase(c) for c in cases)
    result = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    passed = result.testsRun - failed - len(result.skipped)
    sys.stdout.flush()
    print(f"{passed} passed, {failed} failed", flush=True)
    sys.exit(0 if failed == 0 and result.testsRun > 0 else 1)


if __name__ == "__main__":
    if os.environ.get(ISOLATED_ENV):
        run_isolated(os.environ[ISOLATED_ENV],
                     {"InstalledAddonTest": InstalledAddonTest,
                      "BrokenInstallTest": BrokenInstallTest}[os.environ["PLUME_ZIP_CASE"]])
    else:
        run(ZipLayoutTest, IsolatedInstallTest, MissingLibraryTest)
