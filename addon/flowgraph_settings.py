"""Flow-graph fire settings, no ``bpy`` ([Graph Fire Synthesis]): Build Flow Graph's (§4.3) and
Synthesize Fire's (§5), their validation (BakeError naming the setting), and what the graph's
settings come to on given data: the start-up left out, the threshold ε of eq. 11, the velocity
of the Turbulence fields a synthesis feels."""

import math
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import numpy as np

from .ranges import RANGES
from .settings import BakeError
from .ui_words import TAB, label, ui

TRAVERSALS = ('UNIFORM', 'BIASED')
#: The transition state of §5: hold for the pathlines' lifetime, for transition_hold_frames, or not.
TRANSITION_HOLDS = ('LIFETIME', 'CUSTOM', 'OFF')
#: Range of SynthesisSettings.preview_points (points per frame of the preview).
PREVIEW_POINTS_RANGE = RANGES["flowgraph.preview_points"]


@dataclass
class FlowGraphSettings:
    """§4.3: weights of eq. 9, the block size B and ε of eq. 11."""

    block_size: int = 32        # B
    epsilon: float = 0.0        # ε; 0 = (2a + b) / 3
    auto_weights: bool = True   # α, β bringing the three terms to one order of magnitude
    alpha: float = 1.0          # α (density) when not automatic
    beta: float = 1.0           # β (temperature) when not automatic
    min_node_gap: int = 8       # transitions between nodes this close in one state are dropped
    #: groups left out at the start of every state, seeded while its fire starts up from still
    #: air; -1 = the pathlines' lifetime L (flowgraph.startup_groups)
    startup_groups: int = -1


@dataclass
class SynthesisSettings:
    """§5: the random walk and what the synthesized particles feel. targets[f] and winds[f] are
    the keyed target state (-1: none) and uniform wind (m/s) of frame frame_start + f."""

    frame_start: int = 1
    frame_end: int = 200
    seed: int = 0
    traversal: str = 'BIASED'   # UNIFORM: p = 1/d(V_i); BIASED: eq. 12 with γ
    gamma: float = 0.875        # γ of eq. 12
    start_state: int = 0
    transition_hold: str = 'LIFETIME'   # TRANSITION_HOLDS
    transition_hold_frames: float = 1.0  # with 'CUSTOM'
    targets: List[int] = field(default_factory=list)
    winds: List[Tuple[float, float, float]] = field(default_factory=list)
    ignition_temperature: float = 1.0
    max_temperature: float = 4.0
    #: turbulence[f]: the Turbulence force fields of frame f as (strength, size, seed) each
    turbulence: List[List[Tuple[float, float, int]]] = field(default_factory=list)
    #: also write fire/points_<frame>.npz: at most preview_points live particles per frame
    point_preview: bool = False
    preview_points: int = 20000
    #: E per node step (frame f's steps at (f - frame_start) * nodes_per_frame ...): the fire
    #: source's transform relative to its pose at frame_start, (K, 4, 4); None: no fire source
    emitter_transforms: Optional[np.ndarray] = None
    #: MB of prepared pathline groups the native Synthesizer keeps between visits of the walk
    #: (least recently used out); 0 reads every visit from its file
    group_cache_mb: int = 2048


def validate_graph_settings(s: FlowGraphSettings, owner):
    if s.block_size < 1:
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'block_size')} must be >= 1 "
                        f"(got {s.block_size})")
    if s.min_node_gap < 0:
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'min_node_gap')} must be >= 0 "
                        f"(got {s.min_node_gap})")
    if s.startup_groups < -1:
        raise BakeError(f"Plume: {owner}: the start-up groups left out must be -1 (the pathline "
                        f"lifetime) or >= 0 (got {s.startup_groups})")
    if not (math.isfinite(s.epsilon) and s.epsilon >= 0.0):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'epsilon')} must be 0 (automatic: "
                        f"(2a+b)/3) or a cost in [a, b] (got {s.epsilon:g})")
    for name in ("alpha", "beta"):
        v = getattr(s, name)
        if not s.auto_weights and not (math.isfinite(v) and v >= 0.0):
            raise BakeError(f"Plume: {owner}: {ui('flowgraph', name)} must be >= 0 (got {v:g}), "
                            f"or turn on {label('flowgraph', 'auto_weights')}")


