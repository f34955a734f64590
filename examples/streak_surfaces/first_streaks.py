"""A newcomer's first Streak Surfaces, every setting at its default: a 2 m domain at 40³, a UV
sphere of radius 0.25 m as the Source, 60 frames; Bake, Build Surfaces, Fast Sheet Render.

    blender -b --factory-startup --python examples/streak_surfaces/first_streaks.py -- OUT_DIR
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/first_streaks.py -- OUT_DIR

Renders frame 60 three ways from the same bake, side by side in OUT_DIR/first_streaks_strip.png:
- the defaults: point sources on a rim around the Source (addon/point_rim.py), a few sheets;
- Placement Cells, the paper's 16 random points per source cell thinned to Max Streaklines (256),
  all in one sheet at the default h0 (what the defaults gave before the rim);
- the Volume object of the bake (Cycles, 16 samples), the smoke the sheets stand for.
Prints the surfaces and their control nets of each and the build and render times.
"""

import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/first_streaks.py -- OUT_DIR")
WIDTH, HEIGHT = 240, 320
FRAMES, SHOWN = 60, 60


def shot(out_dir, placement):
    """The newcomer's scene with the Source's point_placement, baked and built; the .blend is
    OUT_DIR/first_<placement>.blend. Returns (domain, control nets "nu x nv", build seconds)."""
    scene = scene_kit.new_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(0.0, 0.0, 0.35))
    src = bpy.context.active_object
    src.name = "Source"
    bpy.ops.plume.role_set(role='SOURCE')
    src.hide_render = True
    src.plume.source.point_placement = placement
    dom = scene_kit.domain_cube("Domain", 2.0, (0.0, 0.0, 1.0), 40, FRAMES)
    dom.plume.domain.streaks = True
    scene.frame_start, scene.frame_end = 1, FRAMES
    scene_kit.camera(scene, (0.0, -4.5, 1.0), target=(0.0, 0.0, 1.0))
    scene_kit.dark_studio(scene)
    scene_kit.save_blend(out_dir, f"first_{placement.lower()}")
    scene_kit.select([dom], dom)
    scene_kit.run_op(bpy.ops.plume.bake, placement, "the bake")
    build_s = scene_kit.run_op(bpy.ops.plume.surfaces_build, placement, "Build Surfaces")
    nets = [f"{o.data.splines[0].point_count_u}x{o.data.splines[0].point_count_v}"
            for o in bpy.data.objects if o.type == 'SURFACE']
    return dom, nets, build_s


def render(out_dir, name, sheets):
    """Frame SHOWN at WIDTH x HEIGHT: the sheets with Fast Sheet Render, else the Volume."""
    scene = bpy.context.scene
    dom = bpy.data.objects["Domain"]
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if sheets:
        smoke.hide_render = True
        assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}
    else:
        smoke.hide_render = False
        for o in bpy.data.objects:
            if o.type == 'SURFACE':
                o.hide_render = True
        scene_kit.cycles(scene, WIDTH, HEIGHT, 16, "")
    scene.cycles.device = 'CPU'
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    t0 = time.perf_counter()
    path = scene_kit.render_frames(scene, [SHOWN], os.path.join(out_dir, name + "_%04d.png"))[0]
    return path, time.perf_counter() - t0


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    os.makedirs(out_dir, exist_ok=True)
    paths = []
    for placement in ('RIM', 'CELLS'):
        _dom, nets, build_s = shot(out_dir, placement)
        path, render_s = render(out_dir, f"first_{placement.lower()}", sheets=True)
        paths.append(path)
        print(f"{placement}: {len(nets)} surfaces (nets {', '.join(nets)}); Build Surfaces "
              f"{build_s:.1f} s, Fast Sheet Render {render_s:.1f} s at {WIDTH} x {HEIGHT}",
              flush=True)
        if placement == 'RIM':
            path, render_s = render(out_dir, "first_volume", sheets=False)
            volume = path
            print(f"Volume: Cycles 16 samples {render_s:.1f} s", flush=True)
    paths.append(volume)
    print(scene_kit.strip(paths, os.path.join(out_dir, "first_streaks_strip.png")))


if __name__ == "__main__":
    main()
