"""Scene -> the streak-surface settings ([Smoke Surfaces]): the tracers' settings of a bake and
the density-map and sheet settings of Build Surfaces."""

from ..settings import BakeError, StreakSettings


def streak_settings(d):
    """StreakSettings of a domain's obj.plume.domain (the tracers of a bake, §3.2)."""
    return StreakSettings(enabled=bool(d.streaks), emission_period=int(d.emission_period),
                          max_streaklines=int(d.max_streaklines))


def sheet_settings(d):
    """The density map (§3.4) and sheet look of Build Surfaces, as a dict; BakeError for a
    negative supersampling rate."""
    for name in ("density_k_u", "density_k_v"):
        k = getattr(d, name)
        if k < 0:
            raise BakeError(f"Plume: domain '{d.id_data.name}': {name} must be >= 0 (samples "
                            f"between particles, §3.4; got {k})")
    return {"k_u": int(d.density_k_u), "k_v": int(d.density_k_v), "falloff": d.sheet_falloff,
            "color": tuple(d.sheet_color), "brightness": float(d.sheet_brightness),
            "opacity": float(d.sheet_opacity), "shading": d.sheet_shading}