def transition_hold_steps(s: SynthesisSettings, layout, nodes_per_frame, state_nodes, owner):
    """H of the transition state in node steps: the pathlines' lifetime L ('LIFETIME'),
    transition_hold_frames x nodes per frame ('CUSTOM', rounded) or 0 ('OFF'). BakeError when
    no state is long enough to keep it: a hold must end inside the shortest state's bake
    (state_nodes: (name, node count) per state)."""
    if s.transition_hold == 'OFF':
        return 0
    hold = (int(layout.samples) if s.transition_hold == 'LIFETIME'
            else int(round(s.transition_hold_frames * nodes_per_frame)))
    name, nodes = min(state_nodes, key=lambda sn: sn[1])
    if hold > nodes - 1:
        what = ("the pathline lifetime" if s.transition_hold == 'LIFETIME'
                else f"Hold Frames {s.transition_hold_frames:g}")
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'transition_hold')} ({what} = "
                        f"{hold} node steps, {hold / nodes_per_frame:.2f} frames) is longer than "
                        f"the bake of state '{name}' ({nodes} node steps): set Transition Hold to "
                        f"Custom with at most {(nodes - 1) / nodes_per_frame:.2f} Hold Frames, or "
                        "bake the states longer")
    return hold


def validate_synthesis(s: SynthesisSettings, state_count, owner):
    if s.frame_end < s.frame_start:
        raise BakeError(f"Plume: {owner}: Synthesis {ui('flowgraph', 'frame_end')} must be >= "
                        f"{label('flowgraph', 'frame_start')} (got {s.frame_start} to "
                        f"{s.frame_end})")
    if s.traversal not in TRAVERSALS:
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'traversal')} must be Random or "
                        f"Temporal Bias (got {s.traversal!r})")
    if not (0.0 < s.gamma < 1.0):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'gamma')} must be in (0, 1) "
                        f"(got {s.gamma:g})")
    if s.transition_hold not in TRANSITION_HOLDS:
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'transition_hold')} must be "
                        f"Lifetime, Custom or Off (got {s.transition_hold!r})")
    if s.transition_hold == 'CUSTOM' and not (math.isfinite(s.transition_hold_frames)
                                              and s.transition_hold_frames >= 0.0):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'transition_hold_frames')} must be "
                        f">= 0 (got {s.transition_hold_frames:g})")
    if not (0 <= s.start_state < state_count):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'start_state')} must be in "
                        f"[0, {state_count - 1}], one of the graph's states (got {s.start_state})")
    bad = [t for t in s.targets if not (-1 <= t < state_count)]
    if bad:
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'target_state')} must be -1 (none) "
                        f"or in [0, {state_count - 1}], one of the graph's states (got {bad[0]})")
    if not (0.0 <= s.ignition_temperature < s.max_temperature):
        raise BakeError(f"Plume: {owner}: the fire needs 0 <= ignition temperature < Max "
                        f"Temperature (T_max) ({TAB} › Combustion) (got "
                        f"{s.ignition_temperature}, {s.max_temperature})")
    lo, hi = PREVIEW_POINTS_RANGE
    if s.point_preview and not (lo <= s.preview_points <= hi):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'preview_points')} must be in "
                        f"[{lo}, {hi}] (got {s.preview_points})")
    lo, hi = RANGES["flowgraph.group_cache"]
    if not (lo <= s.group_cache_mb <= hi):
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'group_cache')} must be in "
                        f"[{lo}, {hi}] (got {s.group_cache_mb})")


def startup_groups(s: FlowGraphSettings, layout):
    """The groups left out at the start of every state (FlowGraphSettings.startup_groups): the
    pathlines' lifetime L in node steps by default. A bake starts from still air with no fire:
    the groups seeded during its first t_max rise into a flow that is not yet the fire's (its
    first particles have not yet died, the flame is still growing). Bakes that start alike
    (the same domain, Source and feed, whatever their other settings) give nearly the same such
    groups, so without this their block minima are hops between the states' first moments,
    far cheaper than any candidate of the burning fire: a = min of the candidates falls, ε =
    (2a + b)/3 with it, and almost no transition is kept (measured in
    examples/flowgraph_fire/README.md)."""
    return int(layout.samples) if s.startup_groups < 0 else int(s.startup_groups)


