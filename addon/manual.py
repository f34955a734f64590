"""Where Plume's help opens: the manual of each pipeline, `examples/<pipeline>/README.md` in the
repository. bl_info's doc_url (Blender 3.4) and the manifest's website (4.2+) open the README;
a right click › Online Manual (F1) on any Plume button or setting opens the manual of its
pipeline through Blender's manual map (bpy.utils.register_manual_map). No ``bpy`` here:
manual_map() is the hook, registration.py registers it."""

# The repository's public address: the one place to change when it moves (with the two literal
# copies in __init__.py's bl_info and blender_manifest.toml, which test_tooltips compares). The
# README and the manuals are read from its main branch. A placeholder until the project
# publishes one: no public address exists yet, so these links do not open.
REPOSITORY_URL = "https://github.com/plume-developers/plume"
DOCS_URL = REPOSITORY_URL + "/blob/main/"

SMOKE = "examples/smoke/README.md"
STREAKS = "examples/streak_surfaces/README.md"
TOON = "examples/toon/README.md"
FLOWGRAPH = "examples/flowgraph_fire/README.md"
FLAMES = "examples/flames/README.md"
README = "README.md#readme"

# (pattern, page): Blender matches lower-case RNA ids ("bpy.ops.plume.bake",
# "bpy.types.plumedomainsettings.resolution") with fnmatch, the first match wins.
_DOMAIN = "bpy.types.plumedomainsettings."
PAGES = (
    ("bpy.ops.plume.surface*", STREAKS),  # surfaces_* and surface_edits_*
    ("bpy.ops.plume.toon_*", TOON),
    ("bpy.ops.plume.flowgraph_*", FLOWGRAPH),
    ("bpy.ops.plume.fire_synthesize*", FLOWGRAPH),
    ("bpy.ops.plume.flame*", FLAMES),  # flames_* and flame_preset
    ("bpy.ops.plume.*", SMOKE),  # role_set, bake, cache_free
    (_DOMAIN + "streak*", STREAKS),
    (_DOMAIN + "emission_period*", STREAKS),
    (_DOMAIN + "max_streaklines*", STREAKS),
    (_DOMAIN + "motion_source*", STREAKS),
    (_DOMAIN + "mantaflow_domain*", STREAKS),
    (_DOMAIN + "density_k_*", STREAKS),
    (_DOMAIN + "sheet_*", STREAKS),
    (_DOMAIN + "surfaces_*", STREAKS),
    (_DOMAIN + "pathline*", FLOWGRAPH),
    (_DOMAIN + "flame_smoke*", FLAMES),
    (_DOMAIN + "*", SMOKE),
    ("bpy.types.plumesourcesettings.point_*", STREAKS),
    ("bpy.types.plumesourcesettings.candidate_*", STREAKS),
    ("bpy.types.plumesourcesettings.emit_particles*", STREAKS),
    ("bpy.types.plumesourcesettings.*", SMOKE),
    ("bpy.types.plumeobstaclesettings.*", SMOKE),
    ("bpy.types.plumeobjectsettings.*", SMOKE),
    ("bpy.types.plumetoonsettings.*", TOON),
    ("bpy.types.plumeflowgraphsettings.*", FLOWGRAPH),
    ("bpy.types.plumeflamesourcesettings.*", FLAMES),
    ("bpy.types.plumeflamessettings.*", FLAMES),
)


def manual_map():
    """Blender's manual hook: (URL prefix, ((pattern, page), ...))."""
    return DOCS_URL, PAGES


def page_of(rna_id):
    """The manual URL of a lower- or mixed-case RNA id, as Blender resolves it; None for none."""
    from fnmatch import fnmatchcase
    rna_id = rna_id.lower()
    for pattern, page in PAGES:
        if fnmatchcase(rna_id, pattern):
            return DOCS_URL + page
    return None
