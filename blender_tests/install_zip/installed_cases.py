"""The tests test_install_zip.py runs inside the isolated Blender (see isolated.py): install the
zip into empty user folders, enable it, check where the add-on, _native and each bundled library
were loaded from, bake and render (InstalledAddonTest); or install a zip lacking a library and
check the error names it (BrokenInstallTest). Run by IsolatedRun, never directly."""

import os
import sys
import time
import traceback
import unittest

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))

import plume_zip  # noqa: E402
from helpers import assert_smoke_renders, select_only, smoke_studio  # noqa: E402
from isolated import (ISOLATED_ENV, KEY_LIBS, MISSING_LIB, OUT_DIR,  # noqa: E402
                      VERSION, debian_blender, mapped_by_soname, mapped_files, run_isolated)

#: Bake and render of the installed add-on: small, the machine has 2 cores.
RESOLUTION = 32
FRAMES = 8
SAMPLES = 8


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
        smoke_studio(scene, samples=SAMPLES)
        scene.frame_set(FRAMES)
        self.assertTrue(smoke.data.grids.load(), smoke.data.grids.error_message)
        out = os.path.join(OUT_DIR, f"install_zip_{VERSION}")
        assert_smoke_renders(self, scene, smoke, out + ".png", out + "_empty.png")


class BrokenInstallTest(unittest.TestCase):
    """Runs inside an isolated Blender given a zip whose lib/ lacks MISSING_LIB (and whose
    libraries needing it ignore the system's folders, see MissingLibraryTest)."""

    def test_enable_reports_missing_library(self):
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
            self.assertIn("Plume", error)
            self.assertEqual(blosc, [])



if __name__ == "__main__":
    run_isolated(os.environ[ISOLATED_ENV],
                 {"InstalledAddonTest": InstalledAddonTest,
                  "BrokenInstallTest": BrokenInstallTest}[os.environ["PLUME_ZIP_CASE"]])
