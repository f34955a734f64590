"""Figure 9 of [Smoke Surfaces]: the same incense smoke shown five ways, side by side.

    blender -b --factory-startup --python examples/streak_surfaces/compare_representations.py -- OUT_DIR [FRAMES]

(a) the density field of a 50³ bake rendered as a volume, (b) the same scene at 150³ as a volume,
(c) the 20 streaklines' particles of the 50³ bake, (d) 100 point sources' particles at 150³,
(e) Plume's streak surfaces from the 50³ bake (20 point sources). The scene is that of
incense.py beside this file; every panel shows the last frame through the same camera. The
paper's point, which the strip shows: neither a finer grid nor more particles gives the thin
sheet-like look the surfaces give from the coarse bake, at 1/27 of the fine grid's cells.

The alternatives are rendered fairly (figure9_looks.py): each sends as much light from its smoke
as the sheets do (the brightness above the background summed over the image; volumes by their
Principled Volume density scale, particles by their opacity), the particles are soft
semi-transparent specks about 1.6 pixels wide, and each alternative gets at least the render
time the sheets take (its samples set from a short measuring render). Every panel renders with
the add-on's Fast Sheet Render set-up (no light bounces: the volumes single-scatter the sun,
as thin smoke does) under Blender's default colour management.

Writes OUT_DIR/compare_50.blend and compare_150.blend (caches beside them), one PNG per panel
and OUT_DIR/compare_strip.png, and prints each bake's time and, per panel, its render time,
samples and light. Needs the Plume add-on installed.
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import figure9_looks as looks  # noqa: E402
import incense  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/compare_representations.py -- OUT_DIR [FRAMES]")
DEFAULT_FRAMES = 84
WIDTH, HEIGHT = 200, 320  # one pixel is about 3.8 mm at the smoke (1.7 m, 50 mm lens)
#: Principled Volume density scale per grid where match_light starts; it ends where the volume's
#: light (figure9_looks.measure) equals the sheets' on frame 84 (2026-11-29: 20.6 at 50³ and
#: 36.4 at 150³, for the cubic sheets' 7.3).
VOLUME_DENSITY = {50: 40.0, 150: 70.0}
#: Particle specks: 3 mm radius (1.6 px across), opacity per grid where match_light starts (the
#: 150³ bake's 13,700 particles, against 1,700 at 50³, overlap more: each is fainter for the
#: same light; it ended at 0.105 and 0.007), full at a carried density of 0.02 and fainter below
#: it (the thinned smoke high up).
PARTICLE_RADIUS = 0.003
PARTICLE_OPACITY = {50: 0.2, 150: 0.015}
PARTICLE_FULL_DENSITY = 0.02
#: Samples of the renders that match each panel's light to the sheets' (the sheets' own count;
#: the final renders take about as many, matched to the sheets' time).
MATCH_SAMPLES = 16


def bake(out_dir, frames, resolution, point_sources):
    """The incense scene at `resolution` with `point_sources` point sources in its tip, baked.
    Returns (scene, domain, bake seconds)."""
    scene = scene_kit.new_scene()
    if resolution == incense.RESOLUTION:  # the tip is one cell: `point_sources` in that cell
        incense.make_source(frames, point_sources=point_sources)
    else:  # the same tip spans several cells: exactly `point_sources` vertices inside it
        incense.make_source(frames, vertex_sources=point_sources)
    dom = incense.make_domain(frames, resolution, name=f"Incense{resolution}")
    scene_kit.camera(scene, (0.0, -1.7, 0.5), (90.0, 0.0, 0.0), lens=50.0)
    scene_kit.dark_studio(scene, world_color=(0.004, 0.004, 0.006))
    scene_kit.cycles(scene, WIDTH, HEIGHT, 16, os.path.join(out_dir, "compare_"))
    bpy.ops.plume.surfaces_fast_render()  # every panel: no light bounces (sheet_render.py)
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, f"compare_{resolution}")
    bpy.context.view_layer.objects.active = dom
    bake_s = scene_kit.run_op(bpy.ops.plume.bake, "compare_representations",
                              f"the {resolution}^3 bake")
    print(f"compare_representations: {resolution}^3 bake of {frames} frames {bake_s:.1f} s",
          flush=True)
    return scene, dom, bake_s


def report(label, path, seconds, samples):
    m = looks.measure(path)
    print(f"compare_representations: {label}: {seconds:.2f} s, {samples} samples; light "
          f"{m['light']:.1f} (smoke pixels {100 * m['share']:.1f} %, mean {m['mean']:.3f}), "
          f"speckle {m['speckle']:.2f}, edge {m['edge']:.2f}", flush=True)
    return path


def panels(out_dir, frames, resolution, point_sources, sheets_s=None, sheets_light=None):
    """This grid's volume and particle panels, each rendered for at least `sheets_s` seconds
    with the light of the sheets (`sheets_light`; match_light() from VOLUME_DENSITY and
    PARTICLE_OPACITY), and with `sheets_s` None first its sheets panel, whose time and light set
    them. Returns (paths, the sheets' seconds, the sheets' light)."""
    scene, dom, _ = bake(out_dir, frames, resolution, point_sources)
    paths = {}
    if sheets_s is None:
        # Its bake finds the cache complete and computes nothing; then Build Surfaces.
        _, build_s, _, built = scene_kit.bake_surfaces(dom, "compare_representations")
        print(f"compare_representations: Build Surfaces {build_s:.1f} s, {len(built)} surfaces",
              flush=True)
        scene.frame_set(frames)
        looks.show_only(scene, {o for o in scene.objects if o.type == 'SURFACE'})
        path = os.path.join(out_dir, "surfaces_50.png")
        samples = scene.cycles.samples
        sheets_s, _ = looks.render(scene, path, samples)
        sheets_light = looks.measure(path)["light"]
        paths["surfaces"] = report("(e) surfaces 50^3", path, sheets_s, samples)
    scene.frame_set(frames)
    volume = bpy.data.objects[dom.plume.domain.volume_object]
    looks.show_only(scene, {volume})
    path = os.path.join(out_dir, f"volume_{resolution}.png")
    density = looks.match_light(scene, path, lambda v: looks.set_volume_look(volume, v),
                                VOLUME_DENSITY[resolution], sheets_light, MATCH_SAMPLES)
    print(f"compare_representations: volume {resolution}^3 density scale {density:.1f}",
          flush=True)
    paths["volume"] = report(f"volume {resolution}^3", path,
                             *looks.render_matched(scene, path, sheets_s))
    specks = looks.particles_object(dom, frames, PARTICLE_RADIUS, PARTICLE_OPACITY[resolution],
                                    PARTICLE_FULL_DENSITY, dom.plume.domain.sheet_brightness)
    looks.show_only(scene, {specks})
    path = os.path.join(out_dir, f"particles_{resolution}.png")
    opacity = looks.match_light(scene, path, lambda v: looks.set_speck_opacity(specks, v),
                                PARTICLE_OPACITY[resolution], sheets_light, MATCH_SAMPLES)
    print(f"compare_representations: particles {resolution}^3 opacity {opacity:.3f}", flush=True)
    paths["particles"] = report(f"particles {resolution}^3 ({point_sources} sources)", path,
                                *looks.render_matched(scene, path, sheets_s))
    bpy.ops.wm.save_mainfile()
    return paths, sheets_s, sheets_light


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    coarse, sheets_s, sheets_light = panels(out_dir, frames, 50, 20)
    fine, _, _ = panels(out_dir, frames, 150, 100, sheets_s, sheets_light)
    strip = scene_kit.strip([coarse["volume"], fine["volume"], coarse["particles"],
                             fine["particles"], coarse["surfaces"]],
                            os.path.join(out_dir, "compare_strip.png"))
    print(f"compare_representations: (a) volume 50^3, (b) volume 150^3, (c) particles 50^3 "
          f"(20 sources), (d) particles 150^3 (100 sources), (e) surfaces 50^3 -> {strip}",
          flush=True)


if __name__ == "__main__":
    main()
