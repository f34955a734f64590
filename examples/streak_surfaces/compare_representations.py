"""Figure 9 of smoke_surfaces.txt: the same incense smoke shown five ways, side by side.

    blender -b --factory-startup --python examples/streak_surfaces/compare_representations.py -- OUT_DIR [FRAMES]

(a) the density field of a 50³ bake rendered as a volume, (b) the same scene at 150³ as a volume,
(c) the 20 streaklines' particles of the 50³ bake, (d) 100 point sources' particles at 150³,
(e) Plume's streak surfaces from the 50³ bake (20 point sources). The scene is
that of incense.py beside this file; every panel shows the last frame. The paper's point, which
the strip shows: neither a finer grid nor more particles gives the thin sheet-like look the surfaces give
from the coarse bake, at 1/27 of the fine grid's cells.

Writes OUT_DIR/compare_50.blend and compare_150.blend (caches beside them), one PNG per panel
and OUT_DIR/compare_strip.png, and prints each bake's time. Needs the Plume add-on installed.
"""

import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import incense  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/compare_representations.py -- OUT_DIR [FRAMES]")
DEFAULT_FRAMES = 84
WIDTH, HEIGHT, SAMPLES = 200, 320, 32
PARTICLE_RADIUS = 0.0025  # m
VOLUME_DENSITY = 25.0     # Principled Volume density scale of panels (a), (b)


def bake(out_dir, frames, resolution, point_sources):
    """The incense scene at `resolution` with `point_sources` point sources in its tip, baked."""
    scene = scene_kit.new_scene()
    if resolution == incense.RESOLUTION:  # the tip is one cell: `point_sources` in that cell
        incense.make_source(frames, point_sources=point_sources)
    else:  # the same tip spans several cells: exactly `point_sources` vertices inside it
        incense.make_source(frames, vertex_sources=point_sources)
    dom = incense.make_domain(frames, resolution, name=f"Incense{resolution}")
    scene_kit.camera(scene, (0.0, -1.7, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, WIDTH, HEIGHT, SAMPLES, os.path.join(out_dir, "compare_"))
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, f"compare_{resolution}")
    bpy.context.view_layer.objects.active = dom
    t0 = time.perf_counter()
    if bpy.ops.plume.bake() != {'FINISHED'}:
        sys.exit(f"compare_representations: the {resolution}^3 bake failed")
    print(f"compare_representations: {resolution}^3 bake of {frames} frames "
          f"{time.perf_counter() - t0:.1f} s", flush=True)
    return scene, dom


def particles_object(dom, frame):
    """The streaklines' particles inside the domain at `frame` as a point cloud (geometry nodes
    Mesh to Points), glowing white: the particle rendering of Figure 9 (c), (d)."""
    from plume import _native, cache
    folder = os.path.join(bpy.path.abspath(dom.plume.domain.cache_directory), dom.name)
    snap = _native.read_streak_file(cache.streak_path(folder, frame))
    inside = snap["positions"][snap["outside"] == 0]
    mesh = bpy.data.meshes.new(f"{dom.name}_particles")
    mesh.from_pydata([tuple(p) for p in inside], [], [])
    ob = bpy.data.objects.new(mesh.name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    ng = bpy.data.node_groups.new("ParticlePoints", 'GeometryNodeTree')
    new_socket = scene_kit.compat().group_socket_new
    new_socket(ng, 'INPUT', 'NodeSocketGeometry', "Geometry")
    new_socket(ng, 'OUTPUT', 'NodeSocketGeometry', "Geometry")
    n_in, n_out = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    to_points = ng.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = PARTICLE_RADIUS
    set_mat = ng.nodes.new("GeometryNodeSetMaterial")
    mat = bpy.data.materials.new("ParticleGlow")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Strength"].default_value = 1.5
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    set_mat.inputs["Material"].default_value = mat
    ng.links.new(n_in.outputs[0], to_points.inputs["Mesh"])
    ng.links.new(to_points.outputs[0], set_mat.inputs["Geometry"])
    ng.links.new(set_mat.outputs[0], n_out.inputs[0])
    ob.modifiers.new("Points", 'NODES').node_group = ng
    return ob


def render_only(scene, visible, path):
    """Renders the current frame with only `visible` (and the camera and light) shown."""
    for ob in scene.objects:
        if ob.type not in {'CAMERA', 'LIGHT'}:
            ob.hide_render = ob not in visible
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return path


def panels(out_dir, frames, resolution, point_sources, with_surfaces):
    scene, dom = bake(out_dir, frames, resolution, point_sources)
    scene.frame_set(frames)
    volume = bpy.data.objects[dom.plume.domain.volume_object]
    # The thin plume is 1-3 cells wide: a denser medium than the add-on's default makes it show.
    for slot in volume.material_slots:
        for node in slot.material.node_tree.nodes:
            if node.type == 'PRINCIPLED_VOLUME':
                node.inputs["Density"].default_value = VOLUME_DENSITY
    paths = [render_only(scene, {volume}, os.path.join(out_dir, f"volume_{resolution}.png")),
             render_only(scene, {particles_object(dom, frames)},
                         os.path.join(out_dir, f"particles_{resolution}.png"))]
    if with_surfaces:
        scene_kit.bake_surfaces(dom, "compare_representations")  # the bake is already done
        scene.frame_set(frames)
        sheets = {o for o in scene.objects if o.type == 'SURFACE'}
        paths.append(render_only(scene, sheets, os.path.join(out_dir, "surfaces_50.png")))
    bpy.ops.wm.save_mainfile()
    return paths


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    vol50, part50, surf50 = panels(out_dir, frames, 50, 20, with_surfaces=True)
    vol150, part150 = panels(out_dir, frames, 150, 100, with_surfaces=False)
    strip = scene_kit.strip([vol50, vol150, part50, part150, surf50],
                            os.path.join(out_dir, "compare_strip.png"))
    print(f"compare_representations: (a) volume 50^3, (b) volume 150^3, (c) particles 50^3 "
          f"(20 sources), (d) particles 150^3 (100 sources), (e) surfaces 50^3 -> {strip}",
          flush=True)


if __name__ == "__main__":
    main()
