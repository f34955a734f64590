"""Flow-graph fire, no ``bpy`` ([Graph Fire Synthesis] §4.3-5.2): the states (fire bakes with
pathlines.bin), the graph built from them, and the synthesis that walks it.

    states = open_states(native, [("Calm", folder0), ("Windy", folder1)])   # BakeError if bad
    graph = build_graph(native, states, FlowGraphSettings(), out_folder)   # flowgraph.npz + PNG
    SynthesisRunner(native, out_folder, SynthesisSettings(...)).run()      # fire/fire_####.vdb

The graph's nodes are the pathline groups of every state, state by state in file order, from
each state's first_group on (the groups seeded before it, while the fire starts up from still
air, are left out: startup_groups), so node n of the graph is group
node_steps[n] + states[node_states[n]].first_group of its state's pathline file (node_groups).
"""

import math
import os
import time
import zlib
from dataclasses import dataclass, field
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from . import cache, files
from .settings import BakeError
from .ui_words import FLOWGRAPH, TAB, in_ui_words
# Build Flow Graph's and Synthesize Fire's settings, also reachable as flowgraph.<name>.
from .flowgraph_files import (FIRE_FOLDER, WALK_NAME, points_path, preview_indices,
                              read_points, read_walk, transition_indices, walk_path,
                              write_points, write_walk)
from .flowgraph_settings import (PREVIEW_POINTS_RANGE, TRANSITION_HOLDS, TRAVERSALS,
                                 TURBULENCE_MODES, FlowGraphSettings, SynthesisSettings,
                                 same_moment, startup_groups, threshold, transition_hold_steps,
                                 turbulence_velocity, validate_graph_settings,
                                 validate_synthesis)

__all__ = ["FIRE_FOLDER", "WALK_NAME", "points_path", "preview_indices", "read_points",
           "read_walk", "transition_indices", "walk_path", "write_points", "write_walk",
           "PREVIEW_POINTS_RANGE", "TRANSITION_HOLDS", "TRAVERSALS", "FlowGraphSettings",
           "SynthesisSettings", "TURBULENCE_MODES", "same_moment", "startup_groups", "threshold",
           "transition_hold_steps", "turbulence_velocity", "validate_graph_settings",
           "validate_synthesis"]

GRAPH_NAME = "flowgraph.npz"
IMAGE_NAME = "flowgraph_cost.png"


def graph_path(folder):
    return os.path.join(folder, GRAPH_NAME)


def image_path(folder):
    return os.path.join(folder, IMAGE_NAME)


def fire_path(folder, frame):
    return os.path.join(folder, FIRE_FOLDER, f"fire_{frame:04d}.vdb")


@dataclass
class State:
    """One fire bake used as a state: its name, cache folder and open pathline file, and its
    first group that is a node of the graph (the groups before it are its start-up)."""

    name: str
    folder: str
    file: object  # _native.PathlineFile
    first_group: int = 0

    @property
    def node_count(self):
        """The state's nodes in the graph: its groups from first_group on."""
        return int(self.file.node_count) - self.first_group


def node_groups(graph, states: List[State]):
    """The pathline group, in its state's file, of every node of `graph` (N,) int64."""
    node_states = np.asarray(graph.node_states, np.int64)
    first = np.asarray([st.first_group for st in states], np.int64)
    return np.asarray(graph.node_steps, np.int64) + first[node_states]


def open_states(native, named_folders: Sequence[Tuple[str, str]]) -> List[State]:
    """Opens the pathline file of every state; BakeError for one state only, a missing or
    damaged file, or states of different domains (grid, cell size, placement or layout)."""
    if len(named_folders) < 2:
        raise BakeError("Plume: flow-graph fire needs at least two baked fire states (got "
                        f"{len(named_folders)}): select two or three fire domains baked with "
                        f"Record Pathlines ({TAB} › Combustion), Shift-clicking them in the "
                        "viewport (states in name order; the graph is kept with the active one)")
    states = []
    for name, folder in named_folders:
        path = cache.pathlines_path(folder)
        if not os.path.isfile(path):
            raise BakeError(f"Plume: domain '{name}' has no pathline file ({path}): turn on "
                            f"Record Pathlines ({TAB} › Combustion) and bake it")
        try:
            states.append(State(name, folder, native.PathlineFile.open(path)))
        except RuntimeError as e:
            raise BakeError(f"Plume: domain '{name}': {e} (bake it again)") from None
    first = states[0]
    for s in states[1:]:
        a, b = first.file, s.file
        if (tuple(a.resolution) != tuple(b.resolution)
                or not math.isclose(a.cell_size, b.cell_size, rel_tol=1e-5)
                or not np.allclose(a.origin, b.origin, atol=1e-4 * a.cell_size)):
            raise BakeError(f"Plume: states '{first.name}' and '{s.name}' are caches of different "
                            f"domain sizes ({tuple(a.resolution)} cells of {a.cell_size:.4g} m at "
                            f"{tuple(round(v, 4) for v in a.origin)} vs {tuple(b.resolution)} of "
                            f"{b.cell_size:.4g} m at {tuple(round(v, 4) for v in b.origin)}): "
                            "bake every state on the same domain box and resolution")
        if a.layout != b.layout:
            raise BakeError(f"Plume: states '{first.name}' and '{s.name}' have different pathline "
                            f"layouts ({a.layout} vs {b.layout}): use the same fuel sources, "
                            "nodes per frame and lifetime in every state")
    for s in states:
        if s.file.node_count < 2:
            raise BakeError(f"Plume: domain '{s.name}' holds {s.file.node_count} pathline "
                            "groups: bake more frames (at least twice the pathline lifetime)")
    return states


