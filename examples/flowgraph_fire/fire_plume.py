"""A tall plume of fire going from low to high turbulence: the fire plume of
[Graph Fire Synthesis] (Table 1: three states, 200 x 400 x 200), synthesized from three short
bakes.

    blender -b --factory-startup --python examples/flowgraph_fire/fire_plume.py -- OUT_DIR [FRAMES]

A round burner 16 cm across on the floor of a 0.5 x 0.5 x 1 m box (Table 1's proportions, 1:2:1
with the long axis up) at 64 x 64 x 128 cells (524,288: Table 1's 16,000,000 are 30.5 times as
many) feeds a plume of fire with smooth noise that never repeats (fuel and horizontal velocity
keyed every 3 frames, the same keys in all three states). Three fire domains on that box are
the three states, in name order, from low to high turbulence: "State0 Low", "State1 Medium"
and "State2 High" (vorticity confinement ε = 0.1, 0.8 and 2.5: from a smooth column to a plume
breaking into curling tongues). Each is a bake of 96 frames with Record Pathlines on; Build Flow
Graph joins them with the paper's settings (B = 32, ε = (2a+b)/3, dead ends and traps pruned,
cost matrix like Figure 4) and Synthesize Fire walks the graph for FRAMES frames (default 300),
keyed to start in the low state, go to the medium one at a third of the shot and to the high
one at two thirds (§5.1). The camera is framed on the plume; the fire material's emission
strength is flowgraph_kit.FLOWGRAPH_FIRE_EMISSION.

Writes OUT_DIR/fire_plume.blend, the caches in OUT_DIR/plume_cache, fire_plume_cost.png,
fire_plume_####.png for a few frames and fire_plume_strip.png (the manual's images); prints the
bakes, the graph (nodes, candidates, transitions kept, pruned nodes), the transitions the walk
took (fire/walk.npz), synthesis and render times. Needs the Plume add-on installed (README).
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flowgraph_kit  # noqa: E402
import scene_kit  # noqa: E402
import transition_strip  # noqa: E402

TAG = "fire_plume"
USAGE = (f"usage: blender -b --factory-startup --python examples/flowgraph_fire/{TAG}.py -- "
         "OUT_DIR [FRAMES]")
RESOLUTION = 128               # cells along the longest axis (z): 64 x 64 x 128
BOX = (0.5, 0.5, 1.0)          # m; the floor at z = 0; Table 1's 200 x 400 x 200 is 1:2:1
CENTRE = (0.0, 0.0, 0.5)
BURNER = (0.0, 0.0, 0.0117)
BURNER_SIZE = (0.16, 0.16, 0.0156)  # two cell layers (Δx = 7.8 mm): |Ω| = 8,640 seeds
PUFF_KEYS = 3                  # frames between the feed's keys: half a puff at ~1.5/√0.16 ≈ 4 Hz
# Memory of the graph build: 8,640 seeds x L = 43 samples x 20 B = 7.4 MB per node,
# 3 BAKE_FRAMES - L + 2 = 247 nodes per state, 5.5 GB for three (streamed; 1.9 GB on disk each).
NODES_PER_FRAME = 3            # Δt_n = 1/72 s
LIFETIME = 0.6                 # t_max, s: L = 43; the plume has cooled or left the box by then
BAKE_FRAMES = 96               # 4 s per state (> 2 t_max): 247 nodes, 204 after the start-up
COOLING = 12.0                 # c: slow cooling, for a tall plume
#: Build Flow Graph as in campfire.py: B = 32, ε = (2a + b)/3.
GRAPH = dict(block_size=32, min_node_gap=16)
DEFAULT_FRAMES = 300           # Table 1's 300 output steps are 100 frames at 3 node steps each
#: (name, vorticity confinement ε); names sort in state order.
STATES = (("State0 Low", 0.1), ("State1 Medium", 0.8), ("State2 High", 2.5))
TARGETS = ((0.0, 0), (1.0 / 3.0, 1), (2.0 / 3.0, 2))  # (fraction of the shot, state)
SHOW = (0.25, 0.5, 0.75, 0.95)  # rendered frames: low, medium, high, high


def setup(scene):
    burner = flowgraph_kit.fuel_source("Burner", bpy.ops.mesh.primitive_cylinder_add, BURNER,
                                   BURNER_SIZE)
    flowgraph_kit.flicker(burner, speed=0.4, fuel_share=0.4, frames=BAKE_FRAMES, key_every=PUFF_KEYS)
    domains = flowgraph_kit.fire_states(STATES, BOX, CENTRE, RESOLUTION, BAKE_FRAMES,
                                    NODES_PER_FRAME, LIFETIME, COOLING)
    # Framed on the flames: 1.15 m away, the lowest 0.63 m of the box in view (the flames
    # reach 0.4-0.5 m; the smoke above them fades out).
    scene_kit.camera(scene, (0.0, -1.15, 0.32), lens=35.0, target=(0.0, 0.0, 0.3))
    return domains


def main():
    transition_strip.example_with_walk(TAG, USAGE, DEFAULT_FRAMES, setup, TARGETS, SHOW, GRAPH)


if __name__ == "__main__":
    main()
