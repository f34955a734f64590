"""One candle flame in a dark room ([Structural Flames] §4.3-4.4, the CANDLE profile of
Figure 3).

    blender -b --factory-startup --python examples/flames/candle.py -- OUT_DIR [FRAMES]

A wax cylinder (2.4 cm across) stands on a table in front of a wall; its wick is the Flame
Source: one flame of source radius r = 5 mm, CANDLE profile. A real candle flame is steady: it
flickers (its intermittent tip comes and goes) but hardly ever sheds a piece. So H_p, H_i and
H_max are close together, the breakaway frequency is set well below the automatic
0.50 (g/2r)^½ = 16 Hz of a 5 mm pool (that formula is for free pool fires; a wick is fed
steadily), and a separated tip lives at most A = 1/12 s. The flame's light (§5.2, one point light
of radius h/3) is the only light of the room.

Writes OUT_DIR/candle.blend (flames cache in OUT_DIR/plume_cache/flames), candle_####.png for a
few frames and candle_strip.png (the manual's image); prints the bake time per frame, the flames
and particles per frame and the render time. Needs the Plume add-on (README).
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flame_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "candle"
USAGE = f"usage: blender -b --factory-startup --python examples/flames/{TAG}.py -- OUT_DIR [FRAMES]"
DEFAULT_FRAMES = 48
SHOW = (0.25, 0.5, 0.75, 1.0)
WAX_RADIUS, WAX_HEIGHT = 0.012, 0.08   # m
WICK_TOP = WAX_HEIGHT + 0.006


def setup(scene, frames):
    flame_kit.floor(1.0, color=(0.09, 0.06, 0.04), name="Table")
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.2, 0.3),
                                     rotation=(1.5708, 0.0, 0.0))
    flame_kit.solid(bpy.context.active_object, (0.25, 0.22, 0.2), roughness=0.9, name="Wall")
    bpy.ops.mesh.primitive_cylinder_add(radius=WAX_RADIUS, depth=WAX_HEIGHT,
                                        location=(0.0, 0.0, WAX_HEIGHT / 2))
    flame_kit.wax(bpy.context.active_object)
    wick = flame_kit.flame_source("Wick", bpy.ops.mesh.primitive_cylinder_add,
                                  (0.0, 0.0, WICK_TOP - 0.004), 'CANDLE', 1, 0.005,
                                  radius=0.0008, depth=0.008, vertices=8)
    flame_kit.solid(wick, (0.01, 0.008, 0.006), roughness=0.9)
    # A candle flame is about 3 cm tall and steady: H_p, H_i, H_max close together, little
    # diffusion and noise, pieces rare and short-lived.
    flame_kit.flames_settings(
        scene, frames, points=12, height_persistent=0.024, height_intermittent=0.03,
        height_max=0.042, breakaway_frequency=0.7, lifespan_scale=1.0 / 24.0,
        buoyancy=0.4, diffusion=2e-6, flow_noise=0.04, kolmogorov=0.0001, spine_noise=0.003,
        voxel_size=0.0005, particles_per_pixel=10.0)
    scene_kit.camera(scene, (0.0, -0.34, 0.1), lens=50.0, target=(0.0, 0.0, 0.095))


def main():
    # The manual's headline strip: 1280 x 720.
    flame_kit.flame_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, samples=64, width=1280,
                            height=720)


if __name__ == "__main__":
    main()
