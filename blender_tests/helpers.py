"""Shared helpers of the Blender tests (run inside ``blender -b``).

Each test file does ``sys.path.insert(0, <this folder>)`` and ``from helpers import ...``."""

import math
import os
import shutil
import sys
import tempfile
import time
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


def incense_streak_scene(cache_dir, resolution, frames, point_sources=10):
    """Two source cells of `point_sources` point sources low in a 2 m domain of `resolution`
    cells, streaks on, and a camera: a small streak scene (about 190 streaklines at 24³ over 60
    frames with 10)."""
    cell = 2.0 / resolution
    bpy.ops.mesh.primitive_cube_add(size=cell * 1.8, location=(0.5 * cell, 0.5 * cell,
                                                                 0.2 + 0.5 * cell))
    src = bpy.context.active_object
    src.name = "Incense"
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.point_placement = 'CELLS'  # the paper's set-up: random points in the source cells
    s.point_sources, s.velocity = point_sources, (0.0, 0.0, 1.0)
    s.density, s.temperature = 1.0, 2.0
    dom = add_domain(resolution=resolution, frame_end=frames, cache_directory=cache_dir + "/")
    dom.plume.domain.streaks = True
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = (0.0, -3.6, 0.9)
    bpy.context.scene.camera = cam
    select_only(dom)
    return dom


def recipe_new_file():
    """A manual recipe's first step: File › New › General, the add-on enabled, the cube deleted."""
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    enable_addon()
    bpy.ops.object.select_all(action='DESELECT')
    bpy.data.objects["Cube"].select_set(True)
    bpy.ops.object.delete()


def recipe_sphere_domain(cache_directory, streaks=False):
    """The recipes' smoke scene, as they list it: a UV sphere (radius 0.25 m at z 0.35 m) made
    the Source and hidden from renders, a 2 m cube at z 1 m made the Domain (Resolution 40, End
    60, Streak Surfaces when `streaks`), baked. Returns the domain."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(0.0, 0.0, 0.35))
    assert bpy.ops.plume.role_set(role='SOURCE') == {'FINISHED'}
    bpy.context.active_object.hide_render = True
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
    dom = bpy.context.active_object
    assert bpy.ops.plume.role_set(role='DOMAIN') == {'FINISHED'}
    d = dom.plume.domain
    d.resolution, d.frame_end, d.streaks = 40, 60, streaks
    d.cache_directory = cache_directory
    assert bpy.ops.plume.bake() == {'FINISHED'}
    return dom


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


def render_recipe(name, samples=32, size=(480, 270)):
    """A recipe's test render of the current scene at its own engine: only the size and samples
    (Cycles, on the CPU, no denoiser) are the test's. Returns (path, seconds)."""
    import time
    scene = bpy.context.scene
    if scene.render.engine == 'CYCLES':
        scene.cycles.device = 'CPU'
        scene.cycles.samples = samples
        scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    out = os.path.join(OUT_DIR, f"recipe_{name}")
    os.makedirs(out, exist_ok=True)
    scene.render.filepath = os.path.join(out, f"{name}.png")
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return scene.render.filepath, time.perf_counter() - t0


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