def _params(native, s: FlowGraphSettings, alpha, beta):
    p = native.FlowGraphParams()
    p.block_size = int(s.block_size)
    p.min_node_gap = int(s.min_node_gap)
    p.alpha, p.beta = float(alpha), float(beta)
    if s.epsilon > 0.0:
        p.epsilon_mode = native.EpsilonMode.EXPLICIT
        p.epsilon = float(s.epsilon)
    return p


def set_first_groups(states: List[State], s: FlowGraphSettings):
    """Sets every state's first_group to startup_groups(); BakeError when a state has fewer than
    two groups after its start-up (the bake is too short)."""
    first = startup_groups(s, states[0].file.layout)
    for st in states:
        st.first_group = first
        if st.node_count < 2:
            raise BakeError(f"Plume: domain '{st.name}' holds {st.file.node_count} pathline "
                            f"groups, {first} of them seeded while its fire starts up (the "
                            "first pathline lifetime of the bake, left out of the graph): bake "
                            "more frames (at least three times the pathline lifetime)")


def graph_nodes(states: List[State]):
    """Indices of the graph's nodes among all groups of all states (state by state): the
    groups of each state from its first_group on."""
    offsets = np.cumsum([0] + [int(st.file.node_count) for st in states])
    return np.concatenate([np.arange(o + st.first_group, o + st.file.node_count)
                           for o, st in zip(offsets, states)])


def cost_matrix(native, states: List[State], s: FlowGraphSettings,
                on_job: Optional[Callable[[object], None]] = None):
    """C of eq. 9-10 over the graph's nodes, state by state (each state's groups from its
    first_group on, set here: set_first_groups): (cost, node counts per state, FlowGraphParams
    with the weights α, β). BakeError on bad settings. The groups are streamed from the states'
    pathline files (a bounded number in memory, never all of them). on_job receives the native
    CostMatrixJob before it runs (another thread may read its progress or cancel it)."""
    set_first_groups(states, s)
    pathline_files = [st.file for st in states]
    counts = [st.node_count for st in states]
    alpha, beta = ((native.same_magnitude_weights_of_files(pathline_files)) if s.auto_weights
                   else (s.alpha, s.beta))
    try:
        params = _params(native, s, alpha, beta)
        params.validate()
        job = native.CostMatrixJob.of_files(pathline_files, params)
    except ValueError as e:
        raise BakeError(f"Plume: flow graph: {in_ui_words('flowgraph', str(e))}") from None
    if on_job is not None:
        on_job(job)
    if not job.run():
        raise BakeError("Plume: flow graph: cancelled")
    # The native job compares every group of the files; the start-up's rows and columns go.
    keep = graph_nodes(states)
    return np.ascontiguousarray(np.asarray(job.cost)[np.ix_(keep, keep)]), counts, params


def graph_of(native, cost, counts, params, eps):
    """FlowGraph.build with ε = eps (explicit), the other params as given."""
    p = native.FlowGraphParams()
    p.block_size, p.min_node_gap = params.block_size, params.min_node_gap
    p.alpha, p.beta, p.threads = params.alpha, params.beta, params.threads
    if math.isfinite(eps):
        p.epsilon_mode, p.epsilon = native.EpsilonMode.EXPLICIT, float(eps)
    return native.FlowGraph.build(cost, counts, p)


