"""A campfire in three wind strengths, synthesized for as long as you like: the campfire of
[Graph Fire Synthesis] (Table 1, Figure 1).

    blender -b --factory-startup --python examples/flowgraph_fire/campfire.py -- OUT_DIR [FRAMES]

Three fire domains on the same 2 x 1 x 1 m box at 128 x 64 x 64 (Table 1's grid) are the three
states, in name order: "State0 Calm" (no wind), "State1 Breeze" and "State2 Gale" (the air is
pulled towards a wind along +x). One fuel Source, a round burner on the floor under four logs,
feeds all of them; its feed flickers with smooth noise that never repeats (random velocity and fuel
keyed every 4 frames, half a puff at the puffing rate of a fire that size, ~3 Hz), the same keys
for every state; cooling c = 20 (half fire_domain's) for taller flames. Each state is a fire bake
of 100 frames with Record Pathlines on: every node step (a third of a frame) a group of pathlines
is seeded at Δx/2 spacing in the burner and followed for t_max (§4.2). Build Flow Graph joins the
three states into one graph with the paper's settings (transition costs of eqs. 9-10 over the
pathlines' whole lifetime, blocks of B = 32, ε = (2a+b)/3, dead ends and traps pruned; the cost
matrix is drawn like Figure 4; each bake's first t_max, its start-up from still air, left out), and
Synthesize Fire walks it for FRAMES frames (default 600 = 25 s, far longer than any bake), steered
by keyed target states: calm, then gale from a quarter of the shot, then breeze from 60% on. Every
frame the live particles are rasterized into a VDB (density, temperature, flame) that a Volume
object with Plume's fire material plays (emission strength raised to
flowgraph_kit.FLOWGRAPH_FIRE_EMISSION), seen by a camera framed on the fire. Then one transition the
walk took is shown: five synthesized frames around it above the same frames of the destination
state played straight (transition_strip.py).

Writes OUT_DIR/campfire.blend, the caches in OUT_DIR/plume_cache (the graph and the synthesized
fire/fire_####.vdb and the walk fire/walk.npz with state 0), campfire_cost.png (the cost
matrix), campfire_####.png for a few frames, campfire_strip.png, campfire_transition.png (the
manual's images; its frames are campfire_transition_####.png and campfire_straight_####.png,
the straight run's VDBs in OUT_DIR/campfire_straight). Prints the bake time per state and per
frame, the pathline files (size, bytes per node, RAM of the graph build), the graph (nodes,
candidates, transitions kept, pruned nodes) and its build time, the transitions the walk took,
the synthesis and render times. Needs the Plume add-on installed (README). The synthesis cost
split and its ratio to the simulation: examples/flowgraph_fire/flowgraph_speed.py OUT_DIR after
this.
"""

import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flowgraph_kit  # noqa: E402
import scene_kit  # noqa: E402
import transition_strip  # noqa: E402

TAG = "campfire"
USAGE = (f"usage: blender -b --factory-startup --python examples/flowgraph_fire/{TAG}.py -- "
         "OUT_DIR [FRAMES]")
