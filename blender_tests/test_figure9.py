"""Figure 9 of [Smoke Surfaces], measured: on the incense scene of
examples/streak_surfaces/compare_representations.py (its own functions: 50³, 20 point sources,
the same camera, 200 x 320, every panel under the Fast Sheet Render set-up, its 84 frames: the
150³ panels are left out, their bake is too slow for a test), the last frame rendered three ways with that example's looks (figure9_looks.py):
Plume's streak sheets (16 samples), the same streaklines' particles as soft specks (16 samples)
and the density field as a Principled Volume (64 samples). With figure9_looks.measure:
- the particles and the volume send about the light the sheets send (the fair match the figure
  rests on);
- the sheets are continuous where the same streaklines' particles are specks (speckle: the
  share of the light in detail finer than 3 pixels). Not on a young plume (40 frames): there
  the sheets are seen nearly edge-on as 1-2 pixel lines, as fine as the specks;
- the sheets have the sharp, high-contrast outline the volume lacks (edge: the 99th percentile
  of the brightness gradient over the smoke).
Measured values are in the constants' comments; renders go to $PLUME_TEST_OUT.

Run: python3 blender_tests/run.py --blender all test_figure9.py
"""

import os
import shutil
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(os.path.dirname(HERE), "examples")
sys.path[:0] = [HERE, os.path.join(EXAMPLES, "streak_surfaces"), EXAMPLES]

import bpy  # noqa: E402

from helpers import OUT_DIR, reset_scene, rmtree, run, temp_dir  # noqa: E402

#: Light of the particles and of the volume over the sheets' light, after match_light() scaled
#: the specks' opacity and the volume's density to the sheets' light. Measured (bpy 4.5):
#: particles 1.03-1.04, volume 1.01-1.03 in 3.4.1, 4.5 and 5.3 (the volume's grain moves it by
#: a few per cent).
LIGHT_RATIO_RANGE = (0.75, 1.3)
#: The sheets' speckle over the particles'. Measured: 0.47-0.48 (0.17 against 0.36) on the
#: order-2 sheets of before; 0.56-0.58 (0.22 against 0.39) on today's cubic ones (3.4.1, 4.5, 5.3).
SHEET_SPECKLE_RATIO_MAX = 0.65
#: The sheets' edge over the volume's. Measured: 3.7-4.1 (0.32-0.33 against 0.08-0.09) before;
#: 4.3-4.9 (0.31 against 0.06-0.07) today (3.4.1, 4.5, 5.3).
SHEET_EDGE_RATIO_MIN = 2.5
VOLUME_SAMPLES = 64


class Figure9Test(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import compare_representations as compare
        import figure9_looks as looks
        import scene_kit
        reset_scene()
        cls.tmp = temp_dir("plume_figure9_")
        frames = compare.DEFAULT_FRAMES
        scene, dom, _ = compare.bake(cls.tmp, frames, 50, 20)
        scene_kit.bake_surfaces(dom, "test_figure9")
        scene.frame_set(frames)
        out = os.path.join(OUT_DIR, "figure9")
        os.makedirs(out, exist_ok=True)
        sheets = {o for o in scene.objects if o.type == 'SURFACE'}
        volume = bpy.data.objects[dom.plume.domain.volume_object]
        specks = looks.particles_object(dom, frames, compare.PARTICLE_RADIUS,
                                        compare.PARTICLE_OPACITY[50],
                                        compare.PARTICLE_FULL_DENSITY,
                                        dom.plume.domain.sheet_brightness)
        cls.m = {}
        looks.show_only(scene, sheets)
        path = os.path.join(cls.tmp, "sheets.png")
        looks.render(scene, path, 16)
        target = looks.measure(path)["light"]
        # The example's matching (compare_representations.panels): each alternative's look
        # setting scaled until its probe renders send the sheets' light.
        matched = {"volume": ({volume}, lambda v: looks.set_volume_look(volume, v),
                              compare.VOLUME_DENSITY[50], VOLUME_SAMPLES),
                   "particles": ({specks}, lambda v: looks.set_speck_opacity(specks, v),
                                 compare.PARTICLE_OPACITY[50], 16)}
        values = {}
        for name, (shown, apply, start, samples) in matched.items():
            looks.show_only(scene, shown)
            values[name] = looks.match_light(scene, os.path.join(cls.tmp, "probe.png"), apply,
                                             start, target, samples)
        for name, shown, samples in (("sheets", sheets, 16), ("particles", {specks}, 16),
                                     ("volume", {volume}, VOLUME_SAMPLES)):
            looks.show_only(scene, shown)
            path = os.path.join(cls.tmp, name + ".png")
            looks.render(scene, path, samples)
            cls.m[name] = looks.measure(path)
            if name in matched and not 0.85 < cls.m[name]["light"] / target < 1.18:
                # In 3.4.1 a full run's probes sometimes misjudge the light (3 of 6 runs left
                # the panel at its starting look, 3x the sheets' light; never when run alone):
                # the match runs once more from here, and the panel is rendered again.
                print(f"figure 9, {name}: light {cls.m[name]['light']:.3f} after the match "
                      f"(target {target:.3f}): matching again", flush=True)
                _shown, apply, _start, _samples = matched[name]
                values[name] = looks.match_light(scene, os.path.join(cls.tmp, "probe.png"),
                                                 apply, values[name], target, samples)
                looks.render(scene, path, samples)
                cls.m[name] = looks.measure(path)
            shutil.copy(path, os.path.join(out, name + ".png"))
            print(f"figure 9, {name}: " + ", ".join(f"{k} {v:.3f}" for k, v in
                                                     cls.m[name].items()), flush=True)

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_light_matched(self):
        lo, hi = LIGHT_RATIO_RANGE
        for name in ("particles", "volume"):
            ratio = self.m[name]["light"] / self.m["sheets"]["light"]
            print(f"light, {name} / sheets: {ratio:.2f}")
            self.assertGreater(ratio, lo, name)
            self.assertLess(ratio, hi, name)

    def test_sheets_continuous_where_particles_are_specks(self):
        ratio = self.m["sheets"]["speckle"] / self.m["particles"]["speckle"]
        print(f"speckle, sheets / particles: {ratio:.2f}")
        self.assertLess(ratio, SHEET_SPECKLE_RATIO_MAX)

    def test_sheets_outline_the_volume_lacks(self):
        ratio = self.m["sheets"]["edge"] / self.m["volume"]["edge"]
        print(f"edge, sheets / volume: {ratio:.2f}")
        self.assertGreater(ratio, SHEET_EDGE_RATIO_MIN)


if __name__ == "__main__":
    run(Figure9Test)
