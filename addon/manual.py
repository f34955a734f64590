"""Where Plume's help opens: the manual that ships inside the add-on (`manual/`, HTML pages made
from the repository's README and its five manuals when the zip is packaged, see
blender_tests/install_zip/plume_manual.py), so it opens offline and matches the installed
version. Three ways in: right click › Online Manual (F1) on any Plume button or setting, through
Blender's manual map (bpy.utils.register_manual_map; registration.py registers `manual_map`); the
Help button (?) in the header of Plume's panels (operator plume.manual_open); and Edit ›
Preferences › Add-ons › Plume, whose preferences list the manuals. No ``bpy`` here."""

import os
import pathlib

#: The manual's folder inside the installed add-on.
MANUAL_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "manual")

INDEX = "index.html"
SMOKE = "smoke.html"
STREAKS = "streak_surfaces.html"
TOON = "toon.html"
FLOWGRAPH = "flowgraph_fire.html"
FLAMES = "flames.html"
#: (page, title) of the manuals, as the preferences and the panels' help list them.
MANUALS = ((INDEX, "Plume: install, first effect"), (SMOKE, "Smoke and fire"),
           (STREAKS, "Streak surfaces"), (TOON, "Toon smoke"),
           (FLOWGRAPH, "Flow-graph fire"), (FLAMES, "Structural flames"))

# Sections (ids of a heading, or of a paragraph's bold lead) that help opens directly; each must
# exist in the built manual (test_help.py checks every one).
SMOKE_USE = SMOKE + "#using-plume-in-blender"
SMOKE_CACHE = SMOKE + "#cache-folder"
SMOKE_ADAPTIVE = SMOKE + "#adaptive-domain"
STREAKS_USE = STREAKS + "#in-blender"
STREAKS_EDITS = STREAKS + "#recipe-smoke-sheets-and-a-hand-edit"
STREAKS_MANTAFLOW = STREAKS + "#from-a-mantaflow-bake"
STREAKS_SOURCES = STREAKS + "#animated-sources"
TOON_OUTLINE = TOON + "#outline-width"
FARM = SMOKE + "#farm"

# (pattern, page): Blender matches lower-case RNA ids ("bpy.ops.plume.bake",
# "bpy.types.plumedomainsettings.resolution") with fnmatch, the first match wins.
_DOMAIN = "bpy.types.plumedomainsettings."
PAGES = (
    ("bpy.ops.plume.surface_edits*", STREAKS_EDITS),
    ("bpy.ops.plume.surface*", STREAKS_USE),  # surfaces_build, _bake_keyframes, _export_mesh
    ("bpy.ops.plume.toon_*", TOON),
    ("bpy.ops.plume.flowgraph_*", FLOWGRAPH),
    ("bpy.ops.plume.fire_synthesize*", FLOWGRAPH),
    ("bpy.ops.plume.flame*", FLAMES),  # flames_* and flame_preset
    ("bpy.ops.plume.cache_free", SMOKE_CACHE),
    ("bpy.ops.plume.manual_open", INDEX),
    ("bpy.ops.plume.farm_*", FARM),
    ("bpy.ops.plume.*", SMOKE_USE),  # role_set, bake
    (_DOMAIN + "mantaflow_domain*", STREAKS_MANTAFLOW),
    (_DOMAIN + "motion_source*", STREAKS_MANTAFLOW),
    (_DOMAIN + "streak*", STREAKS_USE),
    (_DOMAIN + "emission_period*", STREAKS_USE),
    (_DOMAIN + "max_streaklines*", STREAKS_USE),
    (_DOMAIN + "density_k_*", STREAKS_USE),
    (_DOMAIN + "sheet_*", STREAKS_USE),
    (_DOMAIN + "surfaces_*", STREAKS_USE),
    (_DOMAIN + "pathline*", FLOWGRAPH),
    (_DOMAIN + "flame_smoke*", FLAMES),
    (_DOMAIN + "cache_*", SMOKE_CACHE),
    (_DOMAIN + "adaptive*", SMOKE_ADAPTIVE),
    (_DOMAIN + "*", SMOKE_USE),
    ("bpy.types.plumesourcesettings.point_*", STREAKS_SOURCES),
    ("bpy.types.plumesourcesettings.candidate_*", STREAKS_SOURCES),
    ("bpy.types.plumesourcesettings.emit_particles*", STREAKS_SOURCES),
    ("bpy.types.plumesourcesettings.*", SMOKE_USE),
    ("bpy.types.plumeobstaclesettings.*", SMOKE_USE),
    ("bpy.types.plumeobjectsettings.*", SMOKE_USE),
    ("bpy.types.plumetoonsettings.outline_*", TOON_OUTLINE),
    ("bpy.types.plumetoonsettings.*", TOON),
    ("bpy.types.plumeflowgraphsettings.*", FLOWGRAPH),
    ("bpy.types.plumeflamesourcesettings.*", FLAMES),
    ("bpy.types.plumeflamessettings.*", FLAMES),
    ("bpy.types.plumefarmsettings.*", FARM),
)


def prefix():
    """The manual folder's file:// URL, ending in "/" (Blender appends a page to it)."""
    return pathlib.Path(MANUAL_DIR).as_uri() + "/"


def manual_map():
    """Blender's manual hook: (URL prefix, ((pattern, page), ...))."""
    return prefix(), PAGES


def url(page):
    """The URL of a manual page ("toon.html", "smoke.html#cache-folder")."""
    return prefix() + page


def installed():
    """Whether this copy of Plume carries its manual (a zip install does; a bare source copy
    without `manual/` does not)."""
    return os.path.isfile(os.path.join(MANUAL_DIR, INDEX))


def page_of(rna_id):
    """The manual URL of a lower- or mixed-case RNA id, as Blender resolves it; None for none."""
    from fnmatch import fnmatchcase
    rna_id = rna_id.lower()
    for pattern, page in PAGES:
        if fnmatchcase(rna_id, pattern):
            return url(page)
    return None
