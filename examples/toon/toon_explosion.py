"""An explosion that propels smoke sideways until it cools and falls: Figure 6 of
[Cartoon Smoke], darkness from speed.

    blender -b --factory-startup --python examples/toon/toon_explosion.py -- OUT_DIR [FRAMES]

A 2.4 x 1.2 x 1.6 m domain (64 x 32 x 43 cells, open on every side but the floor). A Source
at the left end blows hot smoke sideways at 6 m/s for the first 4 frames only (its density,
temperature and velocity are keyframed to 0 after that). Heat lifts the smoke (β > 0) while its
own weight pulls it down (α < 0). The domain's cooling terms take the heat away (Combustion on
with no fuel, so only T changes: the hot burst cools by c ((T - T_amb) / (T_max - T_amb))^4 per
second, and conduction κ spreads its heat into the clear air), so the cloud slows down, sinks
and falls to the floor. Build Toon Smoke colours each particle by its speed (Colour Driver:
Speed): dark while it flies, light once it slows down (the paper: "the darkness is proportional
to the magnitude of the particle velocity"); particles come from the Source and are born
where the smoke is denser than 0.3, 0.8 stencil sizes apart, which keeps the slumped cloud
whole. The floor is drawn as a flat box.

Writes OUT_DIR/toon_explosion.blend (cache in OUT_DIR/plume_cache), toon_explosion_####.png for
a few frames and toon_explosion_strip.png (the manual's image); prints the bake, build and
render times. Needs the Plume add-on (README).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402
import toon_kit  # noqa: E402

TAG = "toon_explosion"
USAGE = f"usage: blender -b --factory-startup --python examples/toon/{TAG}.py -- OUT_DIR [FRAMES]"
RESOLUTION = 64            # cells on the longest axis: 64 x 32 x 32
DEFAULT_FRAMES = 48
BURST_FRAMES = 4           # frames the source blows
SHOW = (0.06, 0.25, 0.55, 0.85)  # rendered frames, as fractions of the shot
BACKGROUND = (0.55, 0.6, 0.68)
FLOOR = (0.2, 0.17, 0.14)
SLOW, FAST = (0.95, 0.93, 0.88), (0.08, 0.07, 0.07)  # ramp colours: light when slow, dark when fast


def make_scene(frames):
    src = toon_kit.sphere_source("Blast", 0.15, (-0.95, 0.0, 0.95), density=1.0,
                                  temperature=1.0, velocity=(6.0, 0.0, 0.3))
    toon_kit.burst(src, BURST_FRAMES)
    dom = scene_kit.domain_cube("Explosion", 1.0, (0.0, 0.0, 0.8), RESOLUTION, frames)
    dom.scale = (2.4, 1.2, 1.6)
    d = dom.plume.domain
    d.alpha, d.beta = -1.0, 1.5      # heavy smoke, lifted while hot
    d.combustion = True              # for its cooling terms only: the source has no fuel
    d.max_temperature = 1.0          # T_max: the source's temperature
    d.cooling_rate = 8.0             # c: the hot burst cools fast ...
    d.conductivity = 0.04            # κ (m²/s): ... then loses its heat to the air around it
    d.vorticity = 0.3
    d.turbulence = 0.0  # the paper's still air (tuned before Turbulence)
    t = d.toon
    toon_kit.puffs(t, 80, sizes=(0.08, 0.2), densities=(0.03, 0.4), death_density=0.05,
                           depth_threshold=0.1)
    t.color_driver = 'SPEED'
    t.color_low, t.color_high = 0.1, 1.5  # m/s
    t.ramp_color_low, t.ramp_color_high = (*SLOW, 1.0), (*FAST, 1.0)
    return dom


def setup(scene, frames, out_dir):
    dom = make_scene(frames)
    scene_kit.flat_box("Floor", (0.0, 0.0, -0.05), (4.0, 1.2, 0.1), FLOOR)  # the domain's floor
    scene_kit.camera(scene, (0.0, -4.2, 0.8), (90.0, 0.0, 0.0), lens=50.0)
    toon_kit.toon_look(scene, BACKGROUND, 384, 256, 16, os.path.join(out_dir, TAG + "_"))
    return dom


def main():
    toon_kit.toon_example(TAG, USAGE, DEFAULT_FRAMES, setup, SHOW, "64x32x43")


if __name__ == "__main__":
    main()
