"""Render time of one toon smoke frame at 640x480 with and without the outlines (the
paper: about 1 s per 640x480 frame for its renderer, after 3 s of simulation per frame).

    blender -b --factory-startup --python examples/toon/toon_render_time.py -- BLEND [FRAME] [REPEATS]

BLEND is a .blend written by one of the toon examples (toon_ceiling.py, toon_donut.py,
toon_explosion.py) after its bake and Build Toon Smoke. Renders FRAME (default: the scene's
last) at 640x480 with the scene's Cycles settings, REPEATS times each (default 3, the best time
is kept: the machine may be shared): with outlines (the compositor's "Plume Depth Differences"
group on the Depth pass, as Build Toon Smoke wires it) and without (compositor and Depth pass
off). Prints both times, their difference and the particle count. Needs the Plume add-on
(README): its frame handler puts the frame's particles on the toon object.
"""

import os
import sys
import time

import addon_utils
import bpy

USAGE = ("usage: blender -b --factory-startup --python examples/toon/toon_render_time.py -- BLEND "
         "[FRAME] [REPEATS]")


def best_render_seconds(scene, view_layer, repeats):
    """Best seconds of `repeats` renders with and without outlines, taken in turn (so a load
    change on a shared machine hits both alike)."""
    best = {True: float("inf"), False: float("inf")}
    for _ in range(repeats):
        for outlines in (True, False):
            scene.render.use_compositing = view_layer.use_pass_z = outlines
            t0 = time.perf_counter()
            bpy.ops.render.render()
            best[outlines] = min(best[outlines], time.perf_counter() - t0)
    return best[True], best[False]


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv or not os.path.isfile(argv[0]):
        sys.exit(USAGE)
    try:
        frame = int(argv[1]) if len(argv) > 1 and argv[1] else None
        repeats = max(1, int(argv[2])) if len(argv) > 2 else 3
    except ValueError:
        sys.exit(USAGE)
    if addon_utils.enable("plume", default_set=True) is None:
        sys.exit("the plume add-on is not installed (see README)")
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(argv[0]))
    scene, view_layer = bpy.context.scene, bpy.context.view_layer
    toon = [o for o in scene.objects if "plume_toon_cache" in o]
    from plume import blender_compat
    tree = blender_compat.compositor_tree(scene)
    if not toon or tree is None or "Plume Depth Differences" not in tree.nodes:
        sys.exit(f"{argv[0]}: no toon smoke built (run the example first)")
    scene.frame_set(frame if frame is not None else scene.frame_end)
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.resolution_percentage = 100
    particles = sum(len(o.data.vertices) for o in toon)

    with_s, without_s = best_render_seconds(scene, view_layer, repeats)
    print(f"toon_render_time: {os.path.basename(argv[0])} frame {scene.frame_current}, "
          f"{particles} particles, 640x480, Cycles {scene.cycles.samples} samples, best of "
          f"{repeats}: {with_s:.2f} s with outlines, {without_s:.2f} s without "
          f"({with_s - without_s:+.2f} s for the Depth pass and the compositor)", flush=True)


if __name__ == "__main__":
    main()