def build_graph(native, states: List[State], s: FlowGraphSettings, out_folder,
                progress: Optional[Callable[[float], None]] = None,
                on_job: Optional[Callable[[object], None]] = None):
    """Cost matrix (eq. 9-10) of every group of every state, the graph (§4.3), then
    <out_folder>/flowgraph.npz and flowgraph_cost.png (Figure 4), atomically. Returns a dict
    with the graph, its cost matrix and a summary. BakeError on bad settings (nothing written;
    when too few transitions join the states, the message gives the candidates' range [a, b]
    to choose ε from). on_job: see cost_matrix."""
    cost, counts, params = cost_matrix(native, states, s, on_job)
    alpha, beta = params.alpha, params.beta
    try:
        eps, a, b, moments = threshold(native, cost, counts, params)
        graph = graph_of(native, cost, counts, params, eps)
    except ValueError as e:
        raise BakeError(f"Plume: flow graph: {in_ui_words('flowgraph', str(e))}"
                        f"{_candidate_range(native, cost, counts, params)}"
                        ) from None
    image = native.cost_matrix_image(cost, graph, size=min(512, max(64, len(cost))))
    t = graph.transitions()
    kept = np.asarray(t["kept"], bool)
    moment = same_moment(t["row"], t["col"], counts, params.min_node_gap)
    summary = {"alpha": float(alpha), "beta": float(beta), "a": a, "b": b, "epsilon": eps,
               "candidates": int(len(kept)), "kept": int(np.sum(kept)),
               "same_moment": moments, "same_moment_kept": int(np.sum(kept & moment)),
               "pruned": [int(v) for v in graph.pruned_per_state],
               "nodes": [int(v) for v in counts],
               "startup": [int(st.first_group) for st in states]}
    os.makedirs(out_folder, exist_ok=True)
    files.save_npz(graph_path(out_folder), compressed=True, cost=cost,
                   state_node_counts=np.asarray(counts, np.int64),
                   state_names=np.asarray([st.name for st in states]),
                   state_folders=np.asarray([st.folder for st in states]),
                   first_groups=np.asarray([st.first_group for st in states], np.int64),
                   threshold=np.asarray([eps, a, b], np.float64),
                   settings=np.asarray([s.block_size, s.min_node_gap, s.epsilon, alpha, beta],
                                       np.float64))
    files.write_bytes(image_path(out_folder), png_rgb(np.asarray(image)))
    if progress is not None:
        progress(1.0)
    return {"graph": graph, "cost": cost, "summary": summary, "params": params}


def _candidate_range(native, cost, counts, params):
    """' (the candidate costs span [a, b] = ...)' for an error message, or '' when the
    candidates cannot be selected either (the message already says why)."""
    try:
        t = native.select_transitions(cost, counts, params)
    except ValueError:
        return ""
    return (f" (the candidate transition costs span [a, b] = [{t['a']:.4g}, {t['b']:.4g}]: an "
            "ε nearer b keeps more transitions)")


def png_rgb(rgb):
    """An 8-bit RGB PNG of a (h, w, 3) uint8 array (rows from the top)."""
    import struct
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + np.ascontiguousarray(rgb[y], np.uint8).tobytes() for y in range(h))

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def load_graph(native, folder, owner):
    """(graph, states, params) from <folder>/flowgraph.npz; BakeError when missing or stale."""
    path = graph_path(folder)
    if not os.path.isfile(path):
        raise BakeError(f"Plume: {owner} has no flow graph yet: select the fire states and "
                        f"press Build Flow Graph first ({FLOWGRAPH})")
    try:
        with np.load(path, allow_pickle=False) as data:
            cost = np.array(data["cost"])
            counts = [int(v) for v in data["state_node_counts"]]
            names = [str(v) for v in data["state_names"]]
            folders = [str(v) for v in data["state_folders"]]
            block, gap, eps, alpha, beta = (float(v) for v in data["settings"])
            # Graphs built before the start-up was left out begin at group 0.
            first = ([int(v) for v in data["first_groups"]] if "first_groups" in data.files
                     else [0] * len(counts))
            # The ε the graph was built with (threshold()); older graphs: the native rule.
            used = float(data["threshold"][0]) if "threshold" in data.files else None
    except (OSError, KeyError, ValueError) as e:
        raise BakeError(f"Plume: {owner}: flow graph {path} cannot be read ({e}): build it "
                        "again") from None
    states = open_states(native, list(zip(names, folders)))
    for st, f in zip(states, first):
        st.first_group = f
    if len(first) != len(states) or [st.node_count for st in states] != counts:
        raise BakeError(f"Plume: {owner}: a state was baked again after the flow graph was "
                        "built: build the flow graph again")
    s = FlowGraphSettings(block_size=int(block), min_node_gap=int(gap), epsilon=eps,
                          auto_weights=False, alpha=alpha, beta=beta)
    params = _params(native, s, alpha, beta)
    try:
        graph = (native.FlowGraph.build(cost, counts, params) if used is None
                 else graph_of(native, cost, counts, params, used))
    except ValueError as e:
        raise BakeError(f"Plume: {owner}: {in_ui_words('flowgraph', str(e))}") from None
    return graph, states


