"""Incense smoke as streak surfaces: the setup of Figure 1 of [Smoke Surfaces].

    blender -b --factory-startup --python examples/streak_surfaces/incense.py -- OUT_DIR [FRAMES]

A 50³ domain (1 m cube on the floor, 2 cm cells), a glowing incense tip as the source: one source
cell holding 20 random point sources (the paper's "twenty point sources"), one particle per
source per step. The warm smoke rises, a faint draught bends it, a slow
swirl of the stick (the source circles 8 mm) and vorticity confinement fold the streaklines into
sheets, and the smoke thins out as it rises (dissipation). After the bake, the threshold h0 giving the most surfaces is read off the live
(h0 -> surfaces) curve of the panel (the paper's Figure 4; the default, the mean of h, joins all
streaklines of this compact source into one sheet), and Build Surfaces clusters the streaklines
into a few NURBS sheets (the paper: five surfaces from 11 streaklines) and renders
them in Cycles (the add-on's Fast Sheet Render) with the density opacity map p = d e^(-|n·v|)
(§3.4).

Writes OUT_DIR/incense.blend, the cache in OUT_DIR/plume_cache, incense_####.png for a few frames
and incense_strip.png (those frames side by side, the manual's image). Prints the bake, build and
render times and the surfaces found. Needs the Plume add-on installed (README).
"""

import math
import os
import random
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/incense.py -- OUT_DIR [FRAMES]")
RESOLUTION = 50            # the paper's 50³ grid
POINT_SOURCES = 20         # in the one source cell (§3.2: 10-20 per source cell)
DEFAULT_FRAMES = 120
SHOW = (0.4, 0.7, 1.0)     # rendered frames, as fractions of the shot


def make_domain(frames, resolution=RESOLUTION, name="Incense"):
    dom = scene_kit.domain_cube(name, 1.0, (0.0, 0.0, 0.5), resolution, frames)
    d = dom.plume.domain
    d.alpha, d.beta = 0.0, 0.3        # heat lifts the smoke, density is passive
    d.vorticity = 0.25                # ε: keeps the small curls a 50³ grid would smooth away
    d.density_dissipation = 0.5       # the smoke thins out as it mixes with the room's air
    d.wind, d.wind_strength = (0.12, 0.0, 0.0), 0.5  # a faint draught bends the column
    d.turbulence = 0.0                # the paper's air: the draught and the stick's swirl alone
    d.boundary_neg_z = 'CLOSED'
    d.streaks = True
    d.emission_period = 1             # §3.2: one particle per point source per step
    d.density_k_u, d.density_k_v = 4, 2
    d.sheet_color = (0.9, 0.92, 1.0, 1.0)
    d.sheet_brightness = 1.4
    d.sheet_opacity = 1.0             # one sheet face-on: p = d e^-1, edge-on d
    return dom


def make_source(frames, point_sources=POINT_SOURCES, vertex_sources=0):
    """The glowing tip: the 2 cm cell centred at (1, 1, 5) cm of the 50³ grid (several cells of a
    finer grid: the same physical source at any resolution), with `point_sources` random point
    sources per source cell, or, when `vertex_sources` > 0, that many seeded random points inside
    the tip as a Point Source Mesh (one streakline per vertex)."""
    size, cx, cz = 0.9 / RESOLUTION, 0.01, 0.05
    bpy.ops.mesh.primitive_cube_add(size=size, location=(cx, cx, cz))
    src = bpy.context.active_object
    src.name = "IncenseTip"
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.density, s.temperature = 1.0, 1.0
    s.smoke_noise = 0.0  # an even tip, as the paper's
    s.velocity = (0.0, 0.0, 0.15)
    s.point_placement = 'CELLS'  # §3.2: random point sources in the one source cell
    s.point_sources = point_sources
    if vertex_sources > 0:
        rng = random.Random(7)
        mesh = bpy.data.meshes.new("TipPoints")
        mesh.from_pydata([tuple(rng.uniform(-0.5, 0.5) * size for _ in range(3))
                          for _ in range(vertex_sources)], [], [])
        points = bpy.data.objects.new("TipPoints", mesh)
        bpy.context.scene.collection.objects.link(points)
        points.parent = src  # rides along with the tip
        points.hide_render = True
        s.point_source_mesh = points
    s.motion_factor = 1.0
    src.hide_render = True
    # A slow circle of 8 mm starting at the cell centre: a hand that is not quite still.
    for n in range(0, frames + 2, 12):
        a = 2.0 * math.pi * n / 48.0
        src.location = (cx + 0.008 * (math.cos(a) - 1.0), cx + 0.008 * math.sin(a), cz)
        src.keyframe_insert("location", frame=n + 1)
    return src


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    make_source(frames)
    dom = make_domain(frames)
    scene_kit.camera(scene, (0.0, -1.7, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, 240, 320, 64, os.path.join(out_dir, "incense_"))
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, "incense")

    bake_s, build_s, h0, surfaces = scene_kit.bake_surfaces(dom, "incense")
    # The sheets shade themselves (§3.4): 16 samples and no light bounces give the same picture
    # as 64 samples with bounces, several times faster (sheet_render_time.py beside this file).
    assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}
    shown = sorted({max(1, min(frames, round(f * frames))) for f in SHOW})
    render_s, strip = scene_kit.render_strip(scene, shown, out_dir, "incense")
    nets = ", ".join(f"{o.data.splines[0].point_count_u}x{o.data.splines[0].point_count_v}"
                     for o in surfaces)
    print(f"incense: {frames} frames at {RESOLUTION}^3, bake {bake_s:.1f} s "
          f"({bake_s / frames:.2f} s/frame), Build Surfaces {build_s:.1f} s -> "
          f"{len(surfaces)} surfaces at h0 = {h0:.3g} (control nets u x v: {nets}), render {render_s:.1f} s/frame "
          f"-> {strip}", flush=True)
    if len(surfaces) < 2:
        sys.exit("incense: fewer than 2 surfaces were built")


if __name__ == "__main__":
    main()
