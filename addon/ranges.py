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


def _native_float_range(name):
    """(lo, hi) of a real-valued setting the core checks, as it defines it."""
    lo, hi = _native.setting_ranges()[name]
    return float(lo), float(hi)


RANGES = {
    # a domain's grid bake (obj.plume.domain)
    "resolution": _native_range("resolution"),  # cells along the longest axis
    "adaptive_margin": _native_range("adaptive_margin"),  # cells
    "adaptive_threshold": _native_float_range("adaptive_threshold"),
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
    # the noises of structural flames (§4.2 spine, §4.5 render particles), bounds of the core
    **{f"flames.{name}": _native_float_range(f"flames.{name}") for name in (
        "flow_noise", "flow_noise_scale", "flow_noise_frequency", "flow_noise_rotation",
        "kolmogorov", "kolmogorov_scale", "kolmogorov_frequency", "kolmogorov_drift",
        "spine_noise", "spine_noise_scale", "spine_noise_frequency", "spine_noise_drift")},
    # flow-graph fire synthesis (obj.plume.domain.flowgraph)
    "flowgraph.preview_points": (100, 1000000),
    "flowgraph.group_cache": (0, 65536),  # MB
}


def bounds(name):
    """(lo, hi) of a setting."""
    return RANGES[name]


def text(name, open_low=False):
    """"[lo, hi]" of a setting, as descriptions and error messages show it; "(lo, hi]" when lo
    itself is excluded (a scale > 0)."""
    lo, hi = (f"{v:g}" if isinstance(v, float) else str(v) for v in RANGES[name])
    return f"{'(' if open_low else '['}{lo}, {hi}]"
