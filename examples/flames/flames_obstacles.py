"""Flames around a simple obstacle: Figure 7 of [Structural Flames] (§6.1).

    blender -b --factory-startup --python examples/flames/flames_obstacles.py -- OUT_DIR [FRAMES]

A ball hangs over a burner. The ball is an Obstacle: the Plume solver computes the flow of hot
gas around it on a 40³ grid (the paper's resolution), rising from a hot Source disc that covers
the burner, and that baked domain is the flames' Wind Domain (w of eq. 1). The burner is a
Flame Source of 6 flames (TORCH profile, r = 3 cm); their spines rise into the ball, are carried
around it by the solver's flow and, where a control point still ends inside the ball, it is
pushed out (§6.1), so the flames lick around the ball instead of through it.

The domain's baked velocity is stored only where it holds smoke (Plume writes the velocity grid
where density is non-zero), so the hot Source also gives a little smoke density: the updraft
that carries the flames is then smoke-filled, and the flames read its velocity; the smoke's own
Volume is hidden from renders.

Writes OUT_DIR/flames_obstacles.blend (caches in OUT_DIR/plume_cache), flames_obstacles_####.png
for a few frames and flames_obstacles_strip.png (the manual's image); prints the solver bake,
the flames bake time per frame, the flames and particles per frame and the render time. Needs
the Plume add-on (README).
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import flame_kit  # noqa: E402
import scene_kit  # noqa: E402

TAG = "flames_obstacles"
USAGE = f"usage: blender -b --factory-startup --python examples/flames/{TAG}.py -- OUT_DIR [FRAMES]"
DEFAULT_FRAMES = 36
SHOW = (0.4, 0.6, 0.8, 1.0)
RESOLUTION = 40          # the paper's 40 x 40 x 40 wind field
BALL = (0.0, 0.0, 0.5)   # centre of the obstacle (m)
BALL_RADIUS = 0.14


def wind_domain(frames):
    """The 40³ domain over the burner, the ball as an Obstacle and a hot Source disc; baked
    here. Returns the domain."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=BALL_RADIUS, location=BALL, segments=48,
                                         ring_count=24)
    ball = bpy.context.active_object
    ball.name = "Ball"
    # Smooth shading: the flat faces of a glossy ball each mirror one patch of flame, a
    # chequer of squares on the metal.
    bpy.ops.object.shade_smooth()
    bpy.ops.plume.role_set(role='OBSTACLE')
    flame_kit.solid(ball, (0.2, 0.2, 0.21), roughness=0.3, name="Metal")
    bpy.ops.mesh.primitive_cylinder_add(radius=0.16, depth=0.08, location=(0.0, 0.0, 0.08))
    hot = bpy.context.active_object
    hot.name = "HotAir"
    bpy.ops.plume.role_set(role='SOURCE')
    s = hot.plume.source
    s.density, s.temperature, s.velocity = 0.05, 1.0, (0.0, 0.0, 0.5)
    hot.hide_render = True
    dom = scene_kit.domain_cube("WindDomain", 1.0, (0.0, 0.0, 0.5), RESOLUTION, frames)
    dom.hide_render = True
    return dom


def setup(scene, frames):
    dom = wind_domain(frames)
    burner = flame_kit.flame_source("Burner", bpy.ops.mesh.primitive_cylinder_add,
                                    (0.0, 0.0, 0.02), 'TORCH', 6, 0.03, radius=0.15,
                                    depth=0.04, vertices=24)
    flame_kit.solid(burner, (0.05, 0.05, 0.05), roughness=0.5, name="Iron")
    flame_kit.floor(6.0)
    flame_kit.flames_settings(
        scene, frames, points=14, height_persistent=0.25, height_intermittent=0.4,
        height_max=0.6, lifespan_scale=0.4, buoyancy=0.3, kolmogorov=0.006, voxel_size=0.005, temperature_scale=1700.0, wind_domain=dom, use_obstacles=True)
    scene_kit.camera(scene, (0.0, -2.2, 0.55), lens=40.0, target=(0.0, 0.0, 0.4))
    scene_kit.save_blend(os.path.dirname(scene.render.filepath), TAG)  # '//' caches
    scene_kit.select([dom], dom)
    s = scene_kit.run_op(bpy.ops.plume.bake, TAG, "the wind bake")
    print(f"{TAG}: wind domain {RESOLUTION}^3 baked {frames} frames in {s:.1f} s "
          f"({s / frames:.2f} s/frame)", flush=True)
    vol = bpy.data.objects.get(dom.plume.domain.volume_object)
    if vol is not None:
        vol.hide_render = True


def main():
    flame_kit.flame_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, samples=64)


if __name__ == "__main__":
    main()
