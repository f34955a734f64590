"""Build Surfaces on the newcomer's sphere scene, timed through the add-on's own operator: a 2 m
domain at 40³, a UV sphere of radius 0.25 m as the Source, Streak Surfaces on, every other setting
at its default, 60 frames; Max Streaklines set to each COUNT in turn (default 256, 1024 and
4096; 256 is the add-on's default). Prints, per count, the bake and Build Surfaces times, the
surfaces built, the forecast the operator said before it started (surfaces_forecast.py) and the
ratio of the time to the forecast.

    blender -b --factory-startup --python examples/streak_surfaces/surfaces_build_time.py -- OUT_DIR [COUNT...]
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/surfaces_build_time.py -- OUT_DIR
"""

import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/surfaces_build_time.py -- OUT_DIR [COUNT...]")
FRAMES = 60


def scene(out_dir, count):
    scene_kit.new_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(0.0, 0.0, 0.35))
    bpy.ops.plume.role_set(role='SOURCE')
    bpy.context.active_object.plume.source.point_placement = 'CELLS'  # count set by the cap
    bpy.context.active_object.plume.source.smoke_noise = 0.0
    dom = scene_kit.domain_cube("Domain", 2.0, (0.0, 0.0, 1.0), 40, FRAMES)
    d = dom.plume.domain
    d.cache_directory = os.path.join(out_dir, f"cache_{count}") + "/"
    d.streaks = True
    d.turbulence = 0.0  # the scene its times were measured on (before Turbulence)
    d.max_streaklines = count
    scene_kit.select([dom], dom)
    return dom


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    os.makedirs(out_dir, exist_ok=True)
    counts = [int(a) for a in argv[1:]] or [256, 1024, 4096]
    sf = scene_kit.addon_module("surfaces_forecast")
    native = scene_kit.addon_module("_native")
    cache = scene_kit.addon_module("cache")
    rows = []
    for count in counts:
        dom = scene(out_dir, count)
        bake_s = scene_kit.run_op(bpy.ops.plume.bake, "surfaces_build_time", "the bake")
        folder = os.path.join(dom.plume.domain.cache_directory, dom.name)
        lines, particles, frames = sf.shot_size(native, folder, cache.read_manifest(folder))
        forecast = sf.seconds(lines, particles, frames)
        t0 = time.perf_counter()
        build_s = scene_kit.run_op(bpy.ops.plume.surfaces_build, "surfaces_build_time",
                                   "Build Surfaces")
        surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
        nets = sorted({(o.data.splines[0].order_u, o.data.splines[0].point_count_u)
                       for o in surfaces})
        rows.append((lines, bake_s, build_s, len(surfaces), forecast, nets))
        print(f"surfaces_build_time: {lines} streaklines x {frames} frames: bake {bake_s:.1f} s, "
              f"Build Surfaces {build_s:.1f} s ({time.perf_counter() - t0:.1f} s with the "
              f"report), {len(surfaces)} surfaces (order, nu along u: {nets}); forecast "
              f"{forecast:.1f} s, time/forecast {build_s / forecast:.2f}", flush=True)


if __name__ == "__main__":
    main()
