"""How long a streak-sheet frame takes to render: the incense of Figure 1 (incense.py beside this
file, its 120 frames) at 640 x 480, frame 84, in three set-ups, with the difference from the
first.

    blender -b --factory-startup --python examples/streak_surfaces/sheet_render_time.py -- OUT_DIR [FRAMES]
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/sheet_render_time.py -- OUT_DIR

- Cycles as the example rendered before: 64 samples, Blender's default light bounces, 64
  transparent bounces;
- Cycles with the add-on's Fast Sheet Render (plume.surfaces_fast_render: 16 samples, no light
  bounces; the sheets shade themselves, §3.4);
- EEVEE, 16 samples, where this Blender can run it (3.4.1 under ``blender -b`` has no GPU
  context: run it in a window, e.g. under ``xvfb-run``, to measure it).

Each set-up renders the frame twice; the second time is printed (the first loads kernels and
shaders). Writes OUT_DIR/sheet_render_<setup>.png and OUT_DIR/sheet_render_strip.png; prints
seconds per frame, the mean and 99.9th-percentile difference from the first set-up in 8-bit
levels, and the ratio of times.
"""

import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import incense  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/sheet_render_time.py -- OUT_DIR [FRAMES]")
WIDTH, HEIGHT = 640, 480
FRAME_SHARE = 0.7  # frame 84 of 120


def pixels(path):
    im = bpy.data.images.load(path)
    a = np.array(im.pixels[:], dtype=np.float32).reshape(im.size[1], im.size[0], 4)[..., :3]
    bpy.data.images.remove(im)
    return a


def render_twice(scene, path):
    """Seconds of the second of two renders of the current frame to `path`."""
    scene.render.filepath = path
    seconds = []
    for _ in range(2):
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds.append(time.perf_counter() - t0)
    return seconds[-1]


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, incense.DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    incense.make_source(frames)
    dom = incense.make_domain(frames)
    scene_kit.camera(scene, (0.0, -1.7, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, WIDTH, HEIGHT, 64, "")
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, "sheet_render")
    bake_s, build_s, _h0, surfaces = scene_kit.bake_surfaces(dom, "sheet_render_time")
    frame = max(1, round(FRAME_SHARE * frames))
    scene.frame_set(frame)
    print(f"sheet_render_time: {len(surfaces)} surfaces, frame {frame}, {WIDTH}x{HEIGHT}, "
          f"Blender {bpy.app.version_string}", flush=True)

    rows, paths = [], []
    path = os.path.join(out_dir, "sheet_render_cycles64.png")
    rows.append(("Cycles, 64 samples, default bounces", render_twice(scene, path)))
    paths.append(path)
    assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}
    path = os.path.join(out_dir, "sheet_render_fast.png")
    rows.append((f"Cycles, Fast Sheet Render ({scene.cycles.samples} samples)",
                 render_twice(scene, path)))
    paths.append(path)
    scene.render.engine = scene_kit.compat().eevee_engine()
    scene.eevee.taa_render_samples = 16
    path = os.path.join(out_dir, "sheet_render_eevee.png")
    try:
        rows.append(("EEVEE, 16 samples", render_twice(scene, path)))
        paths.append(path)
    except RuntimeError as e:
        print(f"sheet_render_time: EEVEE cannot render here ({str(e).strip()})", flush=True)

    ref = pixels(paths[0])
    for (name, seconds), p in zip(rows, paths):
        d = np.abs(pixels(p) - ref) * 255.0
        print(f"  {name}: {seconds:.2f} s per frame ({rows[0][1] / seconds:.1f}x the speed of "
              f"the first), difference from it {d.mean():.2f} mean, {np.percentile(d, 99.9):.1f} "
              f"at the 99.9th percentile (8-bit levels)", flush=True)
    strip = scene_kit.strip(paths, os.path.join(out_dir, "sheet_render_strip.png"))
    print(f"sheet_render_time: bake {bake_s:.1f} s, Build Surfaces {build_s:.1f} s -> {strip}",
          flush=True)


if __name__ == "__main__":
    main()