def same_moment(rows, cols, counts, gap):
    """Which candidates (rows, cols: graph nodes) join groups of two different states seeded at
    the same moment of their bakes, at most max(1, gap) node steps apart (the Min Node Gap that
    makes two groups of one state "close", §4.3). Each state's nodes begin after the same
    start-up, so equal steps are equal times of the bakes."""
    offsets = np.concatenate([[0], np.cumsum(counts)])
    state = np.repeat(np.arange(len(counts)), counts)
    rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
    sr, sc = state[rows], state[cols]
    return (sr != sc) & (np.abs((rows - offsets[sr]) - (cols - offsets[sc])) <= max(1, gap))


def threshold(native, cost, counts, params):
    """ε of eq. 11 and the range [a, b] it is taken in: (ε, a, b, same-moment candidates).
    The candidates are the native block minima (§4.3). a and b are the smallest and largest
    cost of the candidates that are not same_moment() hops between states: states driven by
    the same source animation (one box, Source and feed; other wind, turbulence or burn rate)
    resemble each other at equal times all along their bakes, so such hops cost a fraction of
    any similarity of the fire with itself (0.2-0.6 against 1.2-1.7 for the fire wall's two
    states, measured), and as a they would put ε = (2a + b)/3 below nearly every other
    candidate: no loop would be kept and no walk could go on. They are still candidates and are
    kept when below ε (a change of state at the same moment of the feed, the smoothest there
    is). ε is (2a + b)/3, or params' explicit ε (checked against every candidate's range by
    the native selection). ValueError from the native selection (bad params, explicit ε)."""
    t = native.select_transitions(cost, counts, params)
    costs = np.asarray(t["cost"], np.float64)
    moment = same_moment(t["row"], t["col"], counts, params.min_node_gap)
    own = costs[~moment] if np.any(~moment) else costs
    if len(own) == 0:
        return float("nan"), float("nan"), float("nan"), 0
    a, b = float(own.min()), float(own.max())
    eps = (float(params.epsilon) if params.epsilon_mode == native.EpsilonMode.EXPLICIT
           else (2.0 * a + b) / 3.0)
    return eps, a, b, int(moment.sum())


#: Fourier modes of the turbulence velocity (enough for an irregular, smooth field).
TURBULENCE_MODES = 12


def turbulence_velocity(resolution, cell_size, origin, fields, t):
    """Cell-centred velocity (nx, ny, nz, 3) float32 of Turbulence force fields (§5.2's u_ext
    "for deforming the fire"): for each field, the curl of a random vector potential made of
    TURBULENCE_MODES plane waves of wavelength `size` (so the flow is divergence-free: each
    mode's velocity (k × a) cos(k·x + φ + ωt) is orthogonal to its k), seeded by the field's seed,
    drifting in time with ω = 2π / (size / strength), scaled to an RMS speed of `strength` m/s.
    Blender's own turbulence noise is not reachable from Python: this is Plume's reading of the
    field's Strength, Size and Seed."""
    n = tuple(int(v) for v in resolution)
    axes = [origin[a] + (np.arange(n[a], dtype=np.float64) + 0.5) * cell_size for a in range(3)]
    x = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    u = np.zeros(n + (3,), np.float64)
    for strength, size, seed in fields:
        if strength == 0.0 or size <= 0.0:
            continue
        rng = np.random.default_rng(int(seed))
        k = rng.normal(size=(TURBULENCE_MODES, 3))
        k *= (2.0 * np.pi / size) / np.linalg.norm(k, axis=1, keepdims=True)
        a = rng.normal(size=(TURBULENCE_MODES, 3))
        phase = rng.uniform(0.0, 2.0 * np.pi, TURBULENCE_MODES)
        omega = 2.0 * np.pi * abs(strength) / size
        amp = np.cross(k, a)
        amp *= abs(strength) * np.sqrt(2.0 / TURBULENCE_MODES) / np.linalg.norm(amp, axis=1,
                                                                                 keepdims=True)
        for m in range(TURBULENCE_MODES):
            u += np.cos(x @ k[m] + phase[m] + omega * t)[..., None] * amp[m]
    return u.astype(np.float32)