#: The prepared-group cache of the last synthesized graph, kept for the process: (key,
#: PreparedGroupCache). Each synthesis from Blender is a process of its own (jobs/), so it lives
#: for one synthesis there; a script synthesizing the same graph again in one process (another
#: seed, other keys, a longer range) reads no group twice.
_SESSION_CACHE = [None, None]


def _states_key(states: List[State], budget_mb):
    """What a cached group depends on: every state's pathline file (path, size, time) in order,
    and the budget."""
    key = [int(budget_mb)]
    for st in states:
        path = cache.pathlines_path(st.folder)
        try:
            info = os.stat(path)
            key.append((os.path.abspath(path), info.st_size, info.st_mtime_ns))
        except OSError:
            key.append((os.path.abspath(path), -1, -1))
    return tuple(key)


def session_cache(native, states: List[State], budget_mb):
    """The PreparedGroupCache of this graph's states for the process (a new one, and the old one
    dropped, when the states, their files or the budget changed)."""
    key = _states_key(states, budget_mb)
    if _SESSION_CACHE[0] != key:
        _SESSION_CACHE[1] = None  # free the old groups first
        _SESSION_CACHE[:] = [key, native.PreparedGroupCache(int(budget_mb) * 1_000_000)]
    return _SESSION_CACHE[1]


def clear_session_cache():
    """Frees the session's prepared groups (a new file is loaded, the add-on unregisters)."""
    _SESSION_CACHE[:] = [None, None]


@dataclass
class SynthesisResult:
    frame_start: int
    last_frame: int
    nodes_visited: List[int] = field(default_factory=list)
    transitions_taken: int = 0
    transition_hold: int = 0    # H, node steps (the transition state)
    #: (frame, state) where a keyed target state could no longer be reached (the graph does not
    #: lead back to it from where the walk was), or None
    unreachable_target: Optional[Tuple[int, int]] = None
    cancelled: bool = False
    step_seconds: float = 0.0   # the walk, reading the groups and integrating eq. 13
    write_seconds: float = 0.0  # rasterizing the particles and writing the frame VDBs
    group_reads: int = 0        # node visits whose group was read from its file (not cached)


