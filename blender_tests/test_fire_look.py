"""The combustion fire reads as fire under each Blender's default view transform (issue 30):
AgX in 4.x/5.x, Filmic in 3.4.1; no colour-management setting is touched here or by Plume.

A small combustion bake through the operators (plume.role_set, plume.bake) with the domain's
default combustion settings and the default "Plume Fire" material: a 1 m cube domain at 40
cells, a UV sphere of radius 0.08 m at z 0.12 m with Fuel 1 and Density 0, 30 frames. Three late
frames are rendered (Cycles CPU, 240 x 240, 16 samples, black world) through the scene's own
view transform to PNG and measured with fire_look.measure:
- hue of the coloured pixels in [20, 50] degrees (orange-yellow; a blackbody's salmon reads < 18);
- white (clipped) share and lit share (not black, not a speck);
- not a tube (the old material lit the rising column uniformly to the domain's top): the flame
  ends well below the domain's top, its lower half is brighter than its upper half, and its
  outline changes from frame to frame (it flickers).

Run: python3 blender_tests/run.py --blender all blender_tests/test_fire_look.py
"""

import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import fire_look  # noqa: E402
from helpers import (OUT_DIR, add_domain, add_sphere_source, flame_studio, image_pixels,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)

RESOLUTION = 40
FRAMES = 30
RENDERED = (24, 27, 30)
WIDTH = HEIGHT = 240
#: Rows of the 240-px image of the domain's top (z = 1 m) and floor (z = 0) seen from the
#: camera at (0, -2.2, 0.5) (50 mm lens, 36 mm sensor): 120 -+ 0.5 / (2.2 · 18 / 50) · 120.
DOMAIN_TOP_ROW, DOMAIN_FLOOR_ROW = 44, 196
#: A row belongs to the flame when at least this many of its pixels are lit (single lit pixels
#: high up are Cycles noise from the thinnest fuel, not flame).
ROW_MIN_LIT = 3

# Measured per Blender (frames 24 / 27 / 30; bake 3.8-4.7 s, render 1.9-8.8 s a frame), with
# today's defaults (burn rate 1.5, heat yield 6, T_max 3, Flame Vorticity 24, Flicker 0.8):
#   Blender, view     hue (deg)          white  lit share (%)    flame top z (m)     outline changed
#   3.4.1 Filmic      31.0 / 30.4 / 29.9   0%   4.2 / 4.4 / 4.2  0.84 / 0.70 / 0.80  0.438, 0.436
#   4.2.23 AgX        29.9 / 29.6 / 29.4   0%   3.8 / 3.9 / 3.6  0.82 / 0.70 / 0.79  0.407, 0.426
#   4.5.15 AgX        29.9 / 29.6 / 29.4   0%   3.7 / 3.9 / 3.5  0.82 / 0.70 / 0.79  0.408, 0.428
#   5.0.1 AgX         29.9 / 29.5 / 29.5   0%   3.7 / 3.8 / 3.4  0.82 / 0.70 / 0.79  0.420, 0.429
#   5.3.0 AgX         29.9 / 29.5 / 29.5   0%   3.6 / 3.8 / 3.4  0.82 / 0.69 / 0.79  0.414, 0.434
# With burn rate 6, T_max 4, no Flame Vorticity or Flicker (the first ramp-material defaults): hue
# 30.4-37.2, lit 3.8-4.3%, flame top 0.61-0.67, outline changed 0.069-0.094. The combustion
# defaults before the colour ramp (burn rate 4, cooling 1, expansion 1, vorticity 0.2) with this
# material, in 4.5: flame top z 1.0 (the domain's top: a tube), outline changed 0.035, 0.036
# (sampling noise at the soft edge); with the old material (emission 40 x flame) the tube was
# lit to the top too, hue 27.0.
HUE_RANGE = (20.0, 50.0)
#: Issue 30 asks for well under half; 0% measured everywhere.
WHITE_MAX = 0.05
#: 3.4-4.4% measured.
LIT_MIN = 0.025
#: The flame's top (topmost row with ROW_MIN_LIT lit pixels) is below this height in the domain:
#: the old uniform tube reached the top, z = 1. Measured 0.61-0.67 with burn rate 6 and no Flame
#: Vorticity or Flicker (the bound was 0.75 then); today's defaults (burn rate 1.5, Flame
#: Vorticity 24, Flicker 0.8) give a taller fire whose tongues reach 0.70-0.82 in 4.5 (a 0.3 m
#: burner's fire in Mantaflow is about four burners tall, examples/smoke/fire_vs_mantaflow.py),
#: so the bound is now 0.9: still below the tube's 1.0, and test_base_brighter_than_tips checks
#: that the flame tapers.
FLAME_TOP_MAX = 0.9
#: Share of the flame's pixels (lit in either frame) lit in only one of two rendered frames, at
#: least: 0.41-0.44 measured (0.069-0.094 before Flicker); the old defaults' steady column 0.035
#: (edge noise).
FLICKER_MIN = 0.25


def flame_rows(lit):
    """(first, last) row (top first) with ROW_MIN_LIT lit pixels, or None."""
    rows = np.nonzero(lit.sum(axis=1) >= ROW_MIN_LIT)[0]
    return (int(rows[0]), int(rows[-1])) if len(rows) else None


