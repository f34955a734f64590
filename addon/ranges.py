"""The accepted range of every setting that the add-on validates itself, no ``bpy``: one table
that the properties (their limits and descriptions) and the validation (its bounds and messages)
both read, so a bound is written once. Ranges are inclusive (lo, hi), keyed by the property's
name (with its pipeline where two pipelines use one name)."""

RANGES = {
    # a domain's grid bake (obj.plume.domain)
    "resolution": (2, 1024),
    "emission_period": (1, 100000),  # the native StreakParams bound
    #: 0 (keep every point source) or at least the 2 a surface needs
    "max_streaklines": (0, 1000000),
    "pathline_nodes_per_frame": (1, 64),  # the native PathlineParams bound
    # a Source (obj.plume.source)
    "point_sources": (1, 10000),  # the native random_points_in_cells bound
    "candidate_split": (1, 64),  # §3.3
    # structural flames (scene.plume_flames, obj.plume.flame)
    "flames.points": (2, 256),
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
