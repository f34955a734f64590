"""Structural flames' picture ([Structural Flames] §5), through the operators and Cycles
renders read back as linear EXR:

- eq. 6 reaches the image independent of the sampling: doubling Particles per Pixel leaves the
  rendered flame's total brightness within 5 % and its mean colour within 2 % (§5.3: "the total
  energy of the flame remains constant");
- a flame twice as tall is brighter by what eq. 5 predicts: E = ½ k 0.3 m H_c 2 A_f r³ / h with
  m = |v_c| r², computed here from the baked spines, projected as eq. 6 does
  (E / 4π((h/2)² + l²)), against the ratio of the rendered totals;
- colour (§5.1) and light (§5.2): a candle over a white floor lights it warm (R/B >= 1.5) and the
  base of its flame is mostly blue-dominant pixels; the calibrated Light Unit gives the candle about a
  candle's luminous intensity (1 cd = 4π/683 W in Blender's units);
- bad input: a Colour Image that is empty, missing or not RGB, a Light Unit <= 0 give an error
  naming the setting and change nothing.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_flame_look.py
"""

import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (assert_reports_error, image_pixels, native, rmtree, run,  # noqa: E402
                     temp_dir, tree_listing)
from test_flames import FRAMES, flame_scene  # noqa: E402

#: eq. 5's H_c default (MJ/kg) and the candle's source radius in flame_scene (m).
HEAT = 15.0e6
RADIUS = 0.006


def render_linear(scene, path, samples=16):
    """Renders the current frame to an OpenEXR file, Standard view: linear scene values."""
    scene.cycles.samples = samples
    scene.cycles.seed = 1
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.exposure = 0.0
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return image_pixels(path)[..., :3].astype(np.float64)


def eq5_from_spines(spines):
    """E (eq. 5) and h of the attached flame in a spines file, from its control points: v_c the
    mean velocity of its points, h the arc length of the interpolating B-spline through them
    (§4.1's structural curve; its polyline is up to 7 % shorter on a young, bent flame)."""
    n = int(spines["counts"][0])
    assert not spines["separated"][0]
    pts, vel = spines["points"][:n].astype(np.float64), spines["velocities"][:n].astype(np.float64)
    h = float(native().Spine(pts).length)
    speed = float(np.linalg.norm(vel.mean(axis=0)))
    r = RADIUS
    energy = 0.5 * 1.0 * 0.3 * (speed * r * r) * HEAT * 2.0 * (math.pi * r * r) * r ** 3 / h
    return energy, h, pts[0] + 0.5 * (pts[-1] - pts[0])


