"""A wall of fire going from low to high turbulence: the fire wall of [Graph Fire Synthesis]
(§5.4, Table 1), synthesized from two short bakes.

    blender -b --factory-startup --python examples/flowgraph_fire/firewall.py -- OUT_DIR [FRAMES]

A long line of fuel, 1.6 m x 5 cm on the floor, burns in a 2 x 0.5 x 1 m box at 128 x 32 x 64. It
is one continuous wall: sixteen overlapping Sources, each twice as long as their spacing, so every
point of the line is fed by two of them (a cell takes the larger feed) and the fuel never stops
along it; each flickers with its own smooth noise that never repeats (fuel and a velocity across
the line, none along it, so the pieces never push the flames apart), the same keys in both
states: the feed varies along the line without a gap. Two fire domains on that box are the two states, in name order: "State0 Low" (weak
vorticity confinement: the flames rise smoothly) and "State1 High" (strong confinement: they
break into curling tongues). Each is a bake of 128 frames with Record Pathlines on; Build Flow
Graph joins them with the paper's settings (B = 32, ε = (2a+b)/3, dead ends and traps pruned,
cost matrix like Figure 4) and Synthesize Fire walks the graph for FRAMES frames (default 400),
keyed to stay in the low state for the first 40% of the shot and then steered into the high one
(§5.1). The camera looks square at the wall, which fills most of the picture's width; the
fire material's emission strength is flowgraph_kit.FLOWGRAPH_FIRE_EMISSION.

Writes OUT_DIR/firewall.blend, the caches in OUT_DIR/plume_cache, firewall_cost.png,
firewall_####.png for a few frames and firewall_strip.png (the manual's images); prints the
bake, the graph (nodes, candidates, transitions kept, pruned nodes), the transitions the walk
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

TAG = "firewall"
USAGE = (f"usage: blender -b --factory-startup --python examples/flowgraph_fire/{TAG}.py -- "
         "OUT_DIR [FRAMES]")
RESOLUTION = 128               # cells along x: 128 x 32 x 64
BOX = (2.0, 0.5, 1.0)          # m; the floor at z = 0
CENTRE = (0.0, 0.0, 0.5)
WALL = (0.0, 0.0, 0.0465)
WALL_SIZE = (1.6, 0.05, 0.027)  # three cells across, two layers: about 5,000 seeds
SEGMENTS = 16                  # overlapping feeds along the line, each 2 x 1.6 / 16 m long
SWAY = 0.3                     # m/s: the largest velocity a feed gives across the line (y)
PUFF_KEYS = 4                  # frames between a piece's feed keys: half a puff at ~3 Hz
# Memory of the graph build: about 5,000 seeds x L = 36 samples x 20 B = 3.6 MB per node,
# 3 BAKE_FRAMES - L + 2 = 350 nodes per state, 2.5 GB (streamed).
NODES_PER_FRAME = 3            # Δt_n = 1/72 s
LIFETIME = 0.5                 # t_max, s: L = 36
BAKE_FRAMES = 128              # 5.3 s per state (> 2 t_max), 350 nodes: 11 blocks of B
COOLING = 15.0                 # c: slow cooling, for tall flames along the wall
#: Build Flow Graph as in campfire.py: B = 32, ε = (2a + b)/3 (628 nodes after the states'
#: start-ups: 20 blocks per side).
GRAPH = dict(block_size=32, min_node_gap=16)
DEFAULT_FRAMES = 400
#: (name, vorticity confinement ε); names sort in state order.
STATES = (("State0 Low", 0.05), ("State1 High", 2.0))
TARGETS = ((0.0, 0), (0.4, 1))  # keyed target states: (fraction of the shot, state)
SHOW = (0.2, 0.35, 0.6, 0.9)    # rendered frames: low, low, high, high


def setup(scene):
    # The line of fuel fed by SEGMENTS overlapping pieces, each flickering on its own: a uniform
    # line would give a flow alike all along it (flat horizontal rolls); uneven feeds break it
    # into tongues. Each piece is two spacings long and centred so the pieces overlap by half
    # and reach both ends: every cell of the line is fed by one or two pieces, never none.
    spacing = WALL_SIZE[0] / SEGMENTS
    for n in range(SEGMENTS):
        x0 = max(WALL[0] - 0.5 * WALL_SIZE[0], WALL[0] - 0.5 * WALL_SIZE[0] + (n - 0.5) * spacing)
        x1 = min(WALL[0] + 0.5 * WALL_SIZE[0], x0 + 2.0 * spacing)
        piece = flowgraph_kit.fuel_source(f"Fuel{n:02d}", bpy.ops.mesh.primitive_cube_add,
                                      (0.5 * (x0 + x1), WALL[1], WALL[2]),
                                      (x1 - x0, *WALL_SIZE[1:]))
        flowgraph_kit.flicker(piece, speed=SWAY, fuel_share=0.4, frames=BAKE_FRAMES,
                          key_every=PUFF_KEYS, seed=n, along_x=False)
    domains = flowgraph_kit.fire_states(STATES, BOX, CENTRE, RESOLUTION, BAKE_FRAMES,
                                    NODES_PER_FRAME, LIFETIME, COOLING)
    # Square to the wall, slightly above it: the 1.6 m line spans about 85% of the width.
    scene_kit.camera(scene, (0.0, -1.85, 0.45), lens=35.0, target=(0.0, 0.0, 0.33))
    return domains


def main():
    transition_strip.example_with_walk(TAG, USAGE, DEFAULT_FRAMES, setup, TARGETS, SHOW, GRAPH)


if __name__ == "__main__":
    main()
