"""A burning torch waved through the air: Figure 1 of [Structural Flames].

    blender -b --factory-startup --python examples/flames/torch_swing.py -- OUT_DIR [FRAMES]

A torch (a wooden handle under a 4 cm head) is keyed to swing left, right and back along a
low arc, about 1.5 m/s at the bottom of the swing. Its head is the Flame Source: 5 flames of
source radius r = 2 cm, TORCH profile (Figure 3). As §4.2 and §7 describe, the flames are
generated as if the torch stood still, the head's motion entering the base of each spine as an
initial velocity −V: every particle released at the head keeps moving against the swing, so the
flames trail behind the torch and swap sides when it turns back. Buoyancy and Kolmogorov noise
act on the control points as in Figure 1.

Writes OUT_DIR/torch_swing.blend (flames cache in OUT_DIR/plume_cache/flames),
torch_swing_####.png for a few frames and torch_swing_strip.png (the manual's image); prints the
bake time per frame, the flames and particles per frame and the render time. Needs the Plume
add-on (README).
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flame_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "torch_swing"
USAGE = f"usage: blender -b --factory-startup --python examples/flames/{TAG}.py -- OUT_DIR [FRAMES]"
DEFAULT_FRAMES = 40
SHOW = (0.3, 0.5, 0.65, 0.9)
HEAD_Z = 1.0            # m, height of the torch head at the ends of the swing
#: (frame as a fraction of the shot, x, z) keys of the head: a pendulum-like arc.
SWING = ((0.0, -0.45, HEAD_Z), (0.25, 0.0, HEAD_Z - 0.1), (0.5, 0.45, HEAD_Z),
         (0.75, 0.0, HEAD_Z - 0.1), (1.0, -0.45, HEAD_Z))


def torch(frames):
    head = flame_kit.flame_source("TorchHead", bpy.ops.mesh.primitive_uv_sphere_add,
                                  (SWING[0][1], 0.0, SWING[0][2]), 'TORCH', 5, 0.02,
                                  radius=0.04, segments=16, ring_count=8)
    flame_kit.solid(head, (0.03, 0.02, 0.015), emission=(0.6, 0.15, 0.02), name="Pitch")
    bpy.ops.mesh.primitive_cylinder_add(radius=0.015, depth=0.5, location=(0.0, 0.0, -0.27))
    handle = bpy.context.active_object
    handle.name = "Handle"
    flame_kit.solid(handle, (0.25, 0.14, 0.07), name="Wood")
    handle.parent = head
    for fraction, x, z in SWING:
        head.location = (x, 0.0, z)
        head.keyframe_insert("location", frame=1 + round(fraction * (frames - 1)))
    return head


def setup(scene, frames):
    torch(frames)
    flame_kit.floor(6.0, color=(0.2, 0.17, 0.14))
    # A rough stone wall behind the swing: what the torch lights (0.6 m behind it).
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.6, 1.5), rotation=(1.5708, 0.0, 0.0))
    flame_kit.solid(bpy.context.active_object, (0.3, 0.27, 0.24), roughness=0.95, name="Wall")
    flame_kit.flames_settings(
        scene, frames, points=14, height_persistent=0.08, height_intermittent=0.16,
        height_max=0.3, lifespan_scale=0.3, buoyancy=0.5, kolmogorov=0.006, voxel_size=0.004, temperature_scale=1700.0)
    scene_kit.camera(scene, (0.0, -1.7, 1.1), lens=35.0, target=(0.0, 0.0, 1.05))


def main():
    flame_kit.flame_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, samples=64)


if __name__ == "__main__":
    main()
