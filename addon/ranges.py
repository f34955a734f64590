"""The accepted range of every setting that the add-on validates itself, no ``bpy``: one table
that the properties (their limits and descriptions) and the validation (its bounds and messages)
both read, so a bound is written once. Ranges are inclusive (lo, hi), keyed by the property's
name (with its pipeline where two pipelines use one name). Bounds the native core checks itself
come from it (``_native.setting_ranges()``, the core's one definition), not written again here."""

from .native import _native


def _native_range(name):
    """(lo, hi) of a setting the core checks, as it defines it, whole numbers."""
    lo, hi = _native.setting_ranges()[name]
    return int(lo), int(hi)


RANGES = {
    # a domain's grid bake (obj.plume.domain)
    "resolution": _native_range("resolution"),  # cells along the longest axis
    "emission_period": _native_range("emission_period"),
    #: 0 (keep every point source) or at least the 2 a surface needs
    "max_streaklines": (0, 1000000),
    "pathline_nodes_per_frame": _native_range("pathline_nodes_per_frame"),
    # a Source (obj.plume.source)
    "point_sources": _native_range("point_sources"),  # per source cell
    "candidate_split": (1, 64),  # §3.3
    # structural flames (scene.plume_flames, obj.plume.flame)
    "flames.points": _native_range("flames.points"),
    "flames.flames_per_source": (1, 1024),
    "flames.substeps": (1, 64),
    # flow-graph fire synthesis (obj.plume.domain.flowgraph)
    "flowgraph.preview_points": (100, 1000000),
    "flowgraph.group_cache": (0, 65536),  # MB
}


def bounds(name):
    """(lo, hi) of a setting."""
    return RANGES[name]


def text(name):
    """"[lo, hi]" of a setting, as descriptions and error messages show it."""
    lo, hi = RANGES[name]
    return f"[{lo}, {hi}]"
