"""Help from inside Blender opens Plume's manual, which ships inside the add-on (`manual/`,
HTML made from the repository's manuals when the zip is packaged), so it opens offline and
matches the installed version:
- right click › Online Manual (F1) on any Plume button or setting opens its pipeline's manual at
  its section, through Blender's own lookup (the manual map);
- the Help button (?) of Plume's panels and the manuals listed in Edit › Preferences › Add-ons ›
  Plume open their page (plume.manual_open);
- every page, section, link and picture the help and the pages point to exists in the installed
  manual; a copy without its manual says how to get it.

Run: python3 blender_tests/run.py --blender 3.4 test_help.py
"""

import html
import os
import re
import sys
import tempfile
import unittest
from urllib.parse import unquote, urlparse

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import addon_utils  # noqa: E402
import bpy  # noqa: E402

from helpers import enable_addon, run  # noqa: E402

_ID = re.compile(r'\bid="([^"]+)"')
_LOCAL = re.compile(r'<(?:a|img)\b[^>]*?\b(?:href|src)="([^"]+)"')


def plume():
    enable_addon()
    from plume import manual, operators, properties, ui
    from plume.operators import manual_open
    return manual, operators, properties, ui, manual_open


def file_and_section(url):
    """(path, section id or "") of a file:// URL."""
    u = urlparse(url)
    assert u.scheme == "file", url
    return unquote(u.path), unquote(u.fragment)


def ids_of(path):
    with open(path, encoding="utf-8") as f:
        return set(_ID.findall(f.read()))


class InstalledManualTest(unittest.TestCase):
    """The manual is in the installed add-on, and nothing in it points nowhere."""

    def setUp(self):
        self.manual = plume()[0]

    def test_manual_is_installed(self):
        self.assertTrue(self.manual.installed(), self.manual.MANUAL_DIR)
        pages = sorted(f for f in os.listdir(self.manual.MANUAL_DIR) if f.endswith(".html"))
        print(f"  {self.manual.MANUAL_DIR}: {', '.join(pages)}")
        self.assertEqual(pages, sorted(page for page, _title in self.manual.MANUALS))

    def test_every_link_and_picture_of_the_pages_exists(self):
        root, checked, bad = self.manual.MANUAL_DIR, 0, []
        for page, _title in self.manual.MANUALS:
            with open(os.path.join(root, page), encoding="utf-8") as f:
                text = f.read()
            for target in map(html.unescape, _LOCAL.findall(text)):
                if re.match(r"^[a-z]+:", target):
                    continue  # a web address (none is needed to read the manual)
                path, _, section = target.partition("#")
                path = os.path.join(root, path) if path else os.path.join(root, page)
                checked += 1
                if not os.path.isfile(path) or (section and section not in ids_of(path)):
                    bad.append(f"{page} → {target}")
        print(f"  {checked} links and pictures checked")
        self.assertGreater(checked, 40)  # the six pages link each other and show 40 pictures
        self.assertEqual(bad, [])

    def test_every_section_help_opens_exists(self):
        bad = []
        for _pattern, page in self.manual.PAGES:
            path, section = file_and_section(self.manual.url(page))
            if not os.path.isfile(path) or (section and section not in ids_of(path)):
                bad.append(page)
        self.assertEqual(bad, [])