def lit_components(lit):
    """Connected regions (8-neighbours) of the boolean image `lit`: (share of the lit pixels in
    the largest region, share of lit pixels with no lit neighbour). Labels spread by repeated
    3 x 3 maxima until they settle (numpy only: Blender's Python has no scipy)."""
    h, w = lit.shape
    n = int(lit.sum())
    if n == 0:
        return 0.0, 0.0
    labels = np.where(lit, np.arange(1, h * w + 1).reshape(h, w), 0)
    while True:
        pad = np.pad(labels, 1)
        grown = np.max([pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
                        for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
        grown = np.where(lit, grown, 0)
        if np.array_equal(grown, labels):
            break
        labels = grown
    largest = np.bincount(labels[lit]).max()
    pad = np.pad(lit, 1).astype(np.int32)
    neighbours = sum(pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
                     for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx)
    return float(largest) / n, float((lit & (neighbours == 0)).sum()) / n



def lit_extent(scene, lit, depth_y=0.0):
    """(lowest z, highest z, width) in metres of the lit pixels of `lit` (a boolean image read
    by image_pixels: row 0 at the bottom), measured in the plane y = `depth_y` that the scene
    camera looks at (a flame standing at y = 0 before a camera looking along +y)."""
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector
    h, w = lit.shape
    cam = scene.camera
    rows, cols = np.nonzero(lit.any(axis=1))[0], np.nonzero(lit.any(axis=0))[0]
    if not len(rows):
        return float("nan"), float("nan"), 0.0
    zs = np.linspace(-2.0, 4.0, 601)
    at_z = [world_to_camera_view(scene, cam, Vector((cam.location.x, depth_y, z))).y * h - 0.5
            for z in zs]
    z0, z1 = (float(np.interp(r, at_z, zs)) for r in (rows[0], rows[-1] + 1))
    xs = cam.location.x + np.linspace(-3.0, 3.0, 601)
    z_mid = 0.5 * (z0 + z1)
    at_x = [world_to_camera_view(scene, cam, Vector((x, depth_y, z_mid))).x * w - 0.5
            for x in xs]
    x0, x1 = (float(np.interp(c, at_x, xs)) for c in (cols[0], cols[-1] + 1))
    return z0, z1, x1 - x0

#: Smallest mean |rendered - rendered without the volume| over all pixels and RGB channels that
#: counts as "the smoke shows". Both renders use the same Cycles seed, so pixels whose rays miss the
#: volume are bit-identical and the mean is the smoke's alone. One 8-bit level is 1/255 = 0.0039;
#: the 10-frame 32³ plume measured 0.014 (14 % of the pixels changed), so 0.002 (half an 8-bit
#: level on average) rejects an empty, invisible or nearly transparent volume with a 7x margin.
MIN_MEAN_ABS_DIFF = 0.002
#: ...and at least this share of pixels must change by more than 4/255 (the smoke is not a speck).
MIN_CHANGED_SHARE = 0.01


def flame_studio(scene, location, width, height, samples):
    """A camera at `location` looking along +y (level), Cycles on the CPU at width x height and
    `samples` without denoising, a black world: the flames and their lights alone show."""
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
    scene.camera = cam
    r = scene.render
    r.engine = 'CYCLES'
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    if scene.world is None:
        scene.world = bpy.data.worlds.new("World")
    scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    return cam


def smoke_studio(scene, samples):
    """Camera 3.6 m in front of a 2 m domain on the floor, a sun, Cycles CPU at 160 x 120."""
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
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 160, 120
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'


def assert_smoke_renders(test, scene, smoke, path_with, path_without):
    """Renders the current frame with and without the Volume object `smoke` to the two PNG paths
    and asserts the smoke shows (MIN_MEAN_ABS_DIFF, MIN_CHANGED_SHARE) and is not white."""
    os.makedirs(os.path.dirname(path_with), exist_ok=True)
    for visible, path in ((True, path_with), (False, path_without)):
        smoke.hide_render = not visible
        scene.render.filepath = path
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        print(f"  render ({'with' if visible else 'without'} smoke) took "
              f"{time.perf_counter() - t0:.2f} s -> {path}")
    smoke.hide_render = False
    a = image_pixels(path_with)[..., :3]
    b = image_pixels(path_without)[..., :3]
    diff = np.abs(a - b)
    mean = float(diff.mean())
    changed = float((diff.max(axis=2) > 4.0 / 255.0).mean())
    print(f"  mean |smoke - empty| = {mean:.4f}, changed pixels = {changed:.1%}")
    test.assertGreater(mean, MIN_MEAN_ABS_DIFF)
    test.assertGreater(changed, MIN_CHANGED_SHARE)
    test.assertLess(float(a.mean()), 0.95, "render is white")


def assert_same_frames(test, path_of, a, b, frames, grids=("density", "velocity")):
    """Frames `frames` of two bakes are equal bit for bit, grid by grid: path_of(folder, frame)
    is a frame's VDB file, `a` and `b` the two bakes' folders (a resumed and a straight one)."""
    nat = native()
    for f in frames:
        for grid in grids:
            x = nat.read_vdb_grid(path_of(a, f), grid)
            y = nat.read_vdb_grid(path_of(b, f), grid)
            test.assertEqual(tuple(x["min"]), tuple(y["min"]), f"frame {f} {grid}")
            test.assertEqual(x["values"].shape, y["values"].shape, f"frame {f} {grid}")
            if not np.array_equal(x["values"], y["values"]):
                test.fail(f"frame {f} {grid}: the bakes differ (max |diff| "
                          f"{np.abs(x['values'] - y['values']).max()})")


#: The start of the reason of every skip a file may make: what this machine lacks (a skip for
#: any other reason, e.g. "needs the graph of test_1", hides a failure and counts as one).
MACHINE_LACKS = "this machine lacks "


def skip_machine_lacks(test, what):
    """Skips `test` because the machine lacks `what` (a mount permission, /proc...)."""
    test.skipTest(MACHINE_LACKS + what)


def run(*cases):
    """Runs the TestCases (or the names given after "--"), prints "N passed, N failed, N
    skipped" alone on the last line, exits 1 on failure. Every skip is listed with its reason;
    one whose reason is not what the machine lacks (skip_machine_lacks) counts as a failure."""
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
    skipped = 0
    for test, reason in result.skipped:
        ok = reason.startswith(MACHINE_LACKS)
        skipped += ok
        failed += not ok
        print(f"skipped {test.id()}: {reason}" + ("" if ok else
              " -- FAILED: a skip must say what this machine lacks (skip_machine_lacks)"))
    sys.stdout.flush()
    # Free the scene's simulation data while Python still runs: the bpy module's exit frees a
    # Mantaflow domain after Python let go of its grids, and Mantaflow then aborts the process.
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    print(f"{passed} passed, {failed} failed, {skipped} skipped", flush=True)
    sys.exit(0 if failed == 0 and result.testsRun > 0 else 1)


def run_cancelled(op_class, job, after=1):
    """Calls the job operator `op_class` blocking, as a script does, with `job` (a fresh
    plume.jobs.JobRunner) as its runner, cancelled from its own progress report once `after`
    units are done (0: at its first report; or a predicate of the JobProgress); returns the
    operator's result."""
    def cancel_at(p):
        if after(p) if callable(after) else (p.total > 0 and p.done >= after or after == 0):
            job.cancel()
    job.on_progress = cancel_at
    saved = op_class.make_runner
    op_class.make_runner = lambda self, context: job
    try:
        return getattr(bpy.ops.plume, op_class.bl_idname.split(".")[1])()
    finally:
        op_class.make_runner = saved


def pid_alive(pid):
    """True while process `pid` exists and is not a zombie (a child Blender has not reaped)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            state = f.read().rsplit(b")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in (b"Z", b"X")
