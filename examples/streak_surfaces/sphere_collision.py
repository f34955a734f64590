"""Rising smoke hits a sphere: Figure 10 of [Smoke Surfaces] as streak surfaces.

    blender -b --factory-startup --python examples/streak_surfaces/sphere_collision.py -- OUT_DIR [FRAMES]

The paper's setup: four source cells holding thirty random point sources (here a point-source
mesh of 30 seeded random vertices inside the four cells), a static no-slip sphere above them,
260 frames; the source has density 1 on frames 1-100 and 161-260, and density 0 with particle
emission off on frames 101-160 (keyframes on the source's density and Emit Particles), and the
density map is supersampled at k_u = 4, k_v = 2. The gap in the smoke rises as a gap in the
sheets: the particles on either side of it are far apart, and the supersampled density map
keeps the sheet transparent between them (the paper's middle image).

Writes OUT_DIR/sphere_collision.blend (cache beside it), sphere_####.png for three frames (the
collision, the gap, after the gap) and sphere_strip.png; prints the bake/build/render times and
the surfaces found. Needs the Plume add-on installed (README).
"""

import os
import random
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/sphere_collision.py -- OUT_DIR [FRAMES]")
RESOLUTION = 50
CELL = 1.0 / RESOLUTION
DEFAULT_FRAMES = 260
GAP = (101, 160)           # frames with no smoke and no particles (the paper's interval)
POINT_SOURCES = 30
SHOW = (96, 150, 250)      # frames of the strip, clamped to the shot


def make_domain(frames):
    dom = scene_kit.domain_cube("SphereCollision", 1.0, (0.0, 0.0, 0.5), RESOLUTION, frames)
    d = dom.plume.domain
    d.alpha, d.beta = 0.0, 0.4
    d.vorticity = 0.2
    d.turbulence = 0.0  # still air: the sphere alone breaks the plume
    d.density_dissipation = 0.2
    d.boundary_neg_z = 'CLOSED'
    d.streaks = True
    d.density_k_u, d.density_k_v = 4, 2   # the paper's sampling rates for this figure
    d.sheet_color = (0.9, 0.92, 1.0, 1.0)
    d.sheet_brightness = 1.4
    d.sheet_opacity = 0.5
    return dom


def make_source():
    """Four source cells (2 x 2 x 1 around (0, 0, 5 cm)) and 30 point sources inside them."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.05))
    src = bpy.context.active_object
    src.name = "Source"
    src.scale = (1.9 * CELL, 1.9 * CELL, 0.9 * CELL)
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.density, s.temperature = 1.0, 1.0
    s.smoke_noise = 0.0
    s.velocity = (0.0, 0.0, 0.3)
    src.hide_render = True
    rng = random.Random(10)
    verts = [(rng.uniform(-CELL, CELL), rng.uniform(-CELL, CELL), 0.05 + rng.uniform(-0.5, 0.5) * CELL)
             for _ in range(POINT_SOURCES)]
    mesh = bpy.data.meshes.new("PointSources")
    mesh.from_pydata(verts, [], [])
    points = bpy.data.objects.new("PointSources", mesh)
    bpy.context.scene.collection.objects.link(points)
    points.hide_render = True
    s.point_source_mesh = points
    # Frames 101-160: no smoke, no particles; constant keyframes so the switch is sharp.
    for frame, on in ((1, True), (GAP[0], False), (GAP[1] + 1, True)):
        s.density = 1.0 if on else 0.0
        s.emit_particles = on
        src.keyframe_insert('plume.source.density', frame=frame)
        src.keyframe_insert('plume.source.emit_particles', frame=frame)
    for fc in scene_kit.compat().fcurves(src):
        for k in fc.keyframe_points:
            k.interpolation = 'CONSTANT'
    return src


def make_sphere():
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.12, location=(0.0, 0.0, 0.45), segments=48,
                                         ring_count=24)
    sphere = bpy.context.active_object
    sphere.name = "Sphere"
    bpy.ops.object.shade_smooth()
    bpy.ops.plume.role_set(role='OBSTACLE')
    sphere.plume.obstacle.slip = 'NO_SLIP'
    mat = bpy.data.materials.new("SphereGrey")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.08, 0.08, 0.09, 1)
    sphere.data.materials.append(mat)
    return sphere


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    make_source()
    make_sphere()
    dom = make_domain(frames)
    scene_kit.camera(scene, (0.0, -2.0, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, 240, 320, 64, os.path.join(out_dir, "sphere_"))
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, "sphere_collision")

    bake_s, build_s, h0, surfaces = scene_kit.bake_surfaces(dom, "sphere_collision")
    # Sheets shade themselves (§3.4); the lit sphere seen through them needs more than the
    # sheets' 16 samples against light-sampling noise.
    assert bpy.ops.plume.surfaces_fast_render(samples=48) == {'FINISHED'}
    shown = sorted({min(f, frames) for f in SHOW})
    render_s, strip = scene_kit.render_strip(scene, shown, out_dir, "sphere")
    print(f"sphere_collision: {frames} frames at {RESOLUTION}^3, bake {bake_s:.1f} s, Build "
          f"Surfaces {build_s:.1f} s -> {len(surfaces)} surfaces at h0 = {h0:.3g}, render "
          f"{render_s:.1f} s/frame -> {strip}", flush=True)
    if not surfaces:
        sys.exit("sphere_collision: no surface was built")


if __name__ == "__main__":
    main()
