"""Synthesis against simulation, per frame, at the campfire's 128 x 64 x 64 grid (the paper's
Table 1 and Figure 7 found ~12x).

    blender -b --factory-startup --python examples/flowgraph_fire/flowgraph_speed.py -- CAMPFIRE_DIR [REPEATS]

Opens CAMPFIRE_DIR/campfire.blend (run examples/flowgraph_fire/campfire.py first) and, REPEATS
times (default 2), best of each:
- synthesis: Synthesize Fire again with the saved settings (same seed and keys: the same
  frames are written again), without the group cache, then with it (2 GB) cold and warm (the
  add-on keeps a graph's prepared groups for the session, so synthesizing again reads none),
  timing the walk with the integration of eq. 13 apart from the rasterization of the particles
  into VDB grids and the file writing;
- simulation: the calm state baked again for its frames, as a copy of its domain, without
  pathline recording and with it (the cost of Plume's solver with and without §4.2).
Prints seconds per frame and the ratios: the whole frame (walk, integration, gathering the
particles, rasterizing and writing the VDB) against simulating and writing one, and the walk and
integration alone, labelled as such; `ratio: X` last is the whole-frame ratio with a warm cache.
The machine may be shared: best-of figures.
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import campfire  # noqa: E402
import flowgraph_kit  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/flowgraph_fire/flowgraph_speed.py -- CAMPFIRE_DIR [REPEATS]")


def synthesis_runs(keeper, runs, group_cache_mb):
    """`runs` runs of Synthesize Fire on `keeper` with a group cache of `group_cache_mb` MB,
    the session's cache of prepared groups freed first: per run (walk + integration s/frame,
    rasterization + writing s/frame, groups read from the files per frame), read from the
    runner's SynthesisResult. With a cache, the first run is cold (every node read once) and
    the next ones are warm (the session keeps the graph's prepared groups)."""
    flowgraph = scene_kit.addon_module("flowgraph")
    flowgraph.clear_session_cache()
    results, run = [], flowgraph.SynthesisRunner.run

    def timed_run(runner):
        results.append(run(runner))
        return results[-1]
    flowgraph.SynthesisRunner.run = timed_run
    try:
        g = keeper.plume.domain.flowgraph
        g.group_cache = group_cache_mb
        frames = g.frame_end - g.frame_start + 1
        for _ in range(runs):
            flowgraph_kit.synthesize_fire(keeper, g.frame_end, "speed")
    finally:
        flowgraph.SynthesisRunner.run = run
    return [(r.step_seconds / frames, r.write_seconds / frames, r.group_reads / frames)
            for r in results], frames


def print_synthesis(label, frames, step_s, write_s, reads):
    print(f"speed: synthesis of {frames} frames, {label} ({reads:.2f} groups read from the files "
          f"per frame): walk + integration {step_s * 1e3:.2f} ms/frame "
          f"({step_s / campfire.NODES_PER_FRAME * 1e3:.3f} ms per node step), rasterization + "
          f"VDB writing {write_s * 1e3:.1f} ms/frame", flush=True)


def bake_seconds(state, pathlines, repeats):
    """Best seconds per frame of baking a copy of domain `state` (its frames and settings), with
    or without pathline recording; Free Bake after each, then the copy is removed."""
    import shutil
    dom = state.copy()
    dom.name = f"Speed {'with' if pathlines else 'without'} pathlines"
    bpy.context.scene.collection.objects.link(dom)
    d = dom.plume.domain
    d.pathlines, d.volume_object = pathlines, ""
    frames = d.frame_end - d.frame_start + 1
    best = float("inf")
    for _ in range(repeats):
        scene_kit.select([dom], dom)
        best = min(best, scene_kit.run_op(bpy.ops.plume.bake, "speed", "the bake") / frames)
        scene_kit.run_op(bpy.ops.plume.cache_free, "speed", "Free Bake")
    shutil.rmtree(scene_kit.addon_module("snapshot").cache_folder_of(dom), ignore_errors=True)
    bpy.data.objects.remove(dom, do_unlink=True)
    return best, frames


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    repeats = int(argv[1]) if len(argv) > 1 else 2
    scene_kit.new_scene()
    bpy.ops.wm.open_mainfile(filepath=os.path.join(os.path.abspath(argv[0]),
                                                   campfire.TAG + ".blend"))
    calm = bpy.data.objects[campfire.STATES[0][0]]
    runs, frames = synthesis_runs(calm, repeats, 0)
    print_synthesis(f"no group cache (best of {repeats})", frames,
                    *(min(r[k] for r in runs) for k in range(3)))
    runs, frames = synthesis_runs(calm, 1 + repeats, 2048)
    print_synthesis("2 GB group cache, cold (the first synthesis of the graph)", frames, *runs[0])
    warm = [min(r[k] for r in runs[1:]) for k in range(3)]
    print_synthesis(f"2 GB group cache, warm (synthesizing again, best of {repeats})", frames,
                    *warm)
    cold_s, step_s = runs[0][0], warm[0]
    sim_s, baked = bake_seconds(calm, False, repeats)
    rec_s, _ = bake_seconds(calm, True, repeats)
    print(f"speed: simulation at {campfire.RESOLUTION}x{campfire.RESOLUTION // 2}x"
          f"{campfire.RESOLUTION // 2}, {baked} frames: {sim_s:.2f} s/frame without pathlines, "
          f"{rec_s:.2f} s/frame recording them (best of {repeats}; each bake writes its VDB "
          f"frames)", flush=True)
    whole_cold, whole_warm = cold_s + runs[0][1], step_s + warm[1]
    print(f"speed: walk + integration only (no finished frame: gathering, rasterization and "
          f"writing excluded): simulation / synthesis = {sim_s / cold_s:.0f}x cold, "
          f"{sim_s / step_s:.0f}x warm", flush=True)
    print(f"speed: whole frame on disk (walk, eq. 13, gathering, rasterization, VDB writing) "
          f"{whole_cold * 1e3:.1f} ms cold, {whole_warm * 1e3:.1f} ms warm, against simulating "
          f"and writing a frame {sim_s * 1e3:.0f} ms: {sim_s / whole_cold:.1f}x cold, "
          f"{sim_s / whole_warm:.1f}x warm", flush=True)
    print(f"ratio: {sim_s / whole_warm:.1f}", flush=True)


if __name__ == "__main__":
    main()
