"""Transitions look smooth, measured: how much a synthesized fire's image changes from one frame
to the next across a transition of the walk, against within a state ([Graph Fire Synthesis]
§5.4: "the transitions appear smooth"; Figure 6 shows frames).

    blender -b --factory-startup --python examples/flowgraph_fire/transition_smoothness.py -- CAMPFIRE_DIR [FIRST LAST [WIDTH SAMPLES [reuse]]]

Opens CAMPFIRE_DIR/campfire.blend (run examples/flowgraph_fire/campfire.py first: its synthesis
and its walk, plume_cache/State0 Calm/fire/walk.npz, are used as they are) and renders the
synthesized frames FIRST..LAST (default: all of them) small, WIDTH pixels wide (default 192, 16:9)
with SAMPLES Cycles samples (default 16), without motion blur, through the scene's own view
transform, into CAMPFIRE_DIR/smoothness/ (with `reuse`, frames already rendered there are
read instead). For every frame f > FIRST, the change D(f) = the mean
absolute difference of the display RGB of frames f - 1 and f (8-bit levels, all pixels). The
walk tells each frame's kind:

- transition: a node step of frame f followed a transition (flowgraph.transition_indices): the
  first group of the new time line is emitted in f;
- after: a transition in the t_max before f (the old time line's particles still alive);
- within: no transition in the t_max before f: every live particle comes from one unbroken time
  line of one state, a straight replay of its simulation.

Prints the count, mean, median, 90th percentile and largest D of each kind and their ratios to
within, and the noise floor (frame FIRST rendered again with another sampling seed). Writes
CAMPFIRE_DIR/smoothness/smoothness.npz (frames, D, kinds) and campfire_smoothness.png, Figure 6
in frames: three rows of five frames, the transition with the largest D (centred on it), the
transition with the median D, and five frames within a state around the median within-D, each
frame rendered again at four times WIDTH with 32 samples and cropped to the part of the picture
the fire lights in any of them.
"""

import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import campfire  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/flowgraph_fire/transition_smoothness.py -- CAMPFIRE_DIR [FIRST LAST "
         "[WIDTH SAMPLES [reuse]]]")
KINDS = ("transition", "after", "within")


def change(a, b):
    """Mean absolute difference of two display images, in 8-bit levels."""
    return float(np.abs(a - b).mean() * 255.0)


