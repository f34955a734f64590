"""A burning blade swung through the air, trailing fire: the fire blade of
[Graph Fire Synthesis] (Table 1: "the fire source is attached on a dynamic mesh").

    blender -b --factory-startup --python examples/flowgraph_fire/fire_blade.py -- OUT_DIR [FRAMES]

A dark steel blade 0.8 m long and 8 cm wide stands on its back edge, its flat facing the camera;
the fuel is a thin strip (3 x 2.2 cm) along its upper edge. Two short fire bakes of that strip,
still, in a 1.4 x 0.5 x 1 m box (96 x 34 x 68 cells), from the same noise fuel feed, are the
states: "State0 Low" (weak vorticity confinement: smooth flames) and "State1 High" (strong: curling
tongues). Build Flow Graph joins them (the paper's ε = (2a+b)/3). The visible blade, parented to a
hilt that is keyed to swing it up through 50 degrees and down again, is the flow graph's **Fire
Source**: Synthesize Fire emits every node step's group of pathlines where the blade is at that
instant (its pose relative to the first frame, evaluated at the node step's subframe) and lets the
particles rise in world space, so the swing leaves a trail of fire in the air behind the edge, and
the flames stand upright whatever the blade's angle. The camera is framed on the blade and its
flames; a dim sun lights the blade's flat; the fire material's emission strength is
flowgraph_kit.FLOWGRAPH_FIRE_EMISSION. The walk holds the simulation's time line after each transition
until the old particles are gone (Transition Hold = Lifetime) and drifts from the low to the high
state halfway.

Writes OUT_DIR/fire_blade.blend, the caches in OUT_DIR/plume_cache, fire_blade_cost.png,
fire_blade_####.png for a few frames and fire_blade_strip.png (the manual's images); prints the
bake, graph, synthesis and render times. Needs the Plume add-on installed (README).
"""

import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flowgraph_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "fire_blade"
USAGE = (f"usage: blender -b --factory-startup --python examples/flowgraph_fire/{TAG}.py -- "
         "OUT_DIR [FRAMES]")
RESOLUTION = 96                # cells along x: 96 x 34 x 68
BOX = (1.4, 0.5, 1.0)          # m; the floor of the box at z = 0
CENTRE = (0.0, 0.0, 0.5)
BLADE_AT = (0.05, 0.0, 0.12)   # the blade's centre at rest (frame 1), lying along x
BLADE_SIZE = (0.8, 0.012, 0.08)  # length, thickness, width: the flat faces the camera (-y)
#: The fuel: a strip along the blade's upper edge, two cells across and about two high.
FUEL_AT = (BLADE_AT[0], BLADE_AT[1], BLADE_AT[2] + 0.5 * BLADE_SIZE[2] + 0.011)
FUEL_SIZE = (0.8, 0.03, 0.022)
HILT = (-0.4, 0.0, 0.12)       # the pivot of the swing, at the blade's inner end
NODES_PER_FRAME = 3
LIFETIME = 0.5                 # t_max, s: L = 36 node steps
BAKE_FRAMES = 96               # 4 s per state: 254 nodes each
COOLING = 15.0                 # c: slow cooling, flames tall enough to trail behind the swing
GRAPH = dict(block_size=32, min_node_gap=16)  # ε = (2a + b)/3, the paper's
DEFAULT_FRAMES = 144
#: (name, vorticity confinement ε); names sort in state order.
STATES = (("State0 Low", 0.1), ("State1 High", 1.5))
TARGETS = ((0.0, 0), (0.5, 1))
SHOW = (0.2, 0.4, 0.55, 0.75)
#: The swing: (frame as a fraction of the shot, hilt angle about -y in degrees).
SWING = ((0.0, 0.0), (0.15, 0.0), (0.35, 50.0), (0.6, -10.0), (0.8, 30.0), (1.0, 0.0))
STEEL = (0.06, 0.06, 0.065)    # dark steel: a dark solid under the flames


def blade(frames):
    """The visible blade on a hilt keyed to swing it (the flow graph's Fire Source)."""
    bpy.ops.object.empty_add(location=HILT)
    hilt = bpy.context.active_object
    hilt.name = "Hilt"
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=BLADE_AT)
    steel = bpy.context.active_object
    steel.name = "Blade"
    steel.scale = BLADE_SIZE
    mat = bpy.data.materials.new("Steel")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*STEEL, 1.0)
    bsdf.inputs["Metallic"].default_value = 0.6
    bsdf.inputs["Roughness"].default_value = 0.4
    steel.data.materials.append(mat)
    steel.parent = hilt
    steel.matrix_parent_inverse = hilt.matrix_world.inverted()
    for fraction, angle in SWING:
        hilt.rotation_euler = (0.0, -math.radians(angle), 0.0)
        hilt.keyframe_insert("rotation_euler", frame=max(1, round(fraction * frames)))
    return steel


def setup(scene, frames):
    fuel = flowgraph_kit.fuel_source("BladeFuel", bpy.ops.mesh.primitive_cube_add, FUEL_AT,
                                 FUEL_SIZE)
    # Sway across the edge only: velocity along it would bunch the flames into blobs.
    flowgraph_kit.flicker(fuel, speed=0.3, fuel_share=0.4, frames=BAKE_FRAMES, key_every=4,
                      along_x=False)
    domains = flowgraph_kit.fire_states(STATES, BOX, CENTRE, RESOLUTION, BAKE_FRAMES,
                                    NODES_PER_FRAME, LIFETIME, COOLING)
    g = domains[0].plume.domain.flowgraph
    g.fire_source = blade(frames)
    g.transition_hold = 'LIFETIME'
    # Framed on the blade and its flames at rest (0.94 m of height in view).
    scene_kit.camera(scene, (0.05, -1.85, 0.45), lens=40.0, target=(0.05, 0.0, 0.42))
    sun = scene_kit.dark_studio(scene, sun_energy=1.5)  # the world is set again, near black
    sun.rotation_euler = (math.radians(60.0), 0.0, math.radians(-20.0))  # from the camera's side
    return domains


def main():
    _, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    flowgraph_kit.flowgraph_example(TAG, USAGE, DEFAULT_FRAMES, lambda scene: setup(scene, frames),
                                TARGETS, SHOW, GRAPH)


if __name__ == "__main__":
    main()
