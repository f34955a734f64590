"""Where an artist finds the toon, flow-graph and flames settings, no ``bpy`` (the job's child
imports the modules whose messages use it): each setting's label as its panel shows it and the
panel's path, so a message says "Depth Threshold (γ) (Physics Properties › Plume › Toon Smoke)
must be >= 0" instead of the setting's Python name. The labels are the properties' own names
(properties/); test_messages checks each one against the property and the panel that draws it.
A domain's and a Source's settings are named by setting_paths.py (which reads the properties)."""

import re

TAB = "Physics Properties › Plume"

#: Panel path of each pipeline's settings (ui/panels.py, ui/flame_panels.py).
TOON = TAB + " › Toon Smoke"
FLOWGRAPH = TAB + " › Flow-Graph Fire"
FLAMES = TAB + " › Flames"
FLAMES_NOISE = FLAMES + " › Noise"
FLAME_SOURCE = TAB + " › Flame Source"

#: What to do when the scene has no camera.
ADD_CAMERA = ("add a camera (Add › Camera) and make it the scene's camera (Scene Properties › "
              "Scene › Camera)")

#: Python name -> label, per pipeline (the names the settings and the native core use).
TOON_LABELS = {
    "emission_count": "Emission", "birth_density": "Birth Density (ρ_birth)",
    "birth_spacing": "Birth Spacing (σ)", "death_density": "Death Density (ρ_death)",
    "ramp_density_low": "Ramp Density d0", "ramp_density_high": "Ramp Density d1",
    "size_low": "Size s0", "size_high": "Size s1", "max_size_change": "Max Size Change",
    "max_count": "Max Particles", "integration": "Integration", "cfl": "CFL", "seed": "Seed",
    "stretch_factor": "Stretch (k)", "color_driver": "Colour Driver", "color_low": "Driver Low",
    "color_high": "Driver High", "stencil": "Stencil", "stencil_image": "Stencil Image",
    "depth_threshold": "Depth Threshold (γ)", "ignore_background": "Ignore Background",
    "outline_width": "Outline Width",
}
FLOWGRAPH_LABELS = {
    "block_size": "Block Size (B)", "epsilon": "Threshold (ε)", "auto_weights":
    "Automatic Weights", "alpha": "α (Density)", "beta": "β (Temperature)",
    "min_node_gap": "Min Node Gap", "frame_start": "Start", "frame_end": "End", "seed": "Seed",
    "traversal": "Traversal", "gamma": "γ", "transition_hold": "Transition Hold",
    "transition_hold_frames": "Hold Frames", "fire_source": "Fire Source",
    "start_state": "Start State", "target_state": "Target State", "wind": "Wind",
    "point_preview": "Point Preview", "preview_points": "Preview Points",
    "group_cache": "Group Cache (MB)",
}
FLAMES_LABELS = {
    "frame_start": "Start", "frame_end": "End", "seed": "Seed", "substeps": "Substeps",
    "points": "Control Points (n)", "height_persistent": "Persistent Height (H_p)",
    "height_intermittent": "Intermittent Height (H_i)", "height_max": "Max Height (H_max)",
    "lifespan_scale": "Lifespan Scale (A)", "breakaway_frequency": "Breakaway Frequency (f)",
    "buoyancy": "Buoyancy (β)", "diffusion": "Diffusion",
    "particles_per_pixel": "Particles per Pixel", "max_particles": "Max Particles",
    "voxel_size": "Voxel Size", "temperature_scale": "Temperature (K)", "opacity": "Opacity",
    "heat_of_combustion": "Heat of Combustion (H_c)", "light_unit": "Light Unit",
    "cache_directory": "Cache", "wind_domain": "Wind Domain",
}
#: The Noise sub-panel's settings (ui/flame_panels.NOISE_GROUPS).
FLAMES_NOISE_LABELS = {
    "flow_noise": "Flow Noise", "flow_noise_scale": "Flow Noise Scale (λ)",
    "flow_noise_frequency": "Flow Noise Frequency (ν)",
    "flow_noise_rotation": "Flow Noise Rotation (ω·2r)", "kolmogorov": "Kolmogorov Noise",
    "kolmogorov_scale": "Kolmogorov Scale (Λ)",
    "kolmogorov_frequency": "Kolmogorov Frequency (ν)",
    "kolmogorov_drift": "Kolmogorov Drift (c)", "spine_noise": "Spine Noise",
    "spine_noise_scale": "Spine Noise Scale (Λ)", "spine_noise_frequency":
    "Spine Noise Frequency (ν)", "spine_noise_drift": "Spine Noise Drift (c)",
}
FLAME_SOURCE_LABELS = {
    "profile": "Profile", "profile_curve": "Profile Curve", "color_source": "Colour",
    "color_image": "Colour Image", "flames": "Flames", "radius": "Radius (r)",
    "stops": "Intensity", "intensity": "Density (I)", "temperature": "Temperature (T_p)",
    "spread": "Spread", "activation_map": "Activation Map",
    "spread_temperature": "Flame Temperature (T_f)", "spread_thickness": "Thermal Thickness (L)",
}

#: pipeline -> ((panel path, labels), ...): the property group's settings by panel.
PIPELINES = {
    "toon": ((TOON, TOON_LABELS),),
    "flowgraph": ((FLOWGRAPH, FLOWGRAPH_LABELS),),
    "flames": ((FLAMES, FLAMES_LABELS), (FLAMES_NOISE, FLAMES_NOISE_LABELS)),
    "flame_source": ((FLAME_SOURCE, FLAME_SOURCE_LABELS),),
}

#: Names the native core gives a setting that Blender names otherwise.
NATIVE_ALIASES = {
    "flames": {"kolmogorov_amplitude": "kolmogorov"},
}


def ui(pipeline, name):
    """'Label (Panel path)' of a setting by its Python name."""
    for path, labels in PIPELINES[pipeline]:
        if name in labels:
            return f"{labels[name]} ({path})"
    raise KeyError(f"{pipeline}.{name}")


def label(pipeline, name):
    """The label alone (for a setting the message has already placed)."""
    for _path, labels in PIPELINES[pipeline]:
        if name in labels:
            return labels[name]
    raise KeyError(f"{pipeline}.{name}")


def _known(pipeline):
    names = {n for _path, labels in PIPELINES[pipeline] for n in labels}
    return names | set(NATIVE_ALIASES.get(pipeline, ()))


def in_ui_words(pipeline, text):
    """A native message ("emission_count must be in [1, 1000] (got 0)") with the pipeline's
    settings it names by their Python names named as the artist sees them: the first with its
    panel, the others by their labels. A one-word name ("seed") only as the message's subject,
    its first word: elsewhere it is an English word. The core's own symbol after a name
    ("points (n)") goes: the label carries the paper's."""
    names = sorted(_known(pipeline), key=len, reverse=True)
    pattern = re.compile(r"(?<![\w.])(" + "|".join(map(re.escape, names))
                         + r")(?![\w])( \([^()\s]{1,8}\))?")
    placed = []

    def word(m):
        name = NATIVE_ALIASES.get(pipeline, {}).get(m.group(1), m.group(1))
        if "_" not in m.group(1) and m.start() > 0:
            return m.group(0)
        if placed:
            return label(pipeline, name)
        placed.append(name)
        return ui(pipeline, name)
    return pattern.sub(word, text)
