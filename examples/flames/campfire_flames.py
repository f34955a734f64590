"""A campfire of structural flames ([Structural Flames], the CAMPFIRE profile of Figure 3).

    blender -b --factory-startup --python examples/flames/campfire_flames.py -- OUT_DIR [FRAMES]

Four logs lie crossed in a ring of stones; each log is a Flame Source with 4 flames of source
radius r = 4 cm (CAMPFIRE profile) spread over its upper side. The flames break often (the
automatic breakaway frequency 0.50 (g/2r)^½ = 5.5 Hz of §4.3) and the pieces live up to
A = 0.5 s, rising as loose tongues of fire; merging (§4.5) is on, so neighbouring flames join
into one body. A light breeze from a Blender Wind force field leans the fire.

Writes OUT_DIR/campfire_flames.blend (flames cache in OUT_DIR/plume_cache/flames),
campfire_flames_####.png for a few frames and campfire_flames_strip.png (the manual's image);
prints the bake time per frame, the flames and particles per frame and the render time. Needs
the Plume add-on (README).
"""

import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flame_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "campfire_flames"
USAGE = f"usage: blender -b --factory-startup --python examples/flames/{TAG}.py -- OUT_DIR [FRAMES]"
DEFAULT_FRAMES = 32
SHOW = (0.4, 0.6, 0.8, 1.0)
LOG_RADIUS, LOG_LENGTH = 0.05, 0.55
#: (x, y, z, angle about Z in degrees) of each log: two crossed layers.
LOGS = ((0.0, -0.09, LOG_RADIUS, 0.0), (0.0, 0.09, LOG_RADIUS, 0.0),
        (-0.09, 0.0, 3 * LOG_RADIUS, 90.0), (0.09, 0.0, 3 * LOG_RADIUS, 90.0))


def logs():
    for n, (x, y, z, angle) in enumerate(LOGS):
        log = flame_kit.flame_source(f"Log{n}", bpy.ops.mesh.primitive_cylinder_add, (x, y, z),
                                     'CAMPFIRE', 4, 0.04, radius=LOG_RADIUS, depth=LOG_LENGTH,
                                     vertices=16,
                                     rotation=(0.0, math.radians(90.0), math.radians(angle)))
        flame_kit.solid(log, (0.05, 0.03, 0.02), emission=(0.25, 0.04, 0.0), name="Charred")
    for k in range(12):  # the ring of stones
        a = 2.0 * math.pi * k / 12
        bpy.ops.mesh.primitive_ico_sphere_add(radius=0.07, subdivisions=2,
                                              location=(0.42 * math.cos(a), 0.42 * math.sin(a),
                                                        0.02))
        flame_kit.solid(bpy.context.active_object, (0.2, 0.19, 0.18), roughness=0.9,
                        name="Stone")


def setup(scene, frames):
    logs()
    flame_kit.floor(8.0, color=(0.08, 0.065, 0.05), name="Ground")
    bpy.ops.object.effector_add(type='WIND', location=(-1.0, 0.0, 0.5),
                                rotation=(0.0, math.radians(90.0), 0.0))
    bpy.context.active_object.field.strength = 0.3  # m/s along +x
    flame_kit.flames_settings(
        scene, frames, points=14, height_persistent=0.2, height_intermittent=0.4,
        height_max=0.65, lifespan_scale=0.5, buoyancy=0.5, diffusion=5e-4, kolmogorov=0.01,
        voxel_size=0.008, particles_per_pixel=4.0,
        max_particles=20000, temperature_scale=1600.0)
    scene_kit.camera(scene, (0.0, -3.0, 1.0), lens=40.0, target=(0.05, 0.0, 0.55))


def main():
    flame_kit.flame_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, samples=64)


if __name__ == "__main__":
    main()
