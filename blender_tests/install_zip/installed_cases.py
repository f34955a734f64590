"""The tests test_install_zip.py runs inside the isolated Blender (see isolated.py). An artist
installs the zip into a Blender with nothing of Plume in it and enables it; InstalledAddonTest
checks that the add-on and the native module for this Blender's Python come from that install,
that enabling loads no second OpenVDB or oneTBB beside Blender's own (they are inside _native),
and that a bake renders. BrokenInstallTest installs a zip without the module for this Python
(incomplete, or a release made without it) and checks that the artist is told why in words,
and that nothing is left enabled. Run by IsolatedRun, never directly."""

import importlib.machinery
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
from isolated import (ISOLATED_ENV, OUT_DIR, VERSION, call_capturing_output,  # noqa: E402
                      mapped_files, run_isolated, static_lib_files)

#: Bake and render of the installed add-on: small, the machine has 2 cores.
RESOLUTION = 32
FRAMES = 8
SAMPLES = 8
#: The module file this Blender's Python imports.
MY_MODULE = plume_zip.module_name(sys.version_info[:2])


def plume_addons(before):
    """The plume add-ons enabled now that were not in `before` (module names)."""
    return sorted(m for m in {a.module for a in bpy.context.preferences.addons} - before
                  if m.split(".")[-1] == "plume")


def inside(path, root):
    root = os.path.realpath(root)
    return os.path.commonpath([os.path.realpath(path), root]) == root


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
        new = plume_addons(cls.addons_before)
        cls.module_name = new[0] if len(new) == 1 else None
        cls.module = sys.modules.get(cls.module_name) if cls.module_name else None

    def require_installed(self):
        if self.install_error:
            self.fail(f"installing {self.zip} failed:\n{self.install_error}")
        if self.module is None:
            self.fail(f"no (or more than one) plume add-on enabled after installing {self.zip}")

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
        self.assertTrue(inside(self.module.__file__, self.root), self.module.__file__)
        # The operators an artist clicks are the installed module's.
        cls = bpy.types.Operator.bl_rna_get_subclass_py(bpy.ops.plume.bake.idname())
        self.assertTrue(cls.__module__.startswith(self.module_name + "."), cls.__module__)

    def test_2_native_module_from_install(self):
        """_native is the install's module built for this Blender's Python (picked by its file
        name's suffix), and the other Python's module is not loaded."""
        self.require_installed()
        native = self.module._native
        print(f"  Python {sys.version.split()[0]}: _native is {native.__file__}")
        self.assertTrue(inside(native.__file__, self.root), native.__file__)
        self.assertEqual(os.path.dirname(native.__file__), os.path.dirname(self.module.__file__))
        self.assertEqual(os.path.basename(native.__file__), MY_MODULE)
        self.assertIn(MY_MODULE[len("_native"):], importlib.machinery.EXTENSION_SUFFIXES)
        self.assertIn(os.path.realpath(native.__file__), self.maps_after,
                      "_native is not mapped from its install folder")
        others = [plume_zip.module_name(p) for p in plume_zip.PYTHONS
                  if plume_zip.module_name(p) != MY_MODULE]
        self.assertTrue(others)
        for other in others:
            path = os.path.join(os.path.dirname(native.__file__), other)
            self.assertTrue(os.path.isfile(path), f"{other} was not installed")
            self.assertNotIn(os.path.realpath(path), self.maps_after, f"{other} was loaded")

    def test_3_no_second_openvdb_or_tbb(self):
        """OpenVDB, oneTBB, Blosc and OpenSubdiv are inside _native: enabling Plume maps no file
        of the install but _native itself, and no new copy of any of them from anywhere; the
        copies Blender had mapped before (its own) are still there, unchanged."""
        self.require_installed()
        native = os.path.realpath(self.module._native.__file__)
        new = self.maps_after - self.maps_before
        print(f"  files newly mapped by enabling Plume ({len(new)}):")
        for path in sorted(new):
            print(f"    {path}")
        self.assertEqual([p for p in new if inside(p, self.root)], [native])
        before = static_lib_files(self.maps_before)
        print(f"  Blender's own copies, mapped before: {before or 'none'}")
        self.assertEqual(static_lib_files(new), [], "a second OpenVDB/oneTBB/Blosc/OpenSubdiv")
        self.assertEqual(static_lib_files(self.maps_after), before)

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
    """Runs inside an isolated Blender given a zip without MY_MODULE (see MissingModuleTest):
    each test is run alone, in a Blender of its own, with the zip made for it."""

    def install_and_enable(self):
        """Installs and enables the zip as an artist does: (the Plume message the artist is
        shown, where it was found, the plume add-ons enabled afterwards)."""
        zip_file = os.environ["PLUME_ZIP_UNDER_TEST"]
        root = os.environ["PLUME_ZIP_ROOT"]
        before = {a.module for a in bpy.context.preferences.addons}
        maps_before = mapped_files()
        if bpy.app.version < (4, 2, 0):
            self.assertEqual(bpy.ops.preferences.addon_install(filepath=zip_file), {'FINISHED'})
            result, error, printed = call_capturing_output(
                lambda: bpy.ops.preferences.addon_enable(module="plume"))
        else:
            result, error, printed = call_capturing_output(
                lambda: bpy.ops.extensions.package_install_files(
                    filepath=zip_file, repo="user_default", enable_on_install=True))
        enabled = plume_addons(before)
        print(f"  operator result: {result}; exception: {error.splitlines()[:1] or 'none'}; "
              f"enabled afterwards: {enabled}")
        # Nothing of the install is loaded (there is no module for this Python to load).
        self.assertEqual([p for p in mapped_files() - maps_before if inside(p, root)], [])
        # The message: the last "Plume: ..." line, from the exception (3.4.1: the operator's
        # {'ERROR'} report) or else from what Blender printed.
        for channel, text in (("raised", error), ("printed", printed)):
            lines = [line[line.index("Plume: "):] for line in text.splitlines()
                     if "Plume: " in line]
            if lines:
                print(f"  message ({channel}): {lines[-1]}")
                return lines[-1], channel, enabled
        return "", "nowhere", enabled

    def test_enable_reports_incomplete_install(self):
        import zipfile
        with zipfile.ZipFile(os.environ["PLUME_ZIP_UNDER_TEST"]) as zf:  # "plume <version>"
            release = zf.read(f"plume/{plume_zip.BUILD_INFO}").decode().splitlines()[0].split()[1]
        message, channel, enabled = self.install_and_enable()
        self.assertEqual(enabled, [], "the add-on enabled without " + MY_MODULE)
        self.assertIn("is incomplete", message)
        self.assertIn(MY_MODULE, message)
        self.assertIn(f"install plume-{release}-linux-x64.zip again", message)

    def test_enable_reports_unsupported_python(self):
        message, channel, enabled = self.install_and_enable()
        self.assertEqual(enabled, [], "the add-on enabled without " + MY_MODULE)
        mine = sys.version_info[:2]
        self.assertIn(f"this Blender runs Python {mine[0]}.{mine[1]}", message)
        for other in plume_zip.PYTHONS:
            if other != mine:
                self.assertIn(f"Python {other[0]}.{other[1]} (", message)
        self.assertIn("Use one of those Blenders", message)


if __name__ == "__main__":
    name, _, method = os.environ["PLUME_ZIP_CASE"].partition(".")
    run_isolated(os.environ[ISOLATED_ENV],
                 {"InstalledAddonTest": InstalledAddonTest,
                  "BrokenInstallTest": BrokenInstallTest}[name], method or None)