def frame_kinds(walk, frames, hold_frames):
    """The kind (KINDS index) of every frame of `frames` from the walk's transitions."""
    per_frame, start = int(walk["nodes_per_frame"]), int(walk["frame_start"])
    jump_frames = np.unique(start + walk["transitions"] // per_frame)
    kinds = []
    for f in frames:
        if f in jump_frames:
            kinds.append(0)
        elif np.any((jump_frames < f) & (jump_frames >= f - hold_frames)):
            kinds.append(1)
        else:
            kinds.append(2)
    return np.asarray(kinds), jump_frames


def stats(d):
    return (len(d), float(np.mean(d)), float(np.median(d)), float(np.percentile(d, 90)),
            float(np.max(d))) if len(d) else (0,) + (float("nan"),) * 4


def cropped(paths, out, margin=4):
    """Copies of the PNGs `paths` cut to the box of pixels lit (scene_kit.lit_share's level) in
    any of them, grown by `margin`; returns their paths (OUT/crop_<name>)."""
    images = [scene_kit.png_pixels(p) for p in paths]
    lit = np.any([im.max(axis=2) > 0.05 for im in images], axis=0)
    rows, cols = np.flatnonzero(lit.any(axis=1)), np.flatnonzero(lit.any(axis=0))
    if len(rows) == 0:
        return paths
    r0, r1 = max(0, rows[0] - margin), min(lit.shape[0], rows[-1] + 1 + margin)
    c0, c1 = max(0, cols[0] - margin), min(lit.shape[1], cols[-1] + 1 + margin)
    out_paths = []
    for p, im in zip(paths, images):
        h, w = r1 - r0, c1 - c0
        rgba = np.ones((h, w, 4), np.float32)
        rgba[..., :3] = im[r0:r1, c0:c1]
        img = bpy.data.images.new("plume_crop", w, h, alpha=True)
        img.pixels.foreach_set(rgba.ravel())
        img.filepath_raw = os.path.join(out, "crop_" + os.path.basename(p))
        img.file_format = 'PNG'
        img.save()
        bpy.data.images.remove(img)
        out_paths.append(os.path.join(out, "crop_" + os.path.basename(p)))
    return out_paths


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    camp_dir = os.path.abspath(argv[0])
    scene_kit.new_scene()
    bpy.ops.wm.open_mainfile(filepath=os.path.join(camp_dir, campfire.TAG + ".blend"))
    scene = bpy.context.scene
    keeper = bpy.data.objects[campfire.STATES[0][0]]
    g = keeper.plume.domain.flowgraph
    first = int(argv[1]) if len(argv) > 2 else g.frame_start
    last = int(argv[2]) if len(argv) > 2 else g.frame_end
    width = int(argv[3]) if len(argv) > 3 else 192
    samples = int(argv[4]) if len(argv) > 4 else 16
    reuse = len(argv) > 5 and argv[5] == "reuse"
    flowgraph = scene_kit.addon_module("flowgraph")
    folder = scene_kit.addon_module("snapshot").cache_folder_of(keeper)
    walk = flowgraph.read_walk(flowgraph.walk_path(folder))
    per_frame = int(walk["nodes_per_frame"])
    hold_frames = -(-int(campfire.LIFETIME * scene.render.fps * per_frame) // per_frame)  # t_max
    out = os.path.join(camp_dir, "smoothness")
    os.makedirs(out, exist_ok=True)
    scene.render.resolution_x, scene.render.resolution_y = width, round(width * 9 / 16)
    scene.cycles.samples = samples
    scene.render.use_motion_blur = False
    pattern = os.path.join(out, "smooth_%04d.png")
    todo = [f for f in range(first, last + 1) if not (reuse and os.path.isfile(pattern % f))]
    seconds = (scene_kit.render_frames_timed(scene, todo, out, "smooth")[0] if todo else 0.0)
    paths = [pattern % f for f in range(first, last + 1)]
    print(f"smoothness: rendered frames {first}-{last} at {scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {samples} samples, {seconds:.2f} s/frame", flush=True)
    images = [scene_kit.png_pixels(p) for p in paths]
    frames = np.arange(first + 1, last + 1)
    d = np.asarray([change(images[i - 1], images[i]) for i in range(1, len(images))])
    kinds, jump_frames = frame_kinds(walk, frames, hold_frames)
    # The noise floor: frame FIRST again with another sampling seed.
    scene.cycles.seed = 1
    noise_path = scene_kit.render_frames(scene, [first], os.path.join(out, "noise_%04d.png"))[0]
    scene.cycles.seed = 0
    noise = change(images[0], scene_kit.png_pixels(noise_path))
    np.savez(os.path.join(out, "smoothness.npz"), frames=frames, change=d, kinds=kinds,
             jump_frames=jump_frames, noise=noise)
    lit = np.mean([scene_kit.lit_share(p) for p in paths[::max(1, len(paths) // 20)]])
    print(f"smoothness: {int(np.sum(kinds == 0))} frames with a transition in frames "
          f"{first + 1}-{last} "
          f"(t_max = {hold_frames} frames); lit pixels {lit * 100:.0f}% on average; noise floor "
          f"(frame {first}, another seed) {noise:.3f} levels", flush=True)
    within = stats(d[kinds == 2])
    for k, name in enumerate(KINDS):
        n, mean, median, p90, top = stats(d[kinds == k])
        if n == 0:
            print(f"smoothness: {name}: no frames", flush=True)
            continue
        print(f"smoothness: {name}: {n} frames, D mean {mean:.3f}, median {median:.3f}, 90th "
              f"percentile {p90:.3f}, largest {top:.3f} levels (8-bit); mean / within's "
              f"{mean / within[1]:.2f}, median / within's {median / within[2]:.2f}", flush=True)
    if np.any(kinds == 0) and np.any(kinds == 2):
        rank = [float(np.mean(d[kinds == 2] < v)) for v in d[kinds == 0]]
        print(f"smoothness: each transition frame's D as a percentile of the within frames': "
              f"median {np.median(rank) * 100:.0f}%, largest {max(rank) * 100:.0f}%", flush=True)
    # Figure 6 in frames: the worst transition, the median one, a stretch within a state.
    rows = []

    def window(centre):
        lo = max(first, min(centre - 2, last - 4))
        return list(range(lo, lo + 5))
    for k, pick in ((0, np.argmax), (0, lambda v: np.argsort(v)[len(v) // 2]),
                    (2, lambda v: np.argsort(v)[len(v) // 2])):
        sel = np.flatnonzero(kinds == k)
        if len(sel) == 0:
            continue
        i = sel[int(pick(d[sel]))]
        rows.append((KINDS[k], int(frames[i]), float(d[i])))
        print(f"smoothness: strip row {len(rows)}: {KINDS[k]} frame {frames[i]} (D {d[i]:.3f}): "
              f"frames {max(first, min(frames[i] - 2, last - 4))}-"
              f"{max(first, min(frames[i] - 2, last - 4)) + 4}", flush=True)
    shown = [f for _, f, _ in rows for f in window(f)]
    if shown:
        scene.render.resolution_x, scene.render.resolution_y = 4 * width, round(4 * width * 9 / 16)
        scene.cycles.samples = 32
        strip_paths = scene_kit.render_frames(scene, shown, os.path.join(out, "strip_%04d.png"))
        path = scene_kit.strip(cropped(strip_paths, out),
                               os.path.join(camp_dir, "campfire_smoothness.png"), columns=5)
        print(f"smoothness: strip -> {path}", flush=True)


if __name__ == "__main__":
    main()
