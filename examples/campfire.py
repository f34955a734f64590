"""A campfire in three wind strengths, synthesized for as long as you like: the campfire of
graph_fire_synthesis.txt (Table 1, Figure 1).

    blender -b --factory-startup --python examples/campfire.py -- OUT_DIR [FRAMES]

Three fire domains on the same 2 x 1 x 1 m box at 128 x 64 x 64 (Table 1's grid) are the three
states, in name order: "State0 Calm" (no wind), "State1 Breeze" and "State2 Gale" (the air is
pulled towards a wind along +x). One fuel Source, a round burner on the floor, feeds all of them.
Each state is a short fire bake with Record Pathlines on: every node step (half a frame) a group
of pathlines is seeded at Δx/2 spacing in the burner and followed for t_max (§4.2). Build Flow
Graph joins the three states into one graph (transition costs of eqs. 9-10 over the pathlines'
whole lifetime, blocks of B = 32, dead ends pruned; the cost matrix is drawn like Figure 4), and
Synthesize Fire walks it for FRAMES frames (default 600 = 25 s, far longer than any bake),
steered by keyed target states: calm, then gale from a quarter of the shot, then breeze from
60% on. Every frame the live particles are rasterized into a VDB (density, temperature, flame)
that a Volume object with Plume's fire material plays.

Writes OUT_DIR/campfire.blend, the caches in OUT_DIR/plume_cache (the graph and the synthesized
fire/fire_####.vdb with state 0), campfire_cost.png (the cost matrix), campfire_####.png for a
few frames and campfire_strip.png (the README's images). Prints the bake time per state and per
frame, the pathline files (size, bytes per node, RAM of the graph build), the graph build time,
the synthesis and render times. Needs the Plume add-on installed (README). The synthesis cost
split and its ratio to the simulation: examples/flowgraph_speed.py OUT_DIR after this.
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scene_kit  # noqa: E402

TAG = "campfire"
USAGE = f"usage: blender -b --factory-startup --python examples/{TAG}.py -- OUT_DIR [FRAMES]"
RESOLUTION = 128               # cells along x: 128 x 64 x 64 (Table 1)
BOX = (2.0, 1.0, 1.0)          # m; the floor at z = 0
CENTRE = (0.0, 0.0, 0.5)
BURNER = (-0.45, 0.0, 0.05)    # upwind of the centre, so the gale's flame stays in the box
BURNER_SIZE = (0.24, 0.24, 0.03)  # two cell layers: ~370 fuel cells, ~2,900 seeds
# Memory of the graph build: |Ω| L 20 B per node, nodes = BAKE_FRAMES NODES_PER_FRAME - L + 2
# per state. About 2,900 seeds x 36 samples: 2.1 MB per node, ~190 nodes per state: ~1.2 GB.
NODES_PER_FRAME = 2            # Δt_n = 1/48 s
LIFETIME = 0.75                # t_max, s: the flame has cooled and risen out of the box by then
BAKE_FRAMES = 112              # 4.7 s per state (>= 2 t_max)
BLOCK_SIZE = 32                # B (§4.3)
DEFAULT_FRAMES = 600
#: (name, wind m/s along +x, wind strength k_w 1/s); names sort in state order.
STATES = (("State0 Calm", 0.0, 0.0), ("State1 Breeze", 1.0, 2.0), ("State2 Gale", 2.5, 4.0))
#: Keyed target states: (fraction of the shot, state).
TARGETS = ((0.0, 0), (0.25, 2), (0.6, 1))
SHOW = (0.2, 0.45, 0.55, 0.9)  # rendered frames: calm, gale, gale, breeze


def fire_settings(d):
    """What every state shares: combustion (eqs. 3-5) giving a flame whose hot part is short
    (strong cooling c: the quartic cooling drops T from T_max to half in ~0.1 s), strong
    vorticity confinement for the flame's curls, and Mantaflow's faster solver settings
    (MacCormack, trilinear, Euler back-traces, pressure tolerance 1e-3), about 4x cheaper than
    Plume's defaults at this grid."""
    d.vorticity = 0.8
    d.burn_rate, d.heat_yield, d.soot_yield = 6.0, 6.0, 0.3
    d.cooling_rate, d.max_temperature = 40.0, 4.0
    d.advection, d.interpolation, d.trace = 'MACCORMACK', 'LINEAR', 'EULER'
    d.pressure_tolerance = 1e-3


def make_states(frames_baked):
    burner = scene_kit.fuel_source("Burner", bpy.ops.mesh.primitive_cylinder_add, BURNER,
                                   BURNER_SIZE)
    scene_kit.flicker(burner, speed=0.6, fuel_share=0.4, frames_scale=4.0)
    domains = []
    for name, speed, strength in STATES:
        dom = scene_kit.fire_domain(name, BOX, CENTRE, RESOLUTION, frames_baked,
                                    NODES_PER_FRAME, LIFETIME)
        d = dom.plume.domain
        fire_settings(d)
        d.wind, d.wind_strength = (speed, 0.0, 0.0), strength
        domains.append(dom)
    return domains


def setup(scene, frames, out_dir):
    domains = make_states(BAKE_FRAMES)
    scene_kit.camera(scene, (0.0, -3.2, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.cycles(scene, 400, 220, 64, os.path.join(out_dir, TAG + "_"))
    scene_kit.plain_world(scene, (0.002, 0.002, 0.003))
    keys = [(max(1, round(f * frames)), state) for f, state in TARGETS]
    return domains, keys


def main():
    scene_kit.flowgraph_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, BLOCK_SIZE)


if __name__ == "__main__":
    main()
