"""Bad input to plume.bake: a RuntimeError naming the setting or object, no file written, no
object or datablock created, and Blender keeps running (the next test runs).

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_bad_input.py
"""

import contextlib
import io
import os
import sys
import types
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import (add_domain, add_sphere_source, reset_scene, rmtree, run,  # noqa: E402
                     select_only, temp_dir, tree_listing)


class _Layout:
    """Stands for a panel's layout: keeps the labels draw() puts in it ((text, icon)) and the
    alert of the column each is in; every other call does nothing."""

    def __init__(self, labels=None):
        self.labels = [] if labels is None else labels
        self.alert = False

    def __getattr__(self, name):  # prop, operator, separator...
        return lambda *args, **kwargs: None

    def column(self, *args, **kwargs):
        return _Layout(self.labels)

    row = column

    def label(self, text="", icon='NONE', **kwargs):
        self.labels.append((text, icon, self.alert))


class BadInputTest(unittest.TestCase):
    def setUp(self):
        reset_scene()
        self.tmp = temp_dir("plume_bad_")
        self.cache = os.path.join(self.tmp, "cache")
        os.makedirs(self.cache)
        self.source = add_sphere_source()
        self.domain = add_domain(resolution=16, frame_end=3, cache_directory=self.cache + "/")
        select_only(self.domain)

    def tearDown(self):
        rmtree(self.tmp)

    def counts(self):
        d = bpy.data
        return dict(objects=len(d.objects), volumes=len(d.volumes), meshes=len(d.meshes),
                    materials=len(d.materials), collections=len(d.collections),
                    frame=bpy.context.scene.frame_current)

    def assert_bake_fails(self, *words):
        """bake() raises RuntimeError whose message holds every word; nothing changed."""
        before = self.counts()
        files_before = tree_listing(self.tmp)
        with self.assertRaises(RuntimeError) as cm:
            bpy.ops.plume.bake()
        msg = str(cm.exception)
        for w in words:
            self.assertIn(w, msg, f"message should name {w!r}: {msg}")
        self.assertEqual(self.counts(), before, "objects/datablocks changed")
        self.assertEqual(tree_listing(self.tmp), files_before, "files were written")
        self.assertEqual(self.domain.display_type, 'TEXTURED')
        self.assertFalse(self.domain.hide_render)
        return msg

    def test_no_active_object(self):
        select_only(None)
        self.assert_bake_fails("not a Plume domain", "Physics Properties › Plume › Domain")

    def test_active_object_not_a_domain(self):
        select_only(self.source)
        self.assert_bake_fails("not a Plume domain")

    def test_resolution_zero(self):
        self.domain.plume.domain.resolution = 0
        self.assertEqual(self.domain.plume.domain.resolution, 0, "resolution must not be clamped")
        self.assert_bake_fails("Resolution (Physics Properties › Plume › Settings) "
                               "must be in [2, 1024]",
                               "Domain")

    def test_resolution_5000(self):
        self.domain.plume.domain.resolution = 5000
        self.assert_bake_fails("Resolution (Physics Properties › Plume › Settings)", "5000")

    def test_resolution_above_memory(self):
        # 1000^3 cells is inside the per-axis range but far above the memory bound (512^3).
        self.domain.plume.domain.resolution = 1000
        self.assert_bake_fails("Resolution (Physics Properties › Plume › Settings)", "cells")

    def test_negative_vorticity(self):
        self.domain.plume.domain.vorticity = -1.0
        self.assert_bake_fails("Vorticity (ε) (Physics Properties › Plume › Forces) must be in "
                               "[0, 1000]", "-1")

    def test_nan_alpha(self):
        self.domain.plume.domain.alpha = float("nan")
        self.assert_bake_fails("Density Buoyancy (α) (Physics Properties › Plume › Forces)",
                               "finite")

    def test_frame_end_before_start(self):
        d = self.domain.plume.domain
        d.frame_start, d.frame_end = 10, 5
        self.assert_bake_fails("End (Physics Properties › Plume › Settings) must not "
                               "be before Start",
                               "5 < 10")

    def test_cache_folder_not_writable(self):
        # Tests run as root, so chmod would not stop them: put the cache under a regular file.
        blocker = os.path.join(self.tmp, "not_a_folder")
        with open(blocker, "w") as f:
            f.write("x")
        self.domain.plume.domain.cache_directory = os.path.join(blocker, "cache") + "/"
        msg = self.assert_bake_fails("Cache Directory", "not_a_folder",
                                     "(Physics Properties › Plume › Cache) is not writable")
        self.assertFalse(os.path.exists(os.path.join(blocker, "cache")), msg)

    def test_non_manifold_obstacle(self):
        bpy.ops.mesh.primitive_plane_add(size=0.5, location=(0.0, 0.0, 1.0))
        plane = bpy.context.active_object
        plane.name = "FlatWall"
        bpy.ops.plume.role_set(role='OBSTACLE')
        select_only(self.domain)
        self.assert_bake_fails("FlatWall")

    def test_good_input_still_bakes(self):
        # The same scene without the bad setting bakes (so the failures above are the settings').
        bpy.ops.plume.bake()
        self.assertIsNotNone(bpy.data.objects.get("Domain_smoke"))
        self.assertEqual(len([n for n in os.listdir(os.path.join(self.cache, "Domain"))
                              if n.endswith(".vdb")]), 3)

    def bake_printed(self):
        """plume.bake as a script calls it; what it printed, its reports included ("Warning: ..."
        as Blender writes them)."""
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            bpy.ops.plume.bake()
        sys.stdout.write(out.getvalue())
        return out.getvalue()

    def source_panel_labels(self):
        """The labels the Source panel (Physics > Plume > Source) draws for self.source."""
        from plume.ui.panels import PHYSICS_PT_plume_source
        select_only(self.source)
        try:
            panel = types.SimpleNamespace(layout=_Layout())
            PHYSICS_PT_plume_source.draw(panel, bpy.context)
            return panel.layout.labels
        finally:
            select_only(self.domain)

    def test_fuel_without_combustion_warns(self):
        # Issue 30: Fuel with Combustion off burns nothing; the panel and the bake say so, and
        # the bake still runs (a warning, not an error).
        self.source.plume.source.fuel = 1.0
        self.assertFalse(self.domain.plume.domain.combustion)
        labels = self.source_panel_labels()
        alerts = [text for text, _icon, alert in labels if alert]
        self.assertEqual(labels[0][1], 'ERROR', labels)
        self.assertEqual(alerts, ["Fuel 1.0 of 'Source' burns only with Combustion on:",
                                  "select the domain 'Domain' and enable",
                                  "Physics › Plume › Combustion"])
        out = self.bake_printed()
        self.assertIsNotNone(bpy.data.objects.get("Domain_smoke"), "the bake must run")
        self.assertEqual(len([n for n in os.listdir(os.path.join(self.cache, "Domain"))
                              if n.endswith(".vdb")]), 3)
        warnings = [line for line in out.splitlines() if line.startswith("Warning: ")]
        self.assertEqual(len(warnings), 1, out)
        for words in ("'Domain' baked", "Fuel", "'Source'", "Combustion", " ".join(alerts)):
            self.assertIn(words, warnings[0])

    def test_fuel_with_combustion_says_nothing(self):
        self.source.plume.source.fuel = 1.0
        self.domain.plume.domain.combustion = True
        self.assertEqual([lb for lb in self.source_panel_labels() if lb[2]], [])
        out = self.bake_printed()
        self.assertIsNotNone(bpy.data.objects.get("Domain_smoke"))
        self.assertNotIn("Warning: ", out)
        self.assertNotIn("burns only with Combustion", out)
        self.assertIn("Info: Plume: 'Domain' baked", out)


if __name__ == "__main__":
    run(BadInputTest)
