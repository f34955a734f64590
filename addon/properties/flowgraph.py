"""``obj.plume.domain.flowgraph``: flow-graph fire settings of the domain that holds the graph
([Graph Fire Synthesis] §4.3-5.2), read by plume.flowgraph_build and plume.fire_synthesize.
Soft limits only: the operators validate with messages naming the setting and its range."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from ..ranges import RANGES


class PlumeFlowGraphSettings(bpy.types.PropertyGroup):
    # --- Graph (§4.3) ---
    block_size: IntProperty(
        name="Block Size (B)", default=32, soft_min=1, soft_max=256,
        description="B: the cost matrix is cut into B×B blocks and each block's minimum is a "
                    "candidate transition; at most (N/B)² transitions (§4.3); >= 1")
    epsilon: FloatProperty(
        name="Threshold (ε)", default=0.0, min=0.0, precision=4,
        description="ε of eq. 11: candidates cheaper than ε become transitions. 0 = (2a+b)/3 "
                    "(the paper's), a and b the cheapest and dearest candidate; else in [a, b]")
    auto_weights: BoolProperty(
        name="Automatic Weights", default=True,
        description="α and β bring the velocity, density and temperature terms of eq. 9 to one "
                    "order of magnitude over the data")
    alpha: FloatProperty(name="α (Density)", default=1.0, min=0.0,
                         description="Weight of the soot density difference in eq. 9")
    beta: FloatProperty(name="β (Temperature)", default=1.0, min=0.0,
                        description="Weight of the temperature difference in eq. 9")
    min_node_gap: IntProperty(
        name="Min Node Gap", default=8, min=0, soft_max=64,
        description="Transitions between nodes of one state closer than this many node steps "
                    "are dropped (§4.3: they would stutter)")
    startup_groups: IntProperty(
        name="Start-up Groups", default=-1, min=-1, soft_max=256,
        description="Pathline groups left out at the start of every state: those seeded while "
                    "its bake starts up from still air, alike in states fed alike, whose cheap "
                    "hops would set the threshold's a. -1 = one pathline lifetime")
    # --- Synthesis (§5) ---
    frame_start: IntProperty(name="Start", default=1, description="First synthesized frame")
    frame_end: IntProperty(name="End", default=250, description="Last synthesized frame")
    seed: IntProperty(name="Seed", default=0, min=0,
                      description="Seed of the random walk (same seed, same fire)")
    traversal: EnumProperty(
        name="Traversal", default='BIASED',
        description="How the random walk picks the next node of the flow graph",
        items=(('UNIFORM', "Random", "Every out-edge equally likely, p = 1/d(V_i) (§5.1)"),
               ('BIASED', "Temporal Bias", "The temporal edge with probability γ, the "
                                           "transitions share 1 − γ (eq. 12)")))
    gamma: FloatProperty(name="γ", default=0.875, min=0.0, max=1.0,
                         description="γ of eq. 12: probability of following the temporal edge; "
                                     "in (0, 1)")
    transition_hold: EnumProperty(
        name="Transition Hold", default='LIFETIME',
        items=(('LIFETIME', "Lifetime", "After a transition, follow the simulation (temporal "
                                        "edges only) until the particles emitted before it have "
                                        "died, t_max: the paper's transition state (§5)"),
               ('CUSTOM', "Custom", "Hold for Hold Frames after each transition"),
               ('OFF', "Off", "A transition may follow another at any node step (§5.1 alone)")),
        description="The transition state of §5: after a transition the walk holds to the "
                    "simulation's time line, so the old particles never mix with a second jump")
    transition_hold_frames: FloatProperty(
        name="Hold Frames", default=1.0, min=0.0, soft_max=100.0,
        description="Frames the walk holds after a transition (Custom); less than the shortest "
                    "state's bake")
    fire_source: PointerProperty(
        name="Fire Source", type=bpy.types.Object,
        description="A mesh the synthesized fire is attached to (the paper's fire blade): each "
                    "pathline group is emitted in this object's transform at its emission time, "
                    "relative to its pose at the first synthesized frame, and then rises in "
                    "world space, so a moving object trails fire. Empty: the fire burns where it "
                    "was baked")
    start_state: IntProperty(name="Start State", default=0, min=0,
                             description="The walk starts at node 0 of this state")
    target_state: IntProperty(
        name="Target State", default=-1, min=-1,
        description="Steer the walk into this state (§5.1) and stay there; -1: no target. Key "
                    "it over the timeline to move the fire between states")
    wind: FloatVectorProperty(
        name="Wind", size=3, subtype='VELOCITY', default=(0.0, 0.0, 0.0),
        description="Uniform external velocity u_ext of eq. 13 (m/s); keyable")
    use_force_fields: BoolProperty(
        name="Force Fields", default=True,
        description="Add the scene's force fields to u_ext: a Wind field adds Strength m/s "
                    "along its Z axis, a Turbulence field a divergence-free swirl of RMS speed "
                    "Strength m/s and wavelength Size (falloff ignored)")
    point_preview: BoolProperty(
        name="Point Preview", default=False,
        description="Synthesize Fire also writes the live particles of each frame "
                    "(fire/points_####.npz) and shows them as the points of a mesh object "
                    "\"<domain>_fire_points\", coloured by temperature")
    preview_points: IntProperty(
        name="Preview Points", default=20000, min=RANGES["flowgraph.preview_points"][0],
        max=RANGES["flowgraph.preview_points"][1],
        description="At most this many points per frame in the point preview: more live "
                    "particles are thinned evenly (every (live / this)-th); 100 to 1,000,000")
    group_cache: IntProperty(
        name="Group Cache (MB)", default=2048, min=RANGES["flowgraph.group_cache"][0],
        max=RANGES["flowgraph.group_cache"][1],
        description="Memory kept for prepared pathline groups between visits of the random "
                    "walk during one synthesis: a revisited node is not read from its "
                    "pathlines.bin again (0: read every visit); 0 to 65,536 MB")
    # --- Built data ---
    summary: StringProperty(name="Graph", default="", description="Summary of the last build")
    state_names: StringProperty(name="States", default="",
                                description="The states of the graph, in order")
    fire_object: StringProperty(name="Fire Object", default="",
                                description="Volume object of the synthesized fire")
    points_object: StringProperty(name="Points Object", default="",
                                  description="Mesh object of the fire's point preview")


classes = (PlumeFlowGraphSettings,)
