"""A strip across one transition of a synthesized fire, above the same frames of a straight
simulation (run inside Blender after flowgraph_kit.flowgraph_example).

The top row is the synthesis: `frames` frames centred on the frame in which the walk took a
transition (node i of one state -> node j + 1, §4.3: the successor of the group j similar to
i). The bottom row is the destination state played straight through the same node steps: the
groups of that state emitted one after another by temporal edges only, from at least one
lifetime t_max before the first frame shown (or from the start of its bake), aligned so that
the step at which the walk jumped emits the same group j + 1 in both rows. Both rows go through
the same particles (eq. 13, same u_ext), rasterization and material, so they differ only by the
transition: above, the particles of the old state's groups are still alive after the jump;
below, the destination state has been itself all along. (The state's baked Volume frames are
the solver's grid, another representation of the same fire: beside the particles they would
differ in look for reasons that have nothing to do with the transition.)
"""

import os

import bpy
import numpy as np

import flowgraph_kit
import scene_kit


def pick(walk, counts, frames_shown, last_frame):
    """(walk index k, transitions in its window, between states) of the transition to show: its
    window of `frames_shown` frames centred on the jump's frame fits in the synthesized frames
    and the destination state has groups up to the window's end; fewest other transitions in
    the window first, then a transition between states, then the earliest. None if none fits."""
    flowgraph = scene_kit.addon_module("flowgraph")
    states, steps = walk["states"], walk["steps"]
    per_frame, start = int(walk["nodes_per_frame"]), int(walk["frame_start"])
    jumps = flowgraph.transition_indices(states, steps)
    half = frames_shown // 2
    best = None
    for k in jumps:
        first, last = start + k // per_frame - half, start + k // per_frame + half
        if first < start or last > last_frame:
            continue
        end = (last - start + 1) * per_frame - 1  # walk index of the window's last step
        if (steps[k] + end - k >= counts[states[k]]
                or steps[k] - k + (first - start) * per_frame < 0):
            continue  # the destination state has no groups that far before or after the jump
        inside = int(np.sum((jumps >= (first - start) * per_frame) & (jumps <= end)))
        key = (inside, states[k] == states[k - 1], k)
        if best is None or key < best:
            best = key
    return None if best is None else (int(best[2]), best[0], not best[1])


