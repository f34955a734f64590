"""A newcomer's first Streak Surfaces, every setting at its default: a 2 m domain at 40³, a UV
sphere of radius 0.25 m as the Source, 60 frames; Bake, Build Surfaces, Fast Sheet Render.

    blender -b --factory-startup --python examples/streak_surfaces/first_streaks.py -- OUT_DIR
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/first_streaks.py -- OUT_DIR

Renders frame 60 three ways, side by side in OUT_DIR/first_streaks_strip.png:
- the defaults: the domain's Turbulence stirs the air and the Source's Breakup makes it smoke in
  uneven puffs, so the sheets from the rim of point sources (addon/point_rim.py) fold and thin;
- still air (Turbulence 0, Breakup 0: what the defaults gave before), where the same sheets are
  a straight translucent tube around a laminar column;
- the Volume object of the default bake (Cycles, 16 samples), the smoke the sheets stand for.
Prints for each bake the surfaces and their control nets, the streaklines' mean turning angle
between consecutive particles (how much they fold), the share of the sheets' pixels that are
see-through (alpha below 0.8 on a transparent film), and the build and render times.
"""

import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/first_streaks.py -- OUT_DIR")
WIDTH, HEIGHT = 240, 320
FRAMES, SHOWN = 60, 60
#: Alpha below which a pixel the sheets cover shows the background through them (a fifth or more).
SEE_THROUGH_ALPHA = 0.8


def mean_turning_degrees(snapshot):
    """Mean angle between consecutive segments of every streakline's particles still inside the
    domain (oldest first), over all streaklines of a streak snapshot (read_streak_file()): 0
    for straight lines, larger the more they fold."""
    counts = np.asarray(snapshot["counts"])
    pos = np.asarray(snapshot["positions"]).reshape(-1, 3)
    outside = np.asarray(snapshot.get("outside", np.zeros(len(pos))), dtype=bool)
    angles, start = [], 0
    for n in counts:
        p = pos[start:start + n][~outside[start:start + n]]
        start += n
        seg = np.diff(p, axis=0)
        length = np.linalg.norm(seg, axis=1)
        seg = seg[length > 1e-6] / length[length > 1e-6, None]
        if len(seg) >= 2:
            angles.append(np.degrees(np.arccos(np.clip((seg[1:] * seg[:-1]).sum(axis=1),
                                                       -1.0, 1.0))))
    return float(np.concatenate(angles).mean()) if angles else 0.0


def see_through(alpha):
    """(share of the frame the sheets cover, share of those pixels that are see-through) of a
    render's alpha on a transparent film."""
    covered = alpha > 0.05
    if not covered.any():
        return 0.0, 0.0
    return float(covered.mean()), float((alpha[covered] < SEE_THROUGH_ALPHA).mean())


def newcomer_scene(cache_directory, still=False):
    """The newcomer's Source and Domain (Streak Surfaces on, every other setting at its default;
    in still air when `still`) in the current scene, over frames 1..FRAMES. Returns the domain."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.25, location=(0.0, 0.0, 0.35))
    src = bpy.context.active_object
    src.name = "Source"
    bpy.ops.plume.role_set(role='SOURCE')
    src.hide_render = True
    dom = scene_kit.domain_cube("Domain", 2.0, (0.0, 0.0, 1.0), 40, FRAMES)
    dom.plume.domain.streaks = True
    dom.plume.domain.cache_directory = cache_directory
    if still:
        dom.plume.domain.turbulence = 0.0
        src.plume.source.smoke_noise = 0.0
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, FRAMES
    return dom


def shot(out_dir, name, still):
    """The newcomer's scene, in still air when `still`, baked and built; the .blend is
    OUT_DIR/first_<name>.blend with its cache in OUT_DIR/<name>_cache. Returns (domain, control
    nets "nu x nv", mean turning angle at the last frame, build seconds)."""
    scene = scene_kit.new_scene()
    dom = newcomer_scene(f"//{name}_cache/", still)
    scene_kit.camera(scene, (0.0, -4.5, 1.0), target=(0.0, 0.0, 1.0))
    scene_kit.dark_studio(scene)
    scene_kit.save_blend(out_dir, f"first_{name}")
    scene_kit.select([dom], dom)
    scene_kit.run_op(bpy.ops.plume.bake, name, "the bake")
    build_s = scene_kit.run_op(bpy.ops.plume.surfaces_build, name, "Build Surfaces")
    nets = [f"{o.data.splines[0].point_count_u}x{o.data.splines[0].point_count_v}"
            for o in bpy.data.objects if o.type == 'SURFACE']
    from plume import _native
    streaks = os.path.join(out_dir, f"{name}_cache", "Domain", f"streaks_{FRAMES:04d}.bin")
    turn = mean_turning_degrees(_native.read_streak_file(streaks))
    return dom, nets, turn, build_s


def render(out_dir, name, sheets, transparent=False):
    """Frame SHOWN at WIDTH x HEIGHT: the sheets with Fast Sheet Render, else the Volume; with
    `transparent` on a transparent film (RGBA). Returns (path, seconds)."""
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
    scene.render.film_transparent = transparent
    scene.render.image_settings.file_format = 'PNG'
    scene.render.image_settings.color_mode = 'RGBA' if transparent else 'RGB'
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
    for name, still in (("defaults", False), ("still_air", True)):
        _dom, nets, turn, build_s = shot(out_dir, name, still)
        path, render_s = render(out_dir, f"first_{name}", sheets=True)
        paths.append(path)
        alpha_path, _ = render(out_dir, f"first_{name}_alpha", sheets=True, transparent=True)
        cover, see = see_through(scene_kit.png_pixels(alpha_path, alpha=True)[..., 3])
        print(f"{name}: {len(nets)} surfaces (nets {', '.join(nets)}); streaklines turn "
              f"{turn:.1f} deg per particle; sheets cover {cover:.1%} of the frame, "
              f"{see:.1%} of it see-through; Build Surfaces {build_s:.1f} s, Fast Sheet Render "
              f"{render_s:.1f} s at {WIDTH} x {HEIGHT}", flush=True)
        if not still:
            volume, render_s = render(out_dir, "first_volume", sheets=False)
            print(f"Volume: Cycles 16 samples {render_s:.1f} s", flush=True)
    paths.append(volume)
    print(scene_kit.strip(paths, os.path.join(out_dir, "first_streaks_strip.png")))


if __name__ == "__main__":
    main()
