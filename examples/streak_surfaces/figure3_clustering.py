"""The three clusterings of Figure 3 of [Smoke Surfaces], on the incense set-up of Figure 1.

    blender -b --factory-startup --python examples/streak_surfaces/figure3_clustering.py -- OUT_DIR [FRAMES]

One incense tip (incense.py beside this file) whose 16 point sources are the vertices of a Point
Source Mesh, baked and built three ways, the same frame rendered each time:
  (a) no clustering: every streakline in one surface (threshold h0 above every h);
  (b) manual: the vertices split by hand into four vertex groups (the quadrants around the tip,
      a "naive manual clustering"), one surface per group (§3.3: hand-made candidate groups);
  (c) automatic: no groups, the threshold h0 giving the most surfaces (the peak of Figure 4's
      curve, the Most Surfaces button), clusters found by h(α,β) and ordered greedily.
The paper: (a) "too opaque and thick", (b) better but "unpredictable depending on the user
skill", (c) a consistent semi-transparent look.

Each surface is drawn in its own colour (SURFACE_COLORS, in build order), so the panels show how
the streaklines were grouped: one colour in (a), four quadrants in (b), the clusters in (c).

Writes OUT_DIR/figure3.blend, figure3_{a,b,c}.png and figure3_strip.png (the manual's image), and
prints the surfaces and times of each. Needs the Plume add-on installed (README).
"""

import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import incense  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/figure3_clustering.py -- OUT_DIR [FRAMES]")
DEFAULT_FRAMES = 120
VERTEX_SOURCES = 16
HAND_GROUPS = 4   # Figure 3(b): "manually selected four surfaces"
NO_CLUSTERING = 1e9  # h0 above every h: one surface per candidate group
#: Sheet colours of the surfaces in build order (linear RGB): well apart in hue, equally light.
SURFACE_COLORS = ((0.85, 0.85, 0.9), (0.9, 0.35, 0.25), (0.3, 0.75, 0.35), (0.3, 0.45, 0.95),
                  (0.9, 0.75, 0.2), (0.75, 0.3, 0.85), (0.25, 0.8, 0.85), (0.95, 0.55, 0.7))


def tint_by_surface(surfaces):
    """Gives each surface's sheet material the next colour of SURFACE_COLORS (the Emission
    node's colour: the sheet colour Build Surfaces set from the domain's Sheet Color)."""
    for i, ob in enumerate(sorted(surfaces, key=lambda o: o.name)):
        mat = ob.active_material
        emission = next(n for n in mat.node_tree.nodes if n.type == 'EMISSION')
        emission.inputs["Color"].default_value = (*SURFACE_COLORS[i % len(SURFACE_COLORS)], 1.0)


def quadrant_groups(points_obj, groups):
    """Vertex groups Q0..Q{groups-1} of the point mesh by angle around its centre."""
    mesh = points_obj.data
    for n in range(groups):
        points_obj.vertex_groups.new(name=f"Q{n}")
    for v in mesh.vertices:
        angle = math.atan2(v.co.y, v.co.x) % (2 * math.pi)
        points_obj.vertex_groups[int(angle / (2 * math.pi) * groups) % groups].add(
            [v.index], 1.0, 'REPLACE')


def build(dom, tag, h0):
    """Bake (resumes when nothing changed), Build Surfaces at h0 (None: Most Surfaces)."""
    bpy.context.view_layer.objects.active = dom
    bake_s = scene_kit.run_op(bpy.ops.plume.bake, tag, "the bake")
    if h0 is None:
        if bpy.ops.plume.surfaces_pick_threshold() != {'FINISHED'}:
            sys.exit(f"{tag}: no threshold joins two streaklines")
    else:
        dom.plume.domain.streak_threshold = h0
    build_s = scene_kit.run_op(bpy.ops.plume.surfaces_build, tag, "Build Surfaces")
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if smoke is not None:
        smoke.hide_render = True
    surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
    lines = sum(o.data.splines[0].point_count_v for o in surfaces)
    print(f"figure3 {tag}: bake {bake_s:.1f} s, Build Surfaces {build_s:.1f} s -> "
          f"{len(surfaces)} surfaces from {lines} streaklines at h0 = "
          f"{dom.plume.domain.streak_threshold:.3g}", flush=True)
    return surfaces


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    src = incense.make_source(frames, vertex_sources=VERTEX_SOURCES)
    points = src.plume.source.point_source_mesh
    dom = incense.make_domain(frames)
    scene_kit.camera(scene, (0.0, -1.7, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, 240, 320, 64, os.path.join(out_dir, "figure3_"))
    assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}  # sheets shade themselves
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, "figure3")
    shown = max(1, round(0.7 * frames))
    paths = {}
    # (a) and (c) share one bake; (b)'s vertex groups make another.
    for tag, hand, h0 in (("a", False, NO_CLUSTERING), ("c", False, None),
                          ("b", True, NO_CLUSTERING)):
        points.vertex_groups.clear()
        if hand:
            quadrant_groups(points, HAND_GROUPS)
        surfaces = build(dom, tag, h0)
        if tag == "a" and len(surfaces) != 1 or tag == "b" and len(surfaces) != HAND_GROUPS:
            sys.exit(f"figure3 {tag}: {len(surfaces)} surfaces built")
        tint_by_surface(surfaces)
        paths[tag] = scene_kit.render_frames(
            scene, [shown], os.path.join(out_dir, f"figure3_{tag}_%04d.png"))[0]
    bpy.ops.wm.save_mainfile()
    strip = scene_kit.strip([paths[t] for t in "abc"], os.path.join(out_dir, "figure3_strip.png"))
    print(f"figure3: frame {shown} of {frames} -> {strip}", flush=True)


if __name__ == "__main__":
    main()