def replay(native, runner, states, walk, k, frame_range, out_folder):
    """Writes the destination state's straight run (temporal edges only) for the frames of
    `frame_range` to <out_folder>/fire/fire_####.vdb, aligned with the walk at index k (see the
    module docstring). Returns the state's first group emitted."""
    flowgraph = scene_kit.addon_module("flowgraph")
    state, per_frame = int(walk["states"][k]), int(walk["nodes_per_frame"])
    start = int(walk["frame_start"])
    file = states[state].file
    offset = int(walk["steps"][k]) - k  # state step = walk index + offset
    ends = {(f - start + 1) * per_frame - 1 + offset: f for f in frame_range}
    first = max(0, (frame_range[0] - start) * per_frame + offset - file.layout.samples)
    syn = native.Synthesizer(file.layout, 0)
    os.makedirs(os.path.join(out_folder, flowgraph.FIRE_FOLDER), exist_ok=True)
    for step in range(first, max(ends) + 1):
        frame_index = max(0, (step - offset) // per_frame)  # u_ext of the walk's frame
        syn.step_node(file, step, state, runner.external_velocity(frame_index))
        if step in ends:
            syn.write_vdb(flowgraph.fire_path(out_folder, ends[step]), runner.raster, ends[step])
    return first


def walk_summary(walk, tag):
    """Prints the transitions a synthesis took (read_walk's dict) and returns their count."""
    flowgraph = scene_kit.addon_module("flowgraph")
    jumps = flowgraph.transition_indices(walk["states"], walk["steps"])
    between = int(np.sum(walk["states"][jumps] != walk["states"][jumps - 1]))
    print(f"{tag}: the walk took {len(jumps)} transitions in {len(walk['nodes'])} node steps "
          f"({between} between states; mean {len(walk['nodes']) / max(len(jumps), 1):.1f} "
          "steps between transitions)", flush=True)
    return len(jumps)


def example_with_walk(tag, usage, default_frames, setup, targets, show, graph):
    """flowgraph_kit.flowgraph_example, then the transitions its walk took (walk_summary)."""
    _scene, keeper, _fire, _out = flowgraph_kit.flowgraph_example(tag, usage, default_frames, setup,
                                                              targets, show, graph)
    flowgraph = scene_kit.addon_module("flowgraph")
    folder = scene_kit.addon_module("snapshot").cache_folder_of(keeper)
    walk_summary(flowgraph.read_walk(flowgraph.walk_path(folder)), tag)


def transition_strip(scene, keeper, fire, out_dir, tag, frames_shown=5):
    """Picks a transition of the synthesis kept with `keeper` (its fire/walk.npz), renders the
    synthesized frames around it and the straight run beneath them, and writes
    OUT_DIR/TAG_transition.png (top: synthesis, bottom: straight). Prints the walk's transitions
    and the one shown; returns the strip's path or None when no transition fits."""
    flowgraph, native = scene_kit.addon_module("flowgraph"), scene_kit.addon_module("_native")
    snap = scene_kit.addon_module("snapshot.flowgraph")
    folder = scene_kit.addon_module("snapshot").cache_folder_of(keeper)
    walk = flowgraph.read_walk(flowgraph.walk_path(folder))
    graph, states = flowgraph.load_graph(native, folder, f"domain '{keeper.name}'")
    counts = [st.file.node_count for st in states]
    per_frame, start = int(walk["nodes_per_frame"]), int(walk["frame_start"])
    last_frame = start + len(walk["nodes"]) // per_frame - 1
    walk_summary(walk, tag)
    chosen = pick(walk, counts, frames_shown, last_frame)
    if chosen is None:
        print(f"{tag}: no transition with {frames_shown} frames around it to show", flush=True)
        return None
    k, inside, across = chosen
    f0 = start + k // per_frame
    frame_range = list(range(f0 - frames_shown // 2, f0 + frames_shown // 2 + 1))
    with np.load(flowgraph.graph_path(folder), allow_pickle=False) as data:
        cost = np.array(data["cost"])
    i, dest = int(walk["nodes"][k - 1]), int(walk["nodes"][k])
    c = cost[i, dest - 1] if dest > 0 else float("nan")  # the candidate (i, j) of edge i -> j+1
    print(f"{tag}: shown: the transition at node step {k} (frame {f0}) from state "
          f"{walk['states'][k - 1]} group {walk['steps'][k - 1]} to state {walk['states'][k]} "
          f"group {walk['steps'][k]} (cost c_ij {c:.4g}; {inside} transition(s) in frames "
          f"{frame_range[0]}-{frame_range[-1]}; {'between' if across else 'within'} states)",
          flush=True)
    settings = snap.synthesis_settings(keeper)
    settings.targets, settings.winds, settings.turbulence = snap.frame_inputs(
        bpy.context, keeper, settings.frame_start, settings.frame_end)
    runner = flowgraph.SynthesisRunner(native, graph, states, settings, folder)
    straight = os.path.join(out_dir, tag + "_straight")
    first = replay(native, runner, states, walk, k, frame_range, straight)
    print(f"{tag}: straight run of state {walk['states'][k]} from its group {first}",
          flush=True)
    top = scene_kit.render_frames(scene, frame_range,
                                  os.path.join(out_dir, tag + "_transition_%04d.png"))
    vol = fire.data
    synthesized = vol.filepath
    vol.grids.unload()
    vol.filepath = flowgraph.fire_path(straight, start)
    bottom = scene_kit.render_frames(scene, frame_range,
                                     os.path.join(out_dir, tag + "_straight_%04d.png"))
    vol.grids.unload()
    vol.filepath = synthesized
    return scene_kit.strip(top + bottom, os.path.join(out_dir, tag + "_transition.png"),
                           columns=frames_shown)
