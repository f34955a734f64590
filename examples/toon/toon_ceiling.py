"""Toon smoke rushing up into a ceiling: Figure 7 of [Cartoon Smoke].

    blender -b --factory-startup --python examples/toon/toon_ceiling.py -- OUT_DIR [FRAMES]

The paper's grid, 40 x 40 x 80 cells (its 40x80x40 with y up) over a 1 x 1 x 2 m room (closed
walls and ceiling); a source at the floor emits hot smoke upwards at 2.5 m/s. The smoke hits the
ceiling, is pushed out sideways and tumbles over itself. Build Toon Smoke (puffy stencil,
depth-difference outlines) renders it twice, as Figure 7 does: coloured by speed (top row, slow
blue to fast orange) and in plain white (bottom row). Particles are introduced at the source
(§2.1, 8 per frame) and born where the smoke is denser than ρ_birth = 0.3, each at least 0.8
stencil sizes from any other (§2.3 with the birth spacing): 15-30 cm puffs a few cells apart
give the big puffy shapes, where a particle born in every dense cell (the paper's rule, spacing
0) would merge into one smooth blob on this grid. The ceiling is drawn as a dark beam.

Writes OUT_DIR/toon_ceiling.blend (cache in OUT_DIR/plume_cache), toon_ceiling_speed_####.png
and toon_ceiling_white_####.png for a few frames and toon_ceiling_strip.png (the two rows, the
manual's image); prints the bake, build and render times. Needs the Plume add-on (README).
"""

import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402
import toon_kit  # noqa: E402

TAG = "toon_ceiling"
USAGE = f"usage: blender -b --factory-startup --python examples/toon/{TAG}.py -- OUT_DIR [FRAMES]"
RESOLUTION = 80            # cells on the longest (vertical) axis: 40 x 40 x 80
DEFAULT_FRAMES = 60
SHOW = (0.3, 0.5, 0.75, 1.0)  # rendered frames, as fractions of the shot
BACKGROUND = (0.20, 0.22, 0.27)
CEILING = (0.05, 0.05, 0.06)
#: (name, colour driver, driver range, ramp colours low -> high): Figure 7's two versions.
VERSIONS = (("speed", 'SPEED', (1.0, 7.0), (0.3, 0.55, 1.0), (1.0, 0.3, 0.1)),
            ("white", 'DENSITY', (0.0, 1.0), (1.0, 1.0, 1.0), (1.0, 1.0, 1.0)))


def make_scene(frames):
    toon_kit.sphere_source("Jet", 0.12, (0.0, 0.0, 0.15), density=1.0, temperature=1.0,
                            velocity=(0.0, 0.0, 2.5))
    dom = scene_kit.domain_cube("Ceiling", 1.0, (0.0, 0.0, 1.0), RESOLUTION, frames)
    dom.scale = (1.0, 1.0, 2.0)  # 1 x 1 x 2 m: 40 x 40 x 80 cells of 2.5 cm
    d = dom.plume.domain
    for side in ("neg_x", "pos_x", "neg_y", "pos_y", "pos_z"):  # walls and the ceiling
        setattr(d, "boundary_" + side, 'CLOSED')
    d.vorticity = 0.3
    d.turbulence = 0.0  # the paper's still air (tuned before Turbulence)
    toon_kit.puffs(d.toon, 8, sizes=(0.15, 0.3), densities=(0.05, 0.6),
                           death_density=0.05, depth_threshold=0.12)
    return dom


def set_version(t, version):
    _name, driver, (low, high), color_low, color_high = version
    t.color_driver, t.color_low, t.color_high = driver, low, high
    t.ramp_color_low, t.ramp_color_high = (*color_low, 1.0), (*color_high, 1.0)


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    dom = make_scene(frames)
    # The ceiling, drawn (only a picture: the domain's closed top is the ceiling the smoke meets;
    # the beam clears the 15 cm half-billboards under it).
    scene_kit.flat_box("CeilingBeam", (0.0, 0.0, 2.2), (3.0, 0.1, 0.1), CEILING)
    scene_kit.camera(scene, (0.0, -3.8, 1.05), (90.0, 0.0, 0.0), lens=50.0)
    toon_kit.toon_look(scene, BACKGROUND, 240, 400, 16, os.path.join(out_dir, TAG + "_"))
    scene.frame_start, scene.frame_end = 1, frames
    set_version(dom.plume.domain.toon, VERSIONS[0])
    scene_kit.save_blend(out_dir, TAG)

    bake_s, build_s = toon_kit.bake_toon(dom, TAG)
    shown = scene_kit.shown_frames(SHOW, frames)
    paths, render_s = [], 0.0
    for n, version in enumerate(VERSIONS):
        if n > 0:
            set_version(dom.plume.domain.toon, version)
            build_s += toon_kit.build_toon(dom, TAG)
        seconds, rendered = scene_kit.render_frames_timed(scene, shown, out_dir,
                                                          f"{TAG}_{version[0]}")
        paths += rendered
        render_s += seconds
    bpy.ops.wm.save_mainfile()
    strip = scene_kit.strip(paths, os.path.join(out_dir, TAG + "_strip.png"), columns=len(shown))
    toon_kit.toon_summary(TAG, "40x40x80", frames, bake_s, build_s / len(VERSIONS), dom,
                           render_s / len(VERSIONS), strip)


if __name__ == "__main__":
    main()
