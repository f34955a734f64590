"""Toon outlines keep their weight relative to the picture ([Cartoon Smoke] §2.2 lines drawn
with an Outline Width in pixels of a 1080-line picture). A small bake (24³, 20 frames), Build
Toon Smoke, Outline Width 6, then the same frame rendered from a 1920x1080 scene at 25 % (270
lines: a 1.5 px line) and 50 % (540 lines: a 3 px line), the resolution changed after the build
as an artist would. The compositor group's Line (the drawn line's coverage) and Outline (§2.2's
one-pixel-offset test, a band 2 px wide across every depth edge whatever the resolution: its
area / 2 is the outline's length in pixels) are saved as 32-bit EXR; the line's width is its
area over that length.

Checked: the width at 540 lines is about twice the one at 270 (the geometry is the same, only
the pixel grid differs), it is not a one-pixel line at 540 lines, and the line is antialiased:
a good share of its pixels are partly covered (a grey between the smoke and the outline colour),
while its core is fully covered. Then Thin With Distance: the far smoke's line gets thinner.

Run: python3 blender_tests/run.py --blender 3.4 blender_tests/test_toon_outline_width.py
"""

import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, add_domain, add_sphere_source, compat, image_pixels,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)

FRAME = 16
WIDTH = 6.0                 # px at 1080 lines: 1.5 px at 270, 3 px at 540
PERCENTAGES = (25, 50)
# Measured (3.4.1 and 5.3.0 alike): line width 1.46 px at 270 lines, 2.91 px at 540, ratio
# 1.992. The same bake and frame, only the pixel grid differs: the few % allowed cover the
# staircase of the depth edges on two grids and lines merging across puffs thinner than them
# (an earlier, sharper edge ramp measured 1.94 on this frame).
RATIO_LOW, RATIO_HIGH = 1.8, 2.2
MIN_LARGE_WIDTH = 2.0       # px at 540 lines; measured 2.91: not a one-pixel line
# Partly covered (0.05-0.95) share of the line's pixels at 540 lines; measured 47.6 %, fully
# covered 52.4 % (a one-pixel binary line: 0 % partly covered).
MIN_SOFT_SHARE = 0.2
MIN_FULL_SHARE = 0.2
# Thinned / full width at 540 lines with Thin With Distance 1 from 1 m, the smoke about 3 m
# from the camera (expected about 1/3): measured 0.346 (3.4.1), 0.349 (5.3.0).
THIN_LOW, THIN_HIGH = 0.25, 0.45


def render_widths(test, out, percentages, tag=""):
    """{percentage: (width px, soft share, full share, line pixels)} of the rendered frame."""
    scn = bpy.context.scene
    scn.frame_set(FRAME)
    found = {}
    for pct in percentages:
        scn.render.resolution_percentage = pct
        scn.render.filepath = os.path.join(out, f"toon_{pct}{tag}.png")
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t0
        line = image_pixels(os.path.join(out, f"line{FRAME:04d}.exr"))[..., 0]
        outline = image_pixels(os.path.join(out, f"outline{FRAME:04d}.exr"))[..., 0] > 0.5
        os.replace(os.path.join(out, f"line{FRAME:04d}.exr"),
                   os.path.join(out, f"line_{pct}{tag}.exr"))
        test.assertEqual(line.shape[0], 1080 * pct // 100)
        length = outline.sum() / 2.0
        test.assertGreater(length, 100, "the smoke is outlined")
        drawn = line > 0.02
        soft = float(np.mean((line[drawn] > 0.05) & (line[drawn] < 0.95)))
        full = float(np.mean(line[drawn] > 0.999))
        found[pct] = (float(line.sum() / length), soft, full, int(drawn.sum()))
        print(f"  {line.shape[1]}x{line.shape[0]}{tag}: render {seconds:.1f} s, outline length "
              f"{length:.0f} px, line width {found[pct][0]:.2f} px, partly covered "
              f"{soft * 100:.1f} %, fully covered {full * 100:.1f} % of {found[pct][3]} px")
    return found


class ToonOutlineWidthTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_toon_outline_width_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_width_scales_with_resolution(self):
        reset_scene()
        src = add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.4))
        src.plume.source.velocity = (0.0, 0.0, 1.0)
        src.plume.source.density = 2.0
        dom = add_domain(resolution=24, frame_end=20,
                         cache_directory=os.path.join(self.tmp, "cache") + "/")
        t = dom.plume.domain.toon
        t.birth_density, t.death_density = 0.3, 0.05
        t.size_low, t.size_high = 0.08, 0.2
        t.max_size_change = 0.5
        t.depth_threshold = 0.05
        scn = bpy.context.scene
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scn.collection.objects.link(cam)
        cam.location, cam.rotation_euler = (0.0, -3.2, 1.0), (np.pi / 2, 0.0, 0.0)
        scn.camera = cam
        scn.frame_start, scn.frame_end = 1, 20
        select_only(dom)
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(dom)
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})
        print(f"  bake + toon build: {time.perf_counter() - t0:.1f} s")
        t.outline_width = WIDTH  # a look setting: no rebuild
        group = compat.compositor_tree(scn).nodes["Plume Depth Differences"]
        self.assertAlmostEqual(group.inputs["Outline Width"].default_value, WIDTH, places=6)
        dom.hide_render = True
        volume = bpy.data.objects.get(dom.plume.domain.volume_object)
        if volume is not None:
            volume.hide_render = True
        scn.render.engine = 'CYCLES'
        scn.cycles.device, scn.cycles.samples, scn.cycles.use_denoising = 'CPU', 2, False
        # Set after the build: the compositor follows the render's size.
        scn.render.resolution_x, scn.render.resolution_y = 1920, 1080
        out = os.path.join(OUT_DIR, "toon_outline_width")
        os.makedirs(out, exist_ok=True)
        nt = compat.compositor_tree(scn)
        compat.compositor_file_output(nt, out, "line", group.outputs["Line"])
        compat.compositor_file_output(nt, out, "outline", group.outputs["Outline"])
        found = render_widths(self, out, PERCENTAGES)
        small, large = found[PERCENTAGES[0]], found[PERCENTAGES[1]]
        ratio = large[0] / small[0]
        print(f"  width ratio {ratio:.3f} (expected 2)")
        self.assertGreaterEqual(ratio, RATIO_LOW)
        self.assertLessEqual(ratio, RATIO_HIGH)
        self.assertGreater(large[0], MIN_LARGE_WIDTH)
        self.assertGreater(large[1], MIN_SOFT_SHARE)  # antialiased: grey levels on the edge
        self.assertGreater(large[2], MIN_FULL_SHARE)  # ... around a solid core
        # Thin With Distance 1 from 1 m: the smoke, about 3 m away, gets lines about a third as
        # wide.
        t.outline_thinning, t.outline_thinning_distance = 1.0, 1.0
        thin = render_widths(self, out, PERCENTAGES[1:], "_thin")[PERCENTAGES[1]]
        print(f"  thinned / full width {thin[0] / large[0]:.3f}")
        self.assertGreater(thin[0] / large[0], THIN_LOW)
        self.assertLess(thin[0] / large[0], THIN_HIGH)


if __name__ == "__main__":
    run(ToonOutlineWidthTest)
