"""Flow-graph fire settings, no ``bpy`` (graph_fire_synthesis.txt): Build Flow Graph's (§4.3) and
Synthesize Fire's (§5), and their validation (BakeError naming the setting)."""

import math
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import numpy as np

from .ranges import RANGES
from .settings import BakeError

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
        raise BakeError(f"Plume: {owner}: block_size (B) must be >= 1 (got {s.block_size})")
    if s.min_node_gap < 0:
        raise BakeError(f"Plume: {owner}: min_node_gap must be >= 0 (got {s.min_node_gap})")
    if s.startup_groups < -1:
        raise BakeError(f"Plume: {owner}: startup_groups must be -1 (the pathline lifetime) or "
                        f">= 0 (got {s.startup_groups})")
    if not (math.isfinite(s.epsilon) and s.epsilon >= 0.0):
        raise BakeError(f"Plume: {owner}: epsilon (ε) must be 0 (automatic: (2a+b)/3) or a "
                        f"cost in [a, b] (got {s.epsilon})")
    for name in ("alpha", "beta"):
        v = getattr(s, name)
        if not s.auto_weights and not (math.isfinite(v) and v >= 0.0):
            raise BakeError(f"Plume: {owner}: {name} must be >= 0 (got {v})")


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
        raise BakeError(f"Plume: {owner}: Transition Hold ({what} = {hold} node steps, "
                        f"{hold / nodes_per_frame:.2f} frames) is longer than the bake of state "
                        f"'{name}' ({nodes} node steps): choose at most "
                        f"{(nodes - 1) / nodes_per_frame:.2f} Hold Frames, or bake the states "
                        "longer")
    return hold


def validate_synthesis(s: SynthesisSettings, state_count, owner):
    if s.frame_end < s.frame_start:
        raise BakeError(f"Plume: {owner}: synthesis frame_end must be >= frame_start "
                        f"(got {s.frame_start}..{s.frame_end})")
    if s.traversal not in TRAVERSALS:
        raise BakeError(f"Plume: {owner}: traversal must be one of {', '.join(TRAVERSALS)}")
    if not (0.0 < s.gamma < 1.0):
        raise BakeError(f"Plume: {owner}: gamma (γ) must be in (0, 1) (got {s.gamma})")
    if s.transition_hold not in TRANSITION_HOLDS:
        raise BakeError(f"Plume: {owner}: transition_hold must be one of "
                        f"{', '.join(TRANSITION_HOLDS)} (got {s.transition_hold!r})")
    if s.transition_hold == 'CUSTOM' and not (math.isfinite(s.transition_hold_frames)
                                              and s.transition_hold_frames >= 0.0):
        raise BakeError(f"Plume: {owner}: Hold Frames (transition_hold_frames) must be >= 0 "
                        f"(got {s.transition_hold_frames})")
    if not (0 <= s.start_state < state_count):
        raise BakeError(f"Plume: {owner}: start_state must be in [0, {state_count - 1}] "
                        f"(got {s.start_state})")
    bad = [t for t in s.targets if not (-1 <= t < state_count)]
    if bad:
        raise BakeError(f"Plume: {owner}: target_state must be -1 (none) or in [0, "
                        f"{state_count - 1}] (got {bad[0]})")
    if not (0.0 <= s.ignition_temperature < s.max_temperature):
        raise BakeError(f"Plume: {owner}: the fire needs 0 <= ignition temperature < max "
                        f"temperature (got {s.ignition_temperature}, {s.max_temperature})")
    lo, hi = PREVIEW_POINTS_RANGE
    if s.point_preview and not (lo <= s.preview_points <= hi):
        raise BakeError(f"Plume: {owner}: preview_points must be in [{lo}, {hi}] "
                        f"(got {s.preview_points})")
    lo, hi = RANGES["flowgraph.group_cache"]
    if not (lo <= s.group_cache_mb <= hi):
        raise BakeError(f"Plume: {owner}: group_cache must be in [{lo}, {hi}] MB "
                        f"(got {s.group_cache_mb})")