class FlameLookTest(unittest.TestCase):
    def setUp(self):
        self.tmp = temp_dir("plume_flame_look_")

    def tearDown(self):
        rmtree(self.tmp)

    def steady_candle(self, name, particles_per_pixel=10.0, frames=lambda folder: (FRAMES,)):
        """One candle flame that never breaks (H_max far, f ~ 0: it grows frame by frame), no
        lights, no opacity, baked and rendered against black at each of frames(cache folder):
        [(linear pixels, spines of that frame)], the camera position."""
        folder = os.path.join(self.tmp, name)
        flame_scene(folder)
        scn = bpy.context.scene
        f = scn.plume_flames
        f.height_max, f.breakaway_frequency, f.buoyancy = 1.0, 1e-6, 0.1
        f.particles_per_pixel, f.max_particles = particles_per_pixel, 10_000_000
        f.opacity, f.lights = 0.0, False
        # Far away with a long lens: every part of the flame is seen at nearly the same
        # distance and angle (within 1 %), as eq. 6 assumes of a flame "at distance l".
        scn.camera.location = (0.0, -1.2, 0.1)
        scn.camera.data.lens = 135.0
        scn.render.resolution_x, scn.render.resolution_y = 240, 320
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        out = []
        for frame in frames(folder):
            scn.frame_set(frame)
            pixels = render_linear(scn, os.path.join(self.tmp, f"{name}_{frame}.exr"))
            out.append((pixels, np.load(os.path.join(folder, f"spines_{frame:04d}.npz"))))
        return out, np.array(scn.camera.location)

    def test_brightness_independent_of_particle_count(self):
        (one, _), = self.steady_candle("ppp10", particles_per_pixel=10.0)[0]
        (two, _), = self.steady_candle("ppp20", particles_per_pixel=20.0)[0]
        b1, b2 = one.sum(), two.sum()
        c1, c2 = one.sum(axis=(0, 1)) / b1, two.sum(axis=(0, 1)) / b2
        print(f"  total brightness 10 ppp {b1:.4f}, 20 ppp {b2:.4f} (ratio {b2 / b1:.4f}); "
              f"mean colour {np.round(c1, 4)} / {np.round(c2, 4)}")
        self.assertGreater(b1, 1.0)  # the flame shows (not a black frame)
        self.assertLess(abs(b2 / b1 - 1.0), 0.05)
        self.assertLess(np.abs(c2 / c1 - 1.0).max(), 0.02)

    def test_twice_as_tall_is_brighter_by_equation_5(self):
        # The growing flame at the last frame and at the frame where it was closest to half that
        # length: its length doubles, v_c and its centre change too.
        def half_and_full(folder):
            lengths = [eq5_from_spines(np.load(os.path.join(folder, f"spines_{k:04d}.npz")))[1]
                       for k in range(1, FRAMES + 1)]
            return int(np.argmin(np.abs(np.asarray(lengths) - 0.5 * lengths[-1]))) + 1, FRAMES
        ((short, s1), (tall, s2)), cam = self.steady_candle("growing", frames=half_and_full)
        e1, h1, c1 = eq5_from_spines(s1)
        e2, h2, c2 = eq5_from_spines(s2)
        # eq. 6: the irradiance at the camera, E / 4π((h/2)² + l²)
        predicted = (e2 / (0.25 * h2 ** 2 + np.sum((c2 - cam) ** 2))) / \
                    (e1 / (0.25 * h1 ** 2 + np.sum((c1 - cam) ** 2)))
        rendered = tall.sum() / short.sum()
        print(f"  the bake's own E (lights): {float(s1['light_energy'][0]):.3e} -> "
              f"{float(s2['light_energy'][0]):.3e} W")
        print(f"  h {h1 * 100:.2f} -> {h2 * 100:.2f} cm, E {e1:.3e} -> {e2:.3e} W; rendered "
              f"ratio {rendered:.3f}, eq. 5-6 predict {predicted:.3f}")
        self.assertAlmostEqual(h2 / h1, 2.0, delta=0.25)  # "a flame twice as tall"
        # 5 %: the render's noise and eq. 6's 1 % sampling (the bake's own E and the render
        # agree to 0.1 %).
        self.assertLess(abs(rendered / predicted - 1.0), 0.05)

    def test_candle_colour_and_warm_light(self):
        folder = os.path.join(self.tmp, "white_floor")
        flame_scene(folder)
        scn = bpy.context.scene
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.1, -0.03))
        floor = bpy.context.active_object
        mat = bpy.data.materials.new("White")
        mat.use_nodes = True
        mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (1, 1, 1, 1)
        mat.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
        floor.data.materials.append(mat)
        flame_src = bpy.data.objects["Candle"]
        bpy.context.view_layer.objects.active = flame_src
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        scn.frame_set(FRAMES)
        px = render_linear(scn, os.path.join(self.tmp, "white_floor.exr"), samples=32)
        h, w, _ = px.shape
        # The camera looks along +y at z = 4 cm: the floor is the image's lower part; the flame is
        # the brightest column's pixels.
        floor_rows = px[: h // 4, w // 4: 3 * w // 4]  # row 0 at the bottom (Blender's order)
        r, b = floor_rows[..., 0].mean(), floor_rows[..., 2].mean()
        # The flame alone (the floor hidden): its pixels, and its base, the bottom sixth of its
        # rows (the flame sits on the wick at z = 0 to 1 cm; the lights are inside it).
        floor.hide_render = True
        alone = render_linear(scn, os.path.join(self.tmp, "flame_alone.exr"), samples=32)
        lum = alone @ np.array([0.2126, 0.7152, 0.0722])
        flame = lum > 0.01 * np.percentile(lum, 99.9)
        rows = np.nonzero(flame.any(axis=1))[0]
        base = rows.min() + max(1, (rows.max() - rows.min()) // 6)
        lit = flame[rows.min():base + 1]
        bottom = alone[rows.min():base + 1]
        blue = lit & (bottom[..., 2] > bottom[..., 0])
        print(f"  floor R/B {r / b:.2f} (R {r:.4f}, B {b:.4f}); flame rows {rows.min()}-"
              f"{rows.max()}, blue-dominant pixels at its base {int(blue.sum())} of "
              f"{int(lit.sum())}")
        self.assertGreater(b, 0.0)
        self.assertGreaterEqual(r / b, 1.5)
        # The base is the bottom sixth of the flame's lit rows, so its pixel count follows the
        # flame's height at that frame, which its separated tip (fading and thinning since issue
        # 30) changes: a share is what the colour of the base is. Measured 19 of 35 (54 %,
        # 3.4.1), 26 of 44 (59 %, 4.5) and 43 of 64 (67 %, 5.3.0) blue-dominant pixels (before: 29-30 of ~235 pixels
        # counted on a taller flame); 40 % leaves a quarter of the lower one for noise.
        self.assertGreater(int(blue.sum()), 10)
        self.assertGreater(int(blue.sum()) / max(int(lit.sum()), 1), 0.4)

    def test_light_unit_gives_a_candle_one_candela(self):
        """The calibration of Light Unit's default (flame_settings.LIGHT_UNIT): the candle
        example's flame (r = 5 mm, its heights, noise and buoyancy) lights at 1 cd = 4π/683 W,
        averaged over its attached flame's frames once it stands (from frame 7)."""
        folder = os.path.join(self.tmp, "one_candle")
        src = flame_scene(folder)
        src.plume.flame.radius = 0.005
        scn = bpy.context.scene
        f = scn.plume_flames
        f.frame_end = 24
        for name, value in dict(points=12, height_persistent=0.024, height_intermittent=0.03,
                                height_max=0.042, breakaway_frequency=0.7,
                                lifespan_scale=1.0 / 24.0, buoyancy=0.4, diffusion=2e-6,
                                flow_noise=0.04, kolmogorov=0.0001, spine_noise=0.003).items():
            setattr(f, name, value)
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})
        watts = []
        for frame in range(7, 25):
            d = np.load(os.path.join(folder, f"spines_{frame:04d}.npz"))
            attached = {int(i) for i, sep in zip(d["ids"], d["separated"]) if not sep}
            watts += [e * f.light_unit for i, e in zip(d["light_ids"], d["light_energy"])
                      if int(i) in attached]
        candela = np.asarray(watts) * 683.0 / (4.0 * math.pi)
        print(f"  candle: {len(candela)} attached-flame frames, {candela.mean():.3f} cd "
              f"(min {candela.min():.3f}, max {candela.max():.3f})")
        # "About 1 cd": the constant was set from a mean of 0.98 cd; 15 % allows the spread of
        # the mean over seeds and platforms without letting the unit drift by a stop.
        self.assertAlmostEqual(float(candela.mean()), 1.0, delta=0.15)
        # Every light the scene shows is that flame's or a short piece's: none brighter than 3 cd.
        self.assertLess(float(candela.max()), 3.0)

    def test_bad_colour_image_and_light_unit(self):
        folder = os.path.join(self.tmp, "bad")
        src = flame_scene(folder)
        f = bpy.context.scene.plume_flames
        op = bpy.ops.plume.flames_bake

        def state():
            return (len(bpy.data.objects), len(bpy.data.volumes), len(bpy.data.lights),
                    tuple(tree_listing(self.tmp)))
        fl = src.plume.flame
        fl.color_source = 'IMAGE'
        assert_reports_error(self, op, r"'Candle'.*Colour Image is empty", state)
        img = bpy.data.images.new("Gone", 4, 4)
        img.source = 'FILE'
        img.filepath = os.path.join(self.tmp, "no_such_image.png")
        fl.color_image = img
        assert_reports_error(self, op, r"'Candle'.*Colour Image 'Gone' cannot be read", state)
        grey = os.path.join(self.tmp, "grey.png")
        write_grey_png(grey)
        fl.color_image = bpy.data.images.load(grey)
        assert_reports_error(self, op, r"Colour Image 'grey.png' must be RGB", state)
        fl.color_source = 'PROFILE'
        for bad in (0.0, -1.0):
            f.light_unit = bad
            assert_reports_error(self, op, r"Light Unit \(Physics Properties › Plume › Flames\) "
                                 rf"\(k of eq\. 5\) must be > 0 .*\(got {bad:g};", state)


def write_grey_png(path):
    """A 4 x 4 8-bit greyscale PNG (colour type 0), written without any imaging library."""
    import struct
    import zlib

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + bytes([128] * 4) for _ in range(4))
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 4, 4, 8, 0, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    with open(path, "wb") as fh:
        fh.write(png)


if __name__ == "__main__":
    run(FlameLookTest)
