"""Toon smoke with its defaults on an ordinary scene ([Cartoon Smoke] §2.2-2.3): a 2 m domain
at 40³ in still air (Turbulence 0), a UV sphere of radius 0.25 m as an even Source (Breakup 0),
60 frames, Build Toon Smoke with every toon setting at its default, a camera framing the
domain, 640x360 Cycles.
The outlines must be the silhouettes of puffs, not speckles all over the smoke: on frames 15
(the rising cap), 30 and 45 (the column) the share of outline pixels inside the smoke's
interior (smoke pixels at least 3 px from the background) and the share of interior pixels in
specks (interior outline pieces of fewer than 30 pixels: the ring around a stencil a few pixels
wide) stay small.

Measured (3.4.1): with the old defaults (stencils 2-10 cm, growth 10 frames, γ = 0.1 m, a
particle born in every empty dense cell) interior outline share 3.0 / 7.6 / 4.2 % (mean 4.9 %),
specks 1.5 / 3.2 / 2.4 %; with the new ones (10-25 cm, 4 frames, γ = 0.15 m, birth spacing
0.5) 1.7 / 2.0 / 0.3 % (mean 1.3 %), specks 0.6 / 0.5 / 0.3 %. The bounds sit between: mean
share <= 2.5 %, specks <= 1 % on every frame.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_toon_defaults.py
"""

import math
import os
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, add_domain, add_sphere_source, compat, image_pixels,  # noqa: E402
                     reset_scene, rmtree, run, select_only, temp_dir)

FRAMES = (15, 30, 45)
INTERIOR_PX = 3       # interior: smoke pixels this far (Chebyshev) from any background pixel
SPECK_PX = 30         # an interior outline piece smaller than this is a speck
MAX_MEAN_SHARE = 0.025
MAX_SPECKS = 0.01


def erode(mask, radius):
    """Pixels of `mask` whose (2 radius + 1)² square lies in `mask` (outside the image: not)."""
    padded = np.pad(mask, radius, constant_values=False)
    out = np.ones_like(mask)
    h, w = mask.shape
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            out &= padded[dy:dy + h, dx:dx + w]
    return out


def piece_sizes(mask):
    """Sizes of the 8-connected pieces of a boolean image, one entry per pixel of `mask` in
    np.nonzero order: the size of the piece it belongs to."""
    label = np.full(mask.shape, -1, np.int64)
    sizes = []
    for y0, x0 in zip(*np.nonzero(mask)):
        if label[y0, x0] >= 0:
            continue
        n, stack = 0, [(y0, x0)]
        label[y0, x0] = len(sizes)
        while stack:
            y, x = stack.pop()
            n += 1
            for yy in range(max(y - 1, 0), min(y + 2, mask.shape[0])):
                for xx in range(max(x - 1, 0), min(x + 2, mask.shape[1])):
                    if mask[yy, xx] and label[yy, xx] < 0:
                        label[yy, xx] = len(sizes)
                        stack.append((yy, xx))
        sizes.append(n)
    return np.asarray(sizes, np.int64)[label[mask]] if sizes else np.zeros(0, np.int64)


class ToonDefaultsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_toon_defaults_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_outlines_are_puff_silhouettes(self):
        reset_scene()
        src = add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35))
        dom = add_domain(resolution=40, frame_end=60,
                         cache_directory=os.path.join(self.tmp, "cache") + "/")
        # The laminar column the toon defaults were measured on: still air and an even source
        # (the smoke defaults' Turbulence and Breakup came later and layer the smoke into lobes,
        # whose overlaps are outlined as they should be: interior share 1.3 / 3.2 / 3.4 % in
        # bpy 4.5, specks at most 0.6 %).
        dom.plume.domain.turbulence = 0.0
        src.plume.source.smoke_noise = 0.0
        scn = bpy.context.scene
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scn.collection.objects.link(cam)
        cam.location, cam.rotation_euler = (0.0, -5.5, 1.0), (math.radians(90.0), 0.0, 0.0)
        scn.camera = cam
        scn.frame_start, scn.frame_end = 1, 60
        select_only(dom)
        t0 = time.perf_counter()
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(dom)
        self.assertEqual(bpy.ops.plume.toon_build(), {'FINISHED'})  # toon settings untouched
        print(f"  bake + toon build: {time.perf_counter() - t0:.1f} s")
        dom.hide_render = True
        volume = bpy.data.objects.get(dom.plume.domain.volume_object)
        if volume is not None:
            volume.hide_render = True
        scn.render.engine = 'CYCLES'
        scn.cycles.device, scn.cycles.samples, scn.cycles.use_denoising = 'CPU', 4, False
        scn.render.resolution_x, scn.render.resolution_y = 640, 360
        scn.render.resolution_percentage = 100
        nt = compat.compositor_tree(scn)
        rl = next(n for n in nt.nodes if n.type == 'R_LAYERS')
        group = nt.nodes["Plume Depth Differences"]
        out = os.path.join(OUT_DIR, "toon_defaults")
        os.makedirs(out, exist_ok=True)
        compat.compositor_file_output(nt, out, "depth", rl.outputs["Depth"])
        compat.compositor_file_output(nt, out, "outline", group.outputs["Outline"])
        shares, specks = [], []
        for f in FRAMES:
            scn.frame_set(f)
            scn.render.filepath = os.path.join(out, f"toon_defaults_{f:04d}.png")
            bpy.ops.render.render(write_still=True)
            depth = image_pixels(os.path.join(out, f"depth{f:04d}.exr"))[..., 0]
            outline = image_pixels(os.path.join(out, f"outline{f:04d}.exr"))[..., 0] > 0.5
            smoke = depth < cam.data.clip_end
            interior = erode(smoke, INTERIOR_PX)
            self.assertGreater(int(interior.sum()), 5000, f"frame {f}: the smoke is in view")
            self.assertGreater(int(outline.sum()), 300, f"frame {f}: the smoke is outlined")
            inner = outline & interior
            shares.append(float(inner.sum() / interior.sum()))
            specks.append(float((piece_sizes(inner) < SPECK_PX).sum() / interior.sum()))
            print(f"  frame {f}: interior {int(interior.sum())} px, outline share "
                  f"{shares[-1]:.4f}, specks {specks[-1]:.4f}")
        self.assertLessEqual(float(np.mean(shares)), MAX_MEAN_SHARE)
        for f, s in zip(FRAMES, specks):
            self.assertLessEqual(s, MAX_SPECKS, f"frame {f}")


if __name__ == "__main__":
    run(ToonDefaultsTest)
