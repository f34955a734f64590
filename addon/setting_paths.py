"""Where an artist finds a domain's or a Source's setting that a message names by its Python
name: the core and the bake's checks say "vorticity must be in [0, 1000]", the report says
"Vorticity (ε) (Physics Properties › Plume › Forces) must be in [0, 1000]". The label is the
property's own name; the panel is the one that draws it (ui/panels.py; test_roles_ui draws the
panels and checks these tables)."""

import re

from .properties import PlumeDomainSettings, PlumeSourceSettings

from .ui_words import TAB  # one definition of the tab's path

#: The domain's panels (ui/panels.py) and the settings each draws (the messages' own names).
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

#: The Source panel's settings.
SOURCE_PANELS = (
    ("Source", ("density", "temperature", "smoke_noise", "smoke_noise_scale", "smoke_noise_rate",
                "fuel", "fuel_noise", "fuel_noise_scale", "fuel_noise_rate", "velocity",
                "motion_factor", "emit_particles", "point_source_mesh", "point_placement",
                "point_sources", "candidate_group", "candidate_split")),
)

#: What a message names ("domain 'Smoke': ...") -> its settings' class and panels.
OWNERS = {"domain": (PlumeDomainSettings, DOMAIN_PANELS),
          "source": (PlumeSourceSettings, SOURCE_PANELS)}

# "domain 'Smoke': vorticity must ...": the setting the message is about follows its owner.
_SUBJECT = re.compile(r"\b(domain|source) '[^']*': ([a-z][a-z0-9_]*)\b")
_SNAKE = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")
_SYMBOL = re.compile(r" \(([^()\s]{1,8})\)")


def setting_path(name, owner="domain"):
    """'Label (Physics Properties › Plume › Panel)' of a domain's (or a Source's, owner
    "source") setting by its Python name; None when no panel of the owner draws one."""
    cls, panels = OWNERS[owner]
    for panel, names in panels:
        if name in names:
            return f"{cls.bl_rna.properties[name].name} ({TAB} › {panel})"
    return None


def in_ui_words(message):
    """`message` with the setting it is about named as its panel shows it, the panel with it,
    and the owner's other settings it names (snake_case ones) by their labels."""
    m = _SUBJECT.search(message)
    where = None if m is None else setting_path(m.group(2), m.group(1))
    if where is None:
        return message
    cls, panels = OWNERS[m.group(1)]

    def label(word):
        name = word.group(0)
        drawn = any(name in names for _panel, names in panels)
        return cls.bl_rna.properties[name].name if drawn else name
    rest = message[m.end():]
    symbol = _SYMBOL.match(rest)  # "pathline_lifetime (t_max)": the label carries the symbol
    if symbol is not None and f"({symbol.group(1)})" in where:
        rest = rest[symbol.end():]
    return message[:m.start(2)] + where + _SNAKE.sub(label, rest)
