"""Two puffs of smoke propelled at each other form a donut: Figure 5 of [Cartoon Smoke].

    blender -b --factory-startup --python examples/toon/toon_donut.py -- OUT_DIR [FRAMES]

Two spherical Sources face each other across a 1.2 m domain (64³, open on every side, no
buoyancy) and blow smoke at each other at 3 m/s for the first 5 frames only (their density and
velocity are keyframed to 0 after that). Each puff rolls up into a vortex ring; where they meet,
the rings stop each other and spread out sideways into one ring: a donut. Build Toon Smoke
(puffy stencil, depth-difference outlines; particles from the Sources, and born where the smoke
is denser than 0.3, 0.8 stencil sizes apart, so the ring stays whole as it spreads) follows the
topology change; the camera looks at the ring's plane at an angle, so the hole shows.

Writes OUT_DIR/toon_donut.blend (cache in OUT_DIR/plume_cache), toon_donut_####.png for a few
frames and toon_donut_strip.png (the manual's image); prints the bake, build and render times.
Needs the Plume add-on (README).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402
import toon_kit  # noqa: E402

TAG = "toon_donut"
USAGE = f"usage: blender -b --factory-startup --python examples/toon/{TAG}.py -- OUT_DIR [FRAMES]"
RESOLUTION = 64
DEFAULT_FRAMES = 40
BURST_FRAMES = 5           # frames the sources blow
SPEED = 3.0                # m/s, towards each other
SHOW = (0.08, 0.25, 0.45, 0.7)  # rendered frames, as fractions of the shot
BACKGROUND = (0.20, 0.22, 0.27)
CENTRE = (0.0, 0.0, 0.6)


def make_scene(frames):
    for name, x in (("PuffLeft", -0.42), ("PuffRight", 0.42)):
        src = toon_kit.sphere_source(name, 0.1, (x, CENTRE[1], CENTRE[2]), density=1.0,
                                      velocity=(-SPEED if x > 0 else SPEED, 0.0, 0.0))
        toon_kit.burst(src, BURST_FRAMES)
    dom = scene_kit.domain_cube("Donut", 1.2, CENTRE, RESOLUTION, frames)
    d = dom.plume.domain
    d.alpha = d.beta = 0.0           # no buoyancy: the puffs move only as they were pushed
    d.boundary_neg_z = 'OPEN'        # no floor
    d.vorticity = 0.3
    d.turbulence = 0.0  # the paper's still air (tuned before Turbulence)
    t = d.toon
    toon_kit.puffs(t, 60, sizes=(0.08, 0.2), densities=(0.03, 0.4), death_density=0.03,
                           depth_threshold=0.1)
    t.color_driver = 'DENSITY'
    t.color_low, t.color_high = 0.03, 0.4
    t.ramp_color_low, t.ramp_color_high = (0.55, 0.75, 1.0, 1.0), (1.0, 1.0, 1.0, 1.0)
    return dom


def setup(scene, frames, out_dir):
    dom = make_scene(frames)
    scene_kit.camera(scene, (1.8, -1.6, 1.35), lens=50.0, target=CENTRE)
    toon_kit.toon_look(scene, BACKGROUND, 320, 320, 16, os.path.join(out_dir, TAG + "_"))
    return dom


def main():
    toon_kit.toon_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, f"{RESOLUTION}^3")


if __name__ == "__main__":
    main()