class OnlineManualTest(unittest.TestCase):
    """Blender's own lookup (the Online Manual operator's) finds the Plume manual section of
    each operator and setting."""

    def setUp(self):
        self.manual, self.operators, self.properties, _, _ = plume()
        from bl_operators.wm import WM_OT_doc_view_manual
        self.lookup = WM_OT_doc_view_manual._lookup_rna_url

    def url(self, rna_id):
        return self.lookup(rna_id, verbose=False)

    def test_operators_and_settings_open_their_section(self):
        m = self.manual
        for rna_id, page in (("bpy.ops.plume.bake", m.SMOKE_USE),
                             ("bpy.ops.plume.role_set", m.SMOKE_USE),
                             ("bpy.ops.plume.cache_free", m.SMOKE_CACHE),
                             ("bpy.ops.plume.surfaces_build", m.STREAKS_USE),
                             ("bpy.ops.plume.surface_edits_store", m.STREAKS_EDITS),
                             ("bpy.ops.plume.toon_build", m.TOON),
                             ("bpy.ops.plume.flowgraph_build", m.FLOWGRAPH),
                             ("bpy.ops.plume.fire_synthesize", m.FLOWGRAPH),
                             ("bpy.ops.plume.flames_bake", m.FLAMES),
                             ("bpy.ops.plume.flame_preset", m.FLAMES),
                             ("bpy.types.PlumeDomainSettings.resolution", m.SMOKE_USE),
                             ("bpy.types.PlumeDomainSettings.cache_directory", m.SMOKE_CACHE),
                             ("bpy.types.PlumeDomainSettings.streak_threshold", m.STREAKS_USE),
                             ("bpy.types.PlumeDomainSettings.mantaflow_domain",
                              m.STREAKS_MANTAFLOW),
                             ("bpy.types.PlumeDomainSettings.pathlines", m.FLOWGRAPH),
                             ("bpy.types.PlumeDomainSettings.flame_smoke_point", m.FLAMES),
                             ("bpy.types.PlumeSourceSettings.density", m.SMOKE_USE),
                             ("bpy.types.PlumeSourceSettings.point_sources", m.STREAKS_SOURCES),
                             ("bpy.types.PlumeToonSettings.depth_threshold", m.TOON),
                             ("bpy.types.PlumeToonSettings.outline_width", m.TOON_OUTLINE),
                             ("bpy.types.PlumeFlowGraphSettings.gamma", m.FLOWGRAPH),
                             ("bpy.types.PlumeFlamesSettings.opacity", m.FLAMES)):
            self.assertEqual(self.url(rna_id), m.url(page), rna_id)

    def test_every_operator_and_setting_has_a_section(self):
        groups = [c for c in self.properties.classes if issubclass(c, bpy.types.PropertyGroup)]
        ids = [f"bpy.ops.{cls.bl_idname}" for cls in self.operators.classes]
        ids += [f"bpy.types.{cls.__name__}.{prop.identifier}" for cls in groups
                for prop in cls.bl_rna.properties if prop.identifier != "rna_type"]
        missing = [i for i in ids if not (self.url(i) or "").startswith(self.manual.prefix())]
        print(f"  {len(ids)} operators and settings")
        self.assertGreater(len(ids), 50)
        self.assertEqual(missing, [])

    def test_unregister_removes_the_map(self):
        hook = self.manual.manual_map
        self.assertIn(hook, bpy.utils._manual_map)
        addon_utils.disable("plume", default_set=True)
        try:
            self.assertNotIn(hook, bpy.utils._manual_map)
        finally:
            enable_addon()


class HelpButtonTest(unittest.TestCase):
    """The panels' Help buttons and the preferences' manuals open their pages."""

    def setUp(self):
        self.manual, _, _, self.ui, self.manual_open = plume()
        self.opened = []
        self.real_open = self.manual_open.open_in_browser
        self.manual_open.open_in_browser = self.opened.append

    def tearDown(self):
        self.manual_open.open_in_browser = self.real_open

    def test_help_button_opens_the_page(self):
        m = self.manual
        self.assertEqual(bpy.ops.plume.manual_open(page=m.TOON_OUTLINE), {'FINISHED'})
        self.assertEqual(self.opened, [m.url(m.TOON_OUTLINE)])
        path, section = file_and_section(self.opened[0])
        self.assertIn(section, ids_of(path))

    def test_panels_with_help_open_existing_sections(self):
        pages = {cls.__name__: cls.manual_page for cls in self.ui.classes
                 if getattr(cls, "manual_page", None)}
        print("  panels with a Help button: " + ", ".join(sorted(pages)))
        self.assertTrue({"PHYSICS_PT_plume_streaks", "PHYSICS_PT_plume_toon",
                         "PHYSICS_PT_plume_flowgraph", "PHYSICS_PT_plume_cache"} <= set(pages))
        for name, page in pages.items():
            path, section = file_and_section(self.manual.url(page))
            self.assertIn(section or "", ids_of(path) | {""}, name)

    def test_preferences_list_every_manual(self):
        prefs = bpy.context.preferences.addons["plume"].preferences
        self.assertIsNotNone(prefs)
        for page, _title in self.manual.MANUALS:
            self.assertTrue(os.path.isfile(file_and_section(self.manual.url(page))[0]), page)

    def test_a_copy_without_its_manual_says_how_to_get_it(self):
        m, real = self.manual, self.manual.MANUAL_DIR
        with tempfile.TemporaryDirectory() as empty:
            m.MANUAL_DIR = empty
            try:
                with self.assertRaises(RuntimeError) as cm:
                    bpy.ops.plume.manual_open(page=m.INDEX)
            finally:
                m.MANUAL_DIR = real
        self.assertIn("Edit › Preferences › Get Extensions › Install from Disk", str(cm.exception))
        self.assertIn("Edit › Preferences › Add-ons › Install", str(cm.exception))
        self.assertEqual(self.opened, [])


if __name__ == "__main__":
    run(InstalledManualTest, OnlineManualTest, HelpButtonTest)