RESOLUTION = 128               # cells along x: 128 x 64 x 64 (Table 1)
BOX = (2.0, 1.0, 1.0)          # m; the floor at z = 0
CENTRE = (0.0, 0.0, 0.5)
BURNER = (-0.45, 0.0, 0.0465)  # upwind of the centre, so the gale's flame stays in the box
BURNER_SIZE = (0.24, 0.24, 0.027)  # two cell layers, 420 fuel cells: |Ω| = 3,360 seeds
# Memory of the graph build: |Ω| L 20 B per node and BAKE_FRAMES NODES_PER_FRAME - L + 2 nodes
# per state: 3,360 x 43 x 20 B = 2.9 MB per node, 259 nodes per state, 2.2 GB for three.
NODES_PER_FRAME = 3            # Δt_n = 1/72 s: the fast gale's particle sheets stay ~1 cell apart
LIFETIME = 0.6                 # t_max, s: L = 43; the flame has cooled or left the box by then
BAKE_FRAMES = 100              # 4.2 s per state (> 2 t_max), 259 nodes: more than 8 blocks of B
#: Build Flow Graph (§4.3) with the paper's settings: blocks of B = 32 (the add-on's default),
#: 648 nodes (each state's first 43 groups, its start-up, left out), 21 blocks per side (the
#: paper's 868 nodes in B = 32 give 28), ε = (2a + b)/3 (the
#: default). Transitions between groups at least 16 node steps (5 frames) apart, so no loop
#: replays the same few groups at a visible rhythm.
GRAPH = dict(block_size=32, min_node_gap=16)
DEFAULT_FRAMES = 600
#: (name, wind m/s along +x, wind strength k_w 1/s); names sort in state order. Neighbouring
#: states must share some similar pathline groups for the graph to join them (§4.3).
STATES = (("State0 Calm", 0.0, 0.0), ("State1 Breeze", 0.5, 2.0), ("State2 Gale", 1.0, 3.0))
#: Keyed target states: (fraction of the shot, state).
TARGETS = ((0.0, 0), (0.25, 2), (0.6, 1))
SHOW = (0.2, 0.45, 0.55, 0.9)  # rendered frames: calm, gale, gale, breeze
LOG_COLOR = (0.012, 0.006, 0.003)
COOLING = 20.0                 # c: half fire_domain's 40, so the flames stand taller and hotter
PUFF_KEYS = 4                  # frames between the feed's keys: half a puff at ~3 Hz, 1.5/√D for
                               # D = 0.24 m (the noise has no period)


def make_states(frames_baked):
    burner = flowgraph_kit.fuel_source("Burner", bpy.ops.mesh.primitive_cylinder_add, BURNER,
                                   BURNER_SIZE)
    # One feed for all three states: the noise keyed once.
    flowgraph_kit.flicker(burner, speed=1.0, fuel_share=0.4, frames=frames_baked, key_every=PUFF_KEYS)
    domains = []
    for name, speed, strength in STATES:
        dom = flowgraph_kit.fire_domain(name, BOX, CENTRE, RESOLUTION, frames_baked,
                                    NODES_PER_FRAME, LIFETIME)
        d = dom.plume.domain
        d.wind, d.wind_strength, d.cooling_rate = (speed, 0.0, 0.0), strength, COOLING
        domains.append(dom)
    return domains


def logs():
    """Four dark logs crossed under the burner (only drawn: no Plume objects)."""
    x, y, _ = BURNER
    for n, (dx, dy, z, along_x) in enumerate(((0.0, -0.1, 0.035, True), (0.0, 0.1, 0.035, True),
                                              (-0.1, 0.0, 0.095, False),
                                              (0.1, 0.0, 0.095, False))):
        log = scene_kit.flat_box(f"Log{n}", (x + dx, y + dy, z), (0.07, 0.07, 0.42), LOG_COLOR,
                                 add_primitive=bpy.ops.mesh.primitive_cylinder_add)
        log.rotation_euler = (0.0, math.radians(90.0), 0.0) if along_x else (
            math.radians(90.0), 0.0, 0.0)


def setup(scene):
    domains = make_states(BAKE_FRAMES)
    logs()
    # Framed on the fire: 2.4 m in front of it (1.7 x 0.96 m in view), a little downwind of the
    # burner so that the gale's leaning flame stays in the picture.
    scene_kit.camera(scene, (-0.3, -2.4, 0.45), lens=50.0, target=(-0.3, 0.0, 0.42))
    return domains


def main():
    scene, keeper, fire, out_dir = flowgraph_kit.flowgraph_example(TAG, USAGE, DEFAULT_FRAMES, setup,
                                                               TARGETS, SHOW, GRAPH)
    print(f"{TAG}: transition strip -> "
          f"{transition_strip.transition_strip(scene, keeper, fire, out_dir, TAG)}", flush=True)


if __name__ == "__main__":
    main()