def row_height(row):
    """Height (m) in the domain of image row `row` (top first), on the domain's mid plane."""
    return (DOMAIN_FLOOR_ROW - row) / (DOMAIN_FLOOR_ROW - DOMAIN_TOP_ROW)


class FireLookTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_fire_look_")
        cls.out = os.path.join(OUT_DIR, "fire_look")
        os.makedirs(cls.out, exist_ok=True)
        reset_scene()
        scn = bpy.context.scene
        cls.view_transform = scn.view_settings.view_transform  # the default: not set here
        dom = add_domain(size=1.0, location=(0.0, 0.0, 0.5), resolution=RESOLUTION,
                         frame_end=FRAMES, cache_directory=cls.tmp + "/")
        dom.plume.domain.combustion = True
        src = add_sphere_source(radius=0.08, location=(0.0, 0.0, 0.12))
        src.plume.source.fuel = 1.0
        src.plume.source.density = 0.0
        select_only(dom)
        t0 = time.perf_counter()
        bpy.ops.plume.bake()
        cls.bake_s = time.perf_counter() - t0
        flame_studio(scn, (0.0, -2.2, 0.5), WIDTH, HEIGHT, 16)
        scn.render.image_settings.file_format = 'PNG'
        cls.pixels, cls.looks = {}, {}
        t0 = time.perf_counter()
        for f in RENDERED:
            scn.frame_set(f)
            scn.render.filepath = os.path.join(cls.out, f"fire_{f:03d}.png")
            bpy.ops.render.render(write_still=True)
            px = image_pixels(scn.render.filepath)[::-1, :, :3]  # top row first
            cls.pixels[f] = px
            cls.looks[f] = fire_look.measure(px)
        cls.render_s = (time.perf_counter() - t0) / len(RENDERED)
        print(f"  Blender {bpy.app.version_string}, view transform {cls.view_transform}: bake "
              f"{cls.bake_s:.1f} s, render {cls.render_s:.1f} s a frame")
        for f in RENDERED:
            lit = cls.pixels[f].max(axis=2) > fire_look.LIT
            rows = flame_rows(lit)
            top = f"{row_height(rows[0]):.2f}" if rows else "-"
            print(f"  frame {f}: {fire_look.text(cls.looks[f])}, flame top z {top} m")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_view_transform_untouched(self):
        """The scene keeps its Blender's default view transform (Filmic in 3.x, AgX later)."""
        self.assertEqual(self.view_transform, "Filmic" if bpy.app.version < (4, 0, 0) else "AgX")
        self.assertEqual(bpy.context.scene.view_settings.view_transform, self.view_transform)
        self.assertEqual(bpy.context.scene.view_settings.look, "None")
        self.assertEqual(bpy.context.scene.view_settings.exposure, 0.0)

    def test_fire_vorticity(self):
        """Combustion on swaps the smoke's default vorticity for the fire's; off, back."""
        from plume.properties import domain
        d = bpy.data.objects["Domain"].plume.domain
        self.assertAlmostEqual(d.vorticity, domain.FIRE_VORTICITY, places=5)
        d.combustion = False
        self.assertAlmostEqual(d.vorticity, domain.SMOKE_VORTICITY, places=5)
        d.vorticity = 1.5  # the artist's own value stays
        d.combustion = True
        self.assertAlmostEqual(d.vorticity, 1.5, places=5)
        d.vorticity = domain.FIRE_VORTICITY

    def test_hue_orange_yellow(self):
        for f, m in self.looks.items():
            self.assertTrue(HUE_RANGE[0] <= m["hue"] <= HUE_RANGE[1], (f, fire_look.text(m)))

    def test_not_clipped_white(self):
        for f, m in self.looks.items():
            self.assertLess(m["white_share"], WHITE_MAX, (f, fire_look.text(m)))

    def test_lit(self):
        for f, m in self.looks.items():
            self.assertGreater(m["lit_share"], LIT_MIN, (f, fire_look.text(m)))

    def test_flame_ends_below_top(self):
        """The flame ends: its top row is well below the domain's top (the tube reached it)."""
        for f, px in self.pixels.items():
            rows = flame_rows(px.max(axis=2) > fire_look.LIT)
            self.assertIsNotNone(rows, f)
            self.assertLess(row_height(rows[0]), FLAME_TOP_MAX, f)

    def test_base_brighter_than_tips(self):
        """The lower half of the flame is brighter (mean value of its lit pixels) than its upper
        half."""
        for f, px in self.pixels.items():
            v = px.max(axis=2)
            lit = v > fire_look.LIT
            first, last = flame_rows(lit)
            mid = (first + last) // 2
            upper = v[first:mid][lit[first:mid]].mean()
            lower = v[mid:last + 1][lit[mid:last + 1]].mean()
            self.assertGreater(lower, upper, (f, upper, lower))

    def test_flickers(self):
        """The outline changes between rendered frames: a share of the pixels lit in either of two
        frames is lit in only one (a steady column or candle gives ~0)."""
        shares = []
        for a, b in zip(RENDERED, RENDERED[1:]):
            la = self.pixels[a].max(axis=2) > fire_look.LIT
            lb = self.pixels[b].max(axis=2) > fire_look.LIT
            shares.append(float((la ^ lb).sum()) / max(int((la | lb).sum()), 1))
        print(f"  outline changed between frames: {', '.join(f'{s:.3f}' for s in shares)}")
        self.assertGreater(max(shares), FLICKER_MIN, shares)


if __name__ == "__main__":
    run(FireLookTest)
