"""The streak-sheet rendering equation in the image ([Smoke Surfaces] §3.4): a flat sheet of
known orientation, carrying a known density map, rendered by Cycles through the add-on's own
sheet material, must give p = d·e^(−|n·v|) (brighter where the sheet is seen edge-on) or, with
the linear contour, p = d·(1 − |n·v|), pixel for pixel - with the map's columns along the
surface's u and its rows along v (a swapped or flipped map fails).

Set-up: a 4 x 4 NURBS net (one cubic Bézier patch) with evenly spaced control points spans
x in [-0.5, 0.5] (u) and z in [0, 1] (v), so u and v are linear in x and z; it is turned by θ
about z and seen by an orthographic camera along +y, so n·v = cos θ on every pixel and screen x
= (u − 0.5)·cos θ. Emission colour white, brightness 1, opacity 1, black world: the pixel's
linear value is p itself (Transparent lets the black through, Emission adds p). The scene uses
the add-on's Fast Sheet Render set-up (16 samples, no light bounces: plume.surfaces_fast_render),
so the equation is checked on the picture that set-up gives; three (and 24) sheets stacked in front
of one another must composite as layers do, 1 − (1 − p)^k, which they only do when every layer is
reached (transparent bounces, none ended early by Russian roulette) and nothing but emission and
transparency shades them.

Run: blender_tests/run.py --blender {3.4,4.5,5.0} test_sheet_shading.py
"""

import math
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import OUT_DIR, image_pixels, reset_scene, rmtree, run, temp_dir  # noqa: E402

SIZE = 64           # render width and height, pixels
ORTHO = 1.2         # camera's orthographic scale: x and z in [-0.6, 0.6] and [-0.1, 1.1]
MAP_W, MAP_H = 17, 9  # density map: columns along u, rows along v
#: Emission and Transparent are evaluated exactly in Cycles; the map is a linear ramp, which
#: linear texture filtering reproduces exactly; left: float rounding and the 0.1 px pixel filter
#: on interior pixels. 2e-3 is half an 8-bit level, far below the 0.1-0.6 a flipped, swapped or
#: wrong-falloff sheet is off by.
TOLERANCE = 2e-3


def density_maps():
    """Frame 1: d grows along u (columns); frame 2: d grows along v (rows). Rows = v."""
    u = np.linspace(0.0, 1.0, MAP_W)[None, :].repeat(MAP_H, 0)
    v = np.linspace(0.0, 1.0, MAP_H)[:, None].repeat(MAP_W, 1)
    return [(0.2 + 0.6 * u).astype(np.float32), (0.2 + 0.6 * v).astype(np.float32)]


class SheetShadingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        reset_scene()
        from plume.build import surfaces as build
        cls.build = build
        cls.tmp = temp_dir("plume_sheet_shading_")
        scene = bpy.context.scene
        coll = bpy.data.collections.new("Sheets")
        scene.collection.children.link(coll)
        bpy.context.view_layer.update()  # the view layer still lists the objects reset_scene removed
        ob = build.surface_object("Sheet", coll, 4, 4, bpy.context.view_layer)
        sp = ob.data.splines[0]
        co = [(-0.5 + u / 3.0, 0.0, v / 3.0, 1.0) for v in range(4) for u in range(4)]
        sp.points.foreach_set("co", np.array(co, dtype=np.float32).ravel())
        sp.order_u = sp.order_v = 4
        sp.use_endpoint_u = sp.use_endpoint_v = True
        sp.resolution_u = sp.resolution_v = 4
        cls.sheet = ob
        cls.first = build.write_sheet_images(cls.tmp, 0, 1, density_maps())
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        scene.collection.objects.link(cam)
        cam.data.type = 'ORTHO'
        cam.data.ortho_scale = ORTHO
        cam.location, cam.rotation_euler = (0.0, -5.0, 0.5), (math.pi / 2, 0.0, 0.0)
        scene.camera = cam
        assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}
        scene.cycles.filter_width = 0.1
        scene.render.resolution_x = scene.render.resolution_y = SIZE
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = 'OPEN_EXR'
        scene.render.image_settings.color_depth = '32'
        scene.view_settings.view_transform = 'Standard'
        if scene.world is None:
            scene.world = bpy.data.worlds.new("World")
        scene.world.use_nodes = True
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def render(self, falloff, theta_deg, frame, layers=1):
        """The rendered red channel (rows bottom-up) of the sheet turned by theta, with the
        material of `falloff` ('EXPONENTIAL' or 'LINEAR') showing density map `frame`."""
        mat = self.build.sheet_material(
            f"Sheet {falloff}", self.first, MAP_W, MAP_H, 1, 2,
            {"opacity": 1.0, "falloff": falloff, "color": (1.0, 1.0, 1.0, 1.0),
             "brightness": 1.0})
        cu = self.sheet.data
        cu.materials.clear()
        cu.materials.append(mat)
        self.sheet.rotation_euler = (0.0, 0.0, math.radians(theta_deg))
        scene = bpy.context.scene
        copies = []
        for k in range(1, layers):  # the same sheet 5 cm nearer the camera per layer
            ob = self.sheet.copy()
            ob.location.y = -0.05 * k
            self.sheet.users_collection[0].objects.link(ob)
            copies.append(ob)
        scene.frame_set(frame)
        path = os.path.join(OUT_DIR, "sheet_shading",
                            f"{falloff}_{theta_deg}_{frame}_{layers}.exr")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        scene.render.filepath = path
        try:
            bpy.ops.render.render(write_still=True)
        finally:
            for ob in copies:
                bpy.data.objects.remove(ob, do_unlink=True)
        return image_pixels(path)[..., 0].astype(np.float64)

    @staticmethod
    def density(theta_deg, frame):
        """d at each pixel centre (NaN off the sheet and within 1.5 pixels of its edge)."""
        c = abs(math.cos(math.radians(theta_deg)))
        px = (np.arange(SIZE) + 0.5) / SIZE * ORTHO - ORTHO / 2  # screen x, camera at x = 0
        pz = (np.arange(SIZE) + 0.5) / SIZE * ORTHO - ORTHO / 2 + 0.5
        u = (px[None, :] / c + 0.5).repeat(SIZE, 0)
        v = pz[:, None].repeat(SIZE, 1)
        d = 0.2 + 0.6 * (u if frame == 1 else v)
        margin_u, margin_v = 1.5 * ORTHO / SIZE / c, 1.5 * ORTHO / SIZE
        inside = (u > margin_u) & (u < 1 - margin_u) & (v > margin_v) & (v < 1 - margin_v)
        return np.where(inside, d, np.nan)

    def expected(self, falloff, theta_deg, frame):
        """p at each pixel centre (NaN off the sheet and near its edge)."""
        c = abs(math.cos(math.radians(theta_deg)))
        term = math.exp(-c) if falloff == 'EXPONENTIAL' else 1.0 - c
        return np.clip(self.density(theta_deg, frame) * term, 0.0, 1.0)

    def check(self, falloff, theta_deg, frame, layers=1):
        got = self.render(falloff, theta_deg, frame, layers)
        want = 1.0 - (1.0 - self.expected(falloff, theta_deg, frame)) ** layers
        inside = np.isfinite(want)
        err = np.abs(got[inside] - want[inside])
        print(f"  {falloff} θ={theta_deg}° map {'u' if frame == 1 else 'v'}, {layers} layer(s): "
              f"{inside.sum()} "
              f"pixels, p {want[inside].min():.3f}..{want[inside].max():.3f}, max error "
              f"{err.max():.2e}")
        self.assertGreater(int(inside.sum()), 200)
        self.assertLess(float(err.max()), TOLERANCE)
        # Off the sheet: the black world, untouched.
        off = np.zeros_like(inside)
        off[:, :2] = off[:, -2:] = True
        self.assertLess(float(np.abs(got[off]).max()), 1e-6)
        return got

    def test_exponential_face_on_and_turned(self):
        face_on = self.check('EXPONENTIAL', 0, 1)
        turned = self.check('EXPONENTIAL', 60, 1)
        # Brighter where seen more edge-on (§3.4): p/d is e^(-1) face on and e^(-1/2) at 60°.
        gains = []
        for got, theta in ((face_on, 0), (turned, 60)):
            d = self.density(theta, 1)
            inside = np.isfinite(d)
            gains.append(float(np.median(got[inside] / d[inside])))
        print(f"  p/d face on {gains[0]:.4f} (e^-1 = {math.exp(-1):.4f}), at 60° {gains[1]:.4f} "
              f"(e^-1/2 = {math.exp(-0.5):.4f})")
        self.assertAlmostEqual(gains[1] / gains[0], math.exp(0.5), delta=0.01)

    def test_map_rows_run_along_v(self):
        self.check('EXPONENTIAL', 30, 2)

    def test_stacked_sheets_composite_as_layers(self):
        self.check('EXPONENTIAL', 0, 1, layers=3)

    def test_deep_folds_composite_without_speckle(self):
        # 24 layers, as where default sheets fold: Cycles' Russian roulette would end some paths
        # deep in the stack (their throughput falls to (1 - p)^k) and speckle the picture at
        # Fast Sheet Render's few samples; with every transparent bounce kept, each pixel is
        # exactly 1 - (1 - p)^24.
        self.check('EXPONENTIAL', 0, 1, layers=24)

    def test_linear_contour(self):
        self.check('LINEAR', 60, 1)
        self.check('LINEAR', 75, 2)


if __name__ == "__main__":
    run(SheetShadingTest)
