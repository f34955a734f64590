"""The three stencils of Figure 3 of [Cartoon Smoke]: circle, puffy cloud and hairy cloud, and
the same puff of smoke drawn with each.

    blender -b --factory-startup --python examples/toon/toon_stencils.py -- OUT_DIR [FRAMES]

A spherical Source at the bottom of a 1.2 m domain (48³, open on every side but the floor)
blows hot smoke upwards at 2 m/s for its first 8 frames (density, temperature and velocity
keyframed to 0 after): one puff that rises and rolls up into a mushroom. It is baked once, then
Build Toon Smoke runs three times with the same particles (15 per frame from the Source, births
in the dense smoke kept one stencil size apart, 10 to 24 cm stencils, γ = 0.1 m), once per
stencil, and the middle frame of the shot is rendered with each. The strip's top row shows each stencil as Plume generates it
(its cut-out drawn white with the outline the depth differences give it), the bottom row the
puff drawn with it.

Writes OUT_DIR/toon_stencils.blend (cache in OUT_DIR/plume_cache), toon_stencils_<kind>_####.png,
stencil_<kind>.png and toon_stencils_strip.png (the manual's image); prints the bake, build and
render times. Needs the Plume add-on (README).
"""

import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402
import toon_kit  # noqa: E402

TAG = "toon_stencils"
USAGE = f"usage: blender -b --factory-startup --python examples/toon/{TAG}.py -- OUT_DIR [FRAMES]"
RESOLUTION = 48
DEFAULT_FRAMES = 20
BURST_FRAMES = 10
SHOW = 0.5                 # the rendered frame, as a fraction of the shot
SIZE = 320                 # pixels per side of every picture of the strip
BACKGROUND = (0.20, 0.22, 0.27)
KINDS = ('CIRCLE', 'PUFFY', 'HAIRY')
CENTRE = (0.0, 0.0, 0.6)


def make_scene(frames):
    src = toon_kit.sphere_source("Puff", 0.15, (0.0, 0.0, 0.2), density=1.5, temperature=1.0,
                                 velocity=(0.0, 0.0, 1.5))
    toon_kit.burst(src, BURST_FRAMES)
    dom = scene_kit.domain_cube("Stencils", 1.2, CENTRE, RESOLUTION, frames)
    d = dom.plume.domain
    d.vorticity = 0.3
    d.turbulence = 0.0  # the paper's still air (tuned before Turbulence)
    t = d.toon
    toon_kit.puffs(t, 15, sizes=(0.1, 0.24), densities=(0.05, 0.5), death_density=0.04,
                   depth_threshold=0.1, birth_spacing=1.0)
    t.color_driver = 'DENSITY'
    t.color_low, t.color_high = 0.05, 0.5
    t.ramp_color_low, t.ramp_color_high = (0.6, 0.75, 0.95, 1.0), (1.0, 1.0, 1.0, 1.0)
    return dom


def stencil_picture(kind, path):
    """The stencil as Plume generates it (toon_stencils), drawn as the toon renderer draws one
    stencil: white cut-out, black outline where it meets the background, on the background (its
    linear colour encoded in sRGB, as the renders are)."""
    stencils = scene_kit.addon_module("toon_stencils")
    inner = 256  # the stencil's side in the picture, centred
    inside = stencils.stencil_alpha(kind, inner) >= 0.5
    mask = np.zeros((SIZE, SIZE), bool)
    o = (SIZE - inner) // 2
    mask[o:o + inner, o:o + inner] = inside
    # An outline pixel: inside with a 4-neighbour outside, or outside with one inside (§2.2 marks
    # both sides of a depth jump).
    near = np.zeros_like(mask)
    for axis in (0, 1):
        for step in (-1, 1):
            near |= np.roll(mask, step, axis) != mask
    rgba = np.empty((SIZE, SIZE, 4), np.uint8)
    srgb = [1.055 * c ** (1.0 / 2.4) - 0.055 if c > 0.0031308 else 12.92 * c for c in BACKGROUND]
    rgba[...] = [round(255 * c) for c in (*srgb, 1.0)]
    rgba[mask] = 255
    rgba[near] = (0, 0, 0, 255)
    with open(path, "wb") as f:
        f.write(stencils.png_bytes(rgba))
    return path


def main():
    out_dir, frames = scene_kit.parse_args(USAGE, DEFAULT_FRAMES)
    scene = scene_kit.new_scene()
    dom = make_scene(frames)
    scene_kit.camera(scene, (0.0, -3.0, 0.65), (90.0, 0.0, 0.0), lens=70.0)
    toon_kit.toon_look(scene, BACKGROUND, SIZE, SIZE, 16, os.path.join(out_dir, TAG + "_"))
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, TAG)
    frame = scene_kit.shown_frames((SHOW,), frames)[0]
    stencils, renders, build_s, render_s, bake_s = [], [], 0.0, 0.0, 0.0
    for n, kind in enumerate(KINDS):
        dom.plume.domain.toon.stencil = kind
        if n == 0:
            bake_s, seconds = toon_kit.bake_toon(dom, TAG)
        else:
            seconds = toon_kit.build_toon(dom, TAG)
        build_s += seconds
        seconds, paths = scene_kit.render_frames_timed(scene, [frame], out_dir,
                                                       f"{TAG}_{kind.lower()}")
        render_s += seconds
        renders += paths
        stencils.append(stencil_picture(kind, os.path.join(out_dir,
                                                           f"stencil_{kind.lower()}.png")))
    bpy.ops.wm.save_mainfile()
    strip = scene_kit.strip(stencils + renders, os.path.join(out_dir, TAG + "_strip.png"),
                            columns=len(KINDS))
    toon_kit.toon_summary(TAG, f"{RESOLUTION}^3", frames, bake_s, build_s / len(KINDS), dom,
                          render_s / len(KINDS), strip)


if __name__ == "__main__":
    main()
