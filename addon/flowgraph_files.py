"""The files a flow-graph synthesis writes beside its fire VDBs, no ``bpy``: the walk (which
graph node each node step emitted, for the transitions' study) and the point preview of each
synthesized frame. Sizes read from a file are checked, never trusted."""

import os

import numpy as np

from . import files

FIRE_FOLDER = "fire"
WALK_NAME = "walk.npz"


def walk_path(folder):
    """The walk of the last synthesis (write_walk): which node each node step emitted."""
    return os.path.join(folder, FIRE_FOLDER, WALK_NAME)


def transition_indices(states, steps):
    """Indices k >= 1 of a walk's node steps (read_walk: states, steps) that followed a
    transition (§5.1), not a temporal edge: group steps[k] of state states[k] is not the group
    after steps[k-1] in state states[k-1]."""
    states, steps = np.asarray(states, np.int64), np.asarray(steps, np.int64)
    jump = (steps[1:] != steps[:-1] + 1) | (states[1:] != states[:-1])
    return np.flatnonzero(jump) + 1


def write_walk(path, nodes, node_states, node_steps, frame_start, nodes_per_frame,
               transition_hold=0, unreachable_target=None):
    """Writes the walk atomically: nodes (the graph node of each node step, in order), their
    states and steps (group index in the state's pathline file), frame_start and nodes_per_frame
    (node step k is emitted in frame frame_start + k // nodes_per_frame), the transition hold H
    (node steps) and unreachable_target ((frame, state) from which a keyed target state could
    not be reached, (-1, -1) if none: SynthesisResult)."""
    nodes = np.asarray(nodes, np.int64)
    files.save_npz(path, nodes=nodes, states=np.asarray(node_states, np.int64)[nodes],
                   steps=np.asarray(node_steps, np.int64)[nodes],
                   frame_start=np.int64(frame_start), nodes_per_frame=np.int64(nodes_per_frame),
                   transition_hold=np.int64(transition_hold),
                   unreachable_target=np.asarray(unreachable_target or (-1, -1), np.int64))


def read_walk(path):
    """dict(nodes, states, steps, frame_start, nodes_per_frame, transition_hold,
    unreachable_target, transitions) of a walk file (transitions: transition_indices()); OSError
    or ValueError when it cannot be read or its arrays do not match."""
    w = files.load_npz(path, ("nodes", "states", "steps", "frame_start", "nodes_per_frame",
                              "transition_hold", "unreachable_target"))
    n = len(w["nodes"])
    if (w["states"].shape != (n,) or w["steps"].shape != (n,) or int(w["nodes_per_frame"]) < 1
            or w["unreachable_target"].shape != (2,)):
        raise ValueError(f"{path}: arrays of mismatched sizes")
    w["transitions"] = transition_indices(w["states"], w["steps"])
    return w


def points_path(folder, frame):
    """The point preview of a synthesized frame (SynthesisSettings.point_preview)."""
    return os.path.join(folder, FIRE_FOLDER, f"points_{frame:04d}.npz")



def preview_indices(count, cap):
    """Indices of the particles kept in the point preview: all when count <= cap, else exactly
    cap of them, every (count / cap)-th (floor(i * count / cap)): deterministic and spread over
    all live groups (oldest first), so the preview thins the fire evenly."""
    m = min(int(count), int(cap))
    return (np.arange(m, dtype=np.int64) * int(count)) // max(m, 1)


def write_points(path, particles, cap):
    """Writes the preview of `particles` (Synthesizer.particles()) to `path` atomically (temp
    name + rename): positions (M, 3), temperature and density (M,) float32 and live (the number
    of live particles it was thinned from)."""
    keep = preview_indices(len(particles["temperature"]), cap)
    files.save_npz(path, positions=np.asarray(particles["positions"], np.float32)[keep],
                   temperature=np.asarray(particles["temperature"], np.float32)[keep],
                   density=np.asarray(particles["density"], np.float32)[keep],
                   live=np.int64(len(particles["temperature"])))


def read_points(path):
    """dict(positions, temperature, density, live) of a points file; OSError or ValueError when
    it cannot be read or its arrays do not match (sizes checked, never trusted)."""
    p = files.load_npz(path, ("positions", "temperature", "density", "live"))
    n = len(p["temperature"])
    if (p["positions"].shape != (n, 3) or p["density"].shape != (n,) or p["live"].shape != ()
            or int(p["live"]) < n or any(p[k].dtype != np.float32
                                         for k in ("positions", "temperature", "density"))):
        raise ValueError(f"{path}: arrays of mismatched sizes or types")
    return p