class SynthesisRunner:
    """Walks the graph (§5.1) and integrates the visited nodes' particles (§5.2, eq. 13), one
    node per node step, nodes_per_frame steps per frame; writes fire/fire_<frame>.vdb (density,
    temperature, flame) after each frame, fire/points_<frame>.npz with point_preview, and at the
    end fire/walk.npz (write_walk). progress(done, total) and cancel() are optional. After a
    transition the walk holds for transition_hold_steps() node steps (the transition state of
    §5). With emitter_transforms each node step's group is placed by its E
    (Synthesizer.emitter_transform: the fire source). BakeError (naming `owner`) for a hold no
    state can keep or transforms of the wrong count.

    run(write=(first, last)) is one farm task's part (flowgraph_chunks.py): the walk and the
    particles are stepped from frame_start, as every frame depends on the node steps before it,
    but only frames first..last are written, and the walk file only when last is frame_end.
    Stepping costs a small part of a frame (about 2 of 38 ms at 16³), so a chunk's replay of the
    frames before it is cheap and its frames equal the whole run's bit for bit."""

    def __init__(self, native, graph, states: List[State], settings: SynthesisSettings,
                 out_folder, progress=None, cancel=None, owner="flow graph"):
        self.native, self.graph, self.states, self.s = native, graph, states, settings
        self.out_folder = out_folder
        self.progress, self.cancel = progress, cancel
        f = states[0].file
        self.steps_per_frame = int(f.nodes_per_frame)
        self.raster = native.FireRasterParams(
            voxel_size=float(f.cell_size), origin=tuple(f.origin),
            ignition_temperature=settings.ignition_temperature,
            max_temperature=settings.max_temperature,
            sheet_interval=float(f.layout.sample_dt))  # a group is emitted every node step
        self.hold = transition_hold_steps(settings, f.layout, self.steps_per_frame,
                                          [(st.name, st.node_count) for st in states], owner)
        self.walk = native.RandomWalk(
            graph, int(settings.seed),
            bias=(native.WalkBias.TEMPORAL if settings.traversal == 'BIASED'
                  else native.WalkBias.UNIFORM),
            gamma=float(settings.gamma), start_state=int(settings.start_state),
            transition_hold=self.hold)
        self.placements = settings.emitter_transforms
        steps = (settings.frame_end - settings.frame_start + 1) * self.steps_per_frame
        if self.placements is not None and np.shape(self.placements) != (steps, 4, 4):
            raise BakeError(f"Plume: {owner}: the fire source's transforms cover "
                            f"{np.shape(self.placements)} node steps, not ({steps}, 4, 4)")
        self.node_states = np.asarray(graph.node_states)
        self.node_steps = node_groups(graph, states)  # the group in the state's file

    def external_velocity(self, i):
        """u_ext of frame index i: the uniform wind, or a VelocityField with the turbulence."""
        s = self.s
        wind = tuple(s.winds[i]) if i < len(s.winds) else (0.0, 0.0, 0.0)
        fields = s.turbulence[i] if i < len(s.turbulence) else []
        if not fields:
            return wind
        f = self.states[0].file
        t = i * self.steps_per_frame * f.layout.sample_dt  # seconds since the first frame
        u = turbulence_velocity(f.resolution, f.cell_size, f.origin, fields, t)
        u += np.asarray(wind, np.float32)
        return self.native.VelocityField(u, float(f.cell_size), tuple(f.origin))

    def run(self, write=None) -> SynthesisResult:
        s, native = self.s, self.native
        first_written, last = (s.frame_start, s.frame_end) if write is None else write
        if not s.frame_start <= first_written <= last <= s.frame_end:
            raise BakeError(f"Plume: frames {first_written}-{last} are not inside the synthesis "
                            f"range {s.frame_start}-{s.frame_end}")
        groups = session_cache(native, self.states, s.group_cache_mb)
        misses = groups.misses
        syn = native.Synthesizer(self.states[0].file.layout, 0, groups)
        result = SynthesisResult(frame_start=s.frame_start, last_frame=s.frame_start - 1,
                                 transition_hold=self.hold)
        fire_dir = os.path.join(self.out_folder, FIRE_FOLDER)
        os.makedirs(fire_dir, exist_ok=True)
        for name in os.listdir(fire_dir):  # frames of an older synthesis would mix in
            if ((name.startswith("fire_") and name.endswith(".vdb"))
                    or (name.startswith("points_") and name.endswith(".npz"))
                    or name == WALK_NAME):
                os.remove(os.path.join(fire_dir, name))
        total = last - s.frame_start + 1
        node = self.walk.current
        for i in range(total):
            if self.cancel is not None and self.cancel():
                result.cancelled = True
                break
            target = s.targets[i] if i < len(s.targets) else -1
            if (target >= 0 and result.unreachable_target is None
                    and self.walk.target_distance(node, target, self.walk.hold_remaining) < 0):
                result.unreachable_target = (s.frame_start + i, target)
            wind = self.external_velocity(i)
            t0 = time.perf_counter()
            for j in range(self.steps_per_frame):
                state = int(self.node_states[node])
                if self.placements is not None:
                    syn.emitter_transform = self.placements[i * self.steps_per_frame + j]
                syn.step_node(self.states[state].file, int(self.node_steps[node]), state, wind)
                result.nodes_visited.append(int(node))
                nxt = self.walk.next(target)
                if nxt != node + 1 or self.node_states[nxt] != state:
                    result.transitions_taken += 1
                node = nxt
            frame = s.frame_start + i
            t1 = time.perf_counter()
            if frame >= first_written:
                syn.write_vdb(fire_path(self.out_folder, frame), self.raster, frame)
                if s.point_preview:
                    write_points(points_path(self.out_folder, frame), syn.particles(),
                                 s.preview_points)
            result.step_seconds += t1 - t0
            result.write_seconds += time.perf_counter() - t1
            result.last_frame = frame
            if self.progress is not None:
                self.progress(i + 1, total)
        result.group_reads = groups.misses - misses
        if write is None or result.last_frame == s.frame_end:  # a chunk's walk is partial
            write_walk(walk_path(self.out_folder), result.nodes_visited, self.node_states,
                       self.node_steps, s.frame_start, self.steps_per_frame, self.hold,
                       result.unreachable_target)
        return result
