"""Rim placement of point sources (addon/point_rim.py): the defaults give a newcomer's wide source
a few sheets that render as smoke, not a solid column.

Pure checks of the ring: a source one cell wide still gets MIN_POINTS distinct point sources, all
inside the cell; on a disc of cells the ring lies RADIUS of the way out, one point source per cell
of its length, each inside a source cell; a flow along x puts the ring across x; a hollow source
keeps every point in a source cell; arcs are consecutive candidate groups of about ARC_POINTS.

The newcomer's sphere scene (a 2 m domain at 40³, a UV sphere of radius 0.25 m as the Source, 60
frames, every default) rendered at frame 60 by Fast Sheet Render, alpha kept (film transparent),
seen from the front: the sheets cover the column, and they are translucent with the paper's contour
(§3.4: p = d e^(−|n·v|), brighter where the sheet turns away): across the middle of the column the
alpha at its centre is below 0.8 and the brightest alpha of the row is above it. The same scene with
Placement Cells (256 random streaklines, all in one sheet folded across the column) is rendered too:
its centre alpha is printed, and must be above the rim's (the picture the rim replaces: a solid
white column).

Run: blender_tests/run.py --blender {3.4,4.5,5.0} test_streak_rim.py
"""

import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (add_domain, add_sphere_source, reset_scene, rmtree, run,  # noqa: E402
                     select_only, temp_dir)

WIDTH, HEIGHT = 120, 160
#: Highest alpha allowed at the centre of the column: two sheet layers face-on at d = 1 give
#: 1 - (1 - e^-1)^2 = 0.60; one sheet folded across the column many times gives about 1.
CENTRE_ALPHA_MAX = 0.8


def grid(cells_ijk, resolution=(40, 40, 40), h=0.05, origin=(-1.0, -1.0, 0.0)):
    """Linear cell indices of (i, j, k) triples and the grid tuple point_rim takes."""
    ijk = np.asarray(cells_ijk, dtype=np.int64).reshape(-1, 3)
    nx, ny = resolution[0], resolution[1]
    return ijk[:, 0] + nx * (ijk[:, 1] + ny * ijk[:, 2]), (resolution, h, origin)


def inside_cells(points, cells, g):
    """Whether each point lies in one of `cells` (linear indices on grid g)."""
    resolution, h, origin = g
    ijk = np.floor((np.asarray(points, np.float64) - origin) / h).astype(np.int64)
    lin = ijk[:, 0] + resolution[0] * (ijk[:, 1] + resolution[1] * ijk[:, 2])
    return np.isin(lin, cells)


class PointRimTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_streak_rim_")

    def tearDown(self):
        rmtree(self.tmp)

    def test_one_cell_source(self):
        from plume import point_rim as pr
        cells, g = grid([(20, 20, 5)])
        up = pr.flow_axis((0, 0, 0), (0, 0, -9.81))
        n = pr.natural_count(cells, g, up)
        self.assertEqual(n, pr.MIN_POINTS)
        points, rows = pr.rim_points(cells, g, up, n)
        self.assertEqual(len(np.unique(points, axis=0)), n)
        self.assertTrue(inside_cells(points, cells, g).all())
        self.assertEqual(rows.tolist(), [0] * n)

    def test_disc_ring_radius_and_count(self):
        from plume import point_rim as pr
        r = 10  # cells
        ijk = [(20 + i, 20 + j, 5) for i in range(-r, r) for j in range(-r, r)
               if (i + 0.5) ** 2 + (j + 0.5) ** 2 <= r * r]
        cells, g = grid(ijk)
        up = pr.flow_axis((0, 0, 0), (0, 0, -9.81))
        n = pr.natural_count(cells, g, up)
        expected = 2 * np.pi * pr.RADIUS * r  # cells of the ring's length
        print(f"  disc of radius {r} cells: {n} point sources (ring length {expected:.1f} cells)")
        self.assertLess(abs(n - expected), 0.1 * expected)
        points, _rows = pr.rim_points(cells, g, up, n)
        self.assertTrue(inside_cells(points, cells, g).all())
        centre = np.array([1.0, 1.0, 0.275]) + np.array([-1.0, -1.0, 0.0])
        radius = np.linalg.norm((points - centre)[:, :2], axis=1) / 0.05
        self.assertTrue(np.all(np.abs(radius - pr.RADIUS * r) <= 1.0), radius)
        self.assertTrue(np.allclose(points[:, 2], 0.275))
        # Evenly around: consecutive points about one cell apart.
        gaps = np.linalg.norm(points - np.roll(points, 1, axis=0), axis=1) / 0.05
        self.assertTrue(np.all((gaps > 0.3) & (gaps < 2.0)), gaps)

    def test_ring_across_the_flow(self):
        from plume import point_rim as pr
        ijk = [(20 + i, 20 + j, 20 + k) for i in range(-4, 4) for j in range(-4, 4)
               for k in range(-4, 4)]
        cells, g = grid(ijk)
        along_x = pr.flow_axis((2.0, 0.0, 0.0), (0, 0, -9.81))
        np.testing.assert_allclose(along_x, [1.0, 0.0, 0.0])
        points, _rows = pr.rim_points(cells, g, along_x, pr.natural_count(cells, g, along_x))
        self.assertLessEqual(np.ptp(points[:, 0]), 1e-6)  # one layer across x
        self.assertGreater(np.ptp(points[:, 1]), 0.2)
        self.assertGreater(np.ptp(points[:, 2]), 0.2)
        self.assertTrue(inside_cells(points, cells, g).all())
        np.testing.assert_allclose(pr.flow_axis((0, 0, 0), (0, 0, 0)), [0.0, 0.0, 1.0])

    def test_hollow_source_points_inside(self):
        from plume import point_rim as pr
        ijk = [(20 + i, 20 + j, 5) for i in range(-8, 8) for j in range(-8, 8)
               if 6.0 <= np.hypot(i + 0.5, j + 0.5) <= 8.0]  # a ring of cells, empty middle
        cells, g = grid(ijk)
        up = pr.flow_axis((0, 0, 0), (0, 0, -9.81))
        points, _rows = pr.rim_points(cells, g, up, pr.natural_count(cells, g, up))
        self.assertTrue(inside_cells(points, cells, g).all())

    def test_arcs(self):
        from plume import point_rim as pr
        self.assertEqual(pr.arc_groups(27, 1, 5).tolist(), [5] * 9 + [6] * 9 + [7] * 9)
        g = pr.arc_groups(27, 4, 0)
        self.assertEqual(np.bincount(g).tolist(), [7, 7, 7, 6])
        self.assertTrue(np.all(np.diff(g) >= 0))
        self.assertEqual(pr.arc_count(8, 1), 1)
        self.assertEqual(pr.arc_count(6, 64), 3)  # two streaklines an arc at least

    def render_alpha(self, placement):
        """Bake + Build Surfaces of the newcomer's sphere scene with `placement`, Fast Sheet
        Render of frame 60 from the front, film transparent: alpha (HEIGHT, WIDTH), rows bottom
        up."""
        reset_scene()
        src = add_sphere_source(radius=0.25, location=(0.0, 0.0, 0.35))
        src.plume.source.point_placement = placement
        cache = os.path.join(self.tmp, placement)
        dom = add_domain(resolution=40, frame_end=60, cache_directory=cache + "/")
        dom.plume.domain.streaks = True
        select_only(dom)
        self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        self.assertEqual(bpy.ops.plume.surfaces_build(), {'FINISHED'})
        surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
        smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
        if smoke is not None:
            smoke.hide_render = True
        scene = bpy.context.scene
        cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scene.collection.objects.link(cam)
        cam.location = (0.0, -4.5, 1.0)
        cam.rotation_euler = (np.pi / 2, 0.0, 0.0)  # looking along +y, image up +z
        scene.camera = cam
        self.assertEqual(bpy.ops.plume.surfaces_fast_render(), {'FINISHED'})
        scene.cycles.device = 'CPU'
        scene.render.film_transparent = True
        scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = 'PNG'
        scene.render.image_settings.color_mode = 'RGBA'
        scene.frame_set(60)
        scene.render.filepath = os.path.join(self.tmp, f"{placement}.png")
        bpy.ops.render.render(write_still=True)
        im = bpy.data.images.load(scene.render.filepath)
        px = np.array(im.pixels[:], dtype=np.float32).reshape(HEIGHT, WIDTH, 4)
        bpy.data.images.remove(im)
        return len(surfaces), px[..., 3]

    @staticmethod
    def column(alpha):
        """(median alpha at the column's centre, median of the brightest alpha of each row, rows
        used) over the rows of the middle third of the image (the column between 0.5 and 1.5 m)
        that hold smoke (alpha > 0.05)."""
        centre, edge, rows = [], [], 0
        for row in alpha[HEIGHT // 3: 2 * HEIGHT // 3]:
            smoke = np.flatnonzero(row > 0.05)
            if len(smoke) < 3:
                continue
            rows += 1
            centre.append(row[(smoke[0] + smoke[-1]) // 2])
            edge.append(row.max())
        return float(np.median(centre)), float(np.median(edge)), rows

    def test_default_scene_renders_translucent_sheets(self):
        count, alpha = self.render_alpha('RIM')
        centre, edge, rows = self.column(alpha)
        cells_count, cells_alpha = self.render_alpha('CELLS')
        cells_centre, cells_edge, _ = self.column(cells_alpha)
        print(f"  Rim (default): {count} surfaces, column centre alpha {centre:.2f}, brightest "
              f"{edge:.2f} ({rows} rows); Cells: {cells_count} surfaces, centre "
              f"{cells_centre:.2f}, brightest {cells_edge:.2f}")
        self.assertGreaterEqual(rows, HEIGHT // 3 - 4)  # the column crosses the whole band
        self.assertTrue(2 <= count <= 8, count)
        self.assertLess(centre, CENTRE_ALPHA_MAX)
        self.assertGreater(edge, centre + 0.05)  # the contour: brighter where n turns from v
        self.assertGreater(cells_centre, centre)


if __name__ == "__main__":
    run(PointRimTest)
