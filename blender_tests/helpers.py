"""Shared helpers of the Blender tests (run inside ``blender -b``).

Each test file does ``sys.path.insert(0, <this folder>)`` and ``from helpers import ...``."""

import os
import shutil
import sys
import tempfile
import unittest

import addon_utils
import bpy
import numpy as np

ADDON = "plume"
OUT_DIR = os.environ.get("PLUME_TEST_OUT", "/tmp/plume_test_out")


def reset_scene():
    """Factory startup, default objects deleted, add-on enabled."""
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    enable_addon()


def enable_addon():
    loaded_default, loaded_state = addon_utils.check(ADDON)
    if not loaded_state:
        mod = addon_utils.enable(ADDON, default_set=True, handle_error=_raise)
        if mod is None:
            raise RuntimeError("could not enable the plume add-on")


def _raise(exc):
    raise exc


class _Compat:
    """The add-on's module of Blender version differences (plume.blender_compat), which tests
    use as the builders do; loaded on first use, enabling the add-on then."""

    def __getattr__(self, name):
        enable_addon()
        import importlib
        return getattr(importlib.import_module(ADDON + ".blender_compat"), name)


compat = _Compat()


def native():
    """The installed add-on's native module (plume._native)."""
    from plume import _native
    return _native


def select_only(ob):
    vl = bpy.context.view_layer
    for o in vl.objects:
        o.select_set(False)
    if ob is not None:
        ob.select_set(True)
    vl.objects.active = ob


def add_domain(size=2.0, location=(0.0, 0.0, 1.0), resolution=32, frame_start=1, frame_end=10,
               cache_directory=None, name="Domain"):
    """A cube domain set up through the operators, as an artist would."""
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    dom = bpy.context.active_object
    dom.name = name
    bpy.ops.plume.role_set(role='DOMAIN')
    d = dom.plume.domain
    d.resolution = resolution
    d.frame_start = frame_start
    d.frame_end = frame_end
    if cache_directory is not None:
        d.cache_directory = cache_directory
    return dom


def add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35), name="Source"):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location)
    ob = bpy.context.active_object
    ob.name = name
    bpy.ops.plume.role_set(role='SOURCE')
    ob.hide_render = True  # an artist hides the emitter; the smoke is what renders
    return ob


def add_cube_obstacle(size=0.3, location=(0.45, 0.0, 1.1), name="Obstacle"):
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    ob = bpy.context.active_object
    ob.name = name
    bpy.ops.plume.role_set(role='OBSTACLE')
    return ob


def assert_reports_error(test, operator, pattern, state):
    """`operator()` fails with a reported error (RuntimeError in a script) matching `pattern`,
    and `state()` (e.g. datablock counts) is the same after as before: bad input changes nothing."""
    before = state()
    with test.assertRaises(RuntimeError) as ctx:
        operator()
    test.assertRegex(str(ctx.exception), pattern)
    test.assertEqual(state(), before)


def temp_dir(prefix):
    return tempfile.mkdtemp(prefix=prefix)


def rmtree(path):
    shutil.rmtree(path, ignore_errors=True)


def tree_listing(path):
    """Sorted relative paths of every file and folder under `path` ([] when missing)."""
    out = []
    for root, dirs, files in os.walk(path):
        for n in dirs + files:
            out.append(os.path.relpath(os.path.join(root, n), path))
    return sorted(out)


def density_com_z(path):
    """(total density, centre-of-mass z in world units) of a VDB frame's density grid."""
    g = native().read_vdb_grid(path, "density")
    vals = np.asarray(g["values"], dtype=np.float64)
    mass = float(vals.sum())
    if mass <= 0.0:
        return 0.0, float("nan")
    k = np.arange(vals.shape[2], dtype=np.float64) + g["min"][2]
    z = g["world_of_voxel_zero"][2] + k * g["voxel_size"]
    return mass, float((vals.sum(axis=(0, 1)) * z).sum() / mass)


def image_pixels(path):
    """RGBA float pixels (h, w, 4) of an image file, read through Blender."""
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return px.reshape(h, w, 4)


def run(*cases):
    """Runs the TestCases (or the names given after "--"), prints "N passed, N failed" alone on the last line, exits 1 on failure."""
    loader = unittest.defaultTestLoader
    names = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if names:  # e.g. -- BakeTest.test_cache_free
        module = sys.modules[cases[0].__module__]
        suite = loader.loadTestsFromNames(names, module)
    else:
        suite = unittest.TestSuite(loader.loadTestsFromTestCase(c) for c in cases)
    result = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    passed = result.testsRun - failed - len(result.skipped)
    sys.stdout.flush()
    # Free the scene's simulation data while Python still runs: the bpy module's exit frees a
    # Mantaflow domain after Python let go of its grids, and Mantaflow then aborts the process.
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    print(f"{passed} passed, {failed} failed", flush=True)
    sys.exit(0 if failed == 0 and result.testsRun > 0 else 1)
