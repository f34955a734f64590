"""Where an artist finds a domain setting that a message names by its Python name: the core and
the bake's checks say "vorticity must be in [0, 1000]", the report says "Vorticity (Physics
Properties › Plume › Forces) must be in [0, 1000]". The label is the property's own name; the
panel is the one that draws it (ui/panels.py; test_roles_ui draws them and checks this table)."""

import re

from .properties import PlumeDomainSettings

TAB = "Physics Properties › Plume"

#: The domain's panels (ui/panels.py) and the settings each draws.
DOMAIN_PANELS = (
    ("Settings", ("resolution", "frame_start", "frame_end", "time_scale", "substeps", "use_cfl",
                  "cfl", "seed", "threads", "adaptive_domain", "adaptive_margin",
                  "adaptive_threshold")),
    ("Forces", ("alpha", "beta", "buoyancy_units", "ambient_temperature", "gravity", "vorticity",
                "wind", "wind_strength", "turbulence", "turbulence_scale", "turbulence_rate",
                "density_dissipation")),
    ("Advection", ("advection", "interpolation", "linear_velocity", "trace", "conserve_mass")),
    ("Pressure", ("pressure_tolerance", "max_pressure_iterations")),
    ("Combustion", ("combustion", "burn_rate", "soot_yield", "heat_yield", "conductivity",
                    "cooling_rate", "max_temperature", "expansion", "flame_vorticity",
                    "pathlines", "pathline_nodes_per_frame", "pathline_lifetime",
                    "pathline_float16")),
    ("Flame Smoke", ("flame_smoke", "flame_smoke_yield", "flame_smoke_point",
                     "flame_smoke_temperature")),
    ("Streak Surfaces", ("streaks", "emission_period", "max_streaklines", "streak_threshold",
                         "density_k_u", "density_k_v", "sheet_falloff", "sheet_shading",
                         "sheet_color", "sheet_brightness", "sheet_opacity")),
    ("Cache", ("motion_source", "mantaflow_domain", "cache_directory", "velocity_everywhere")),
)

# "domain 'Smoke': vorticity must ...": the setting the message is about follows the domain.
_SUBJECT = re.compile(r"(domain '[^']*': )([a-z][a-z0-9_]*)\b")
_SNAKE = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")


def domain_setting(name):
    """'Label (Physics Properties › Plume › Panel)' of a domain setting's Python name; None when
    no domain panel draws one of that name."""
    for panel, names in DOMAIN_PANELS:
        if name in names:
            label = PlumeDomainSettings.bl_rna.properties[name].name
            return f"{label} ({TAB} › {panel})"
    return None


def _label(m):
    name = m.group(0)
    if any(name in names for _panel, names in DOMAIN_PANELS):
        return PlumeDomainSettings.bl_rna.properties[name].name
    return name


def in_ui_words(message):
    """`message` with the domain setting it is about named as its panel shows it, the panel
    with it, and the other domain settings it names (snake_case ones) by their labels."""
    m = _SUBJECT.search(message)
    where = None if m is None else domain_setting(m.group(2))
    if where is None:
        return message
    return message[:m.start(2)] + where + _SNAKE.sub(_label, message[m.end():])
