"""Flame Source presets (no ``bpy``): Candle, Torch, Campfire and Dragon Breath, each the settings
of its example scene (examples/flames/): the source's own (profile, flames, radius r, Intensity
in stops) and the scene's Flames settings they need (heights H_p, H_i, H_max, breakaway,
lifespan A, buoyancy β, noise, voxel size, temperature).

Intensity: eq. 5 grows as r⁷/h, so with one Light Unit a torch is ~13 stops brighter than a
candle and a dragon's breath ~26. Each preset's Intensity brings its flames' visible brightness
back to the candle's (measured: the 90th percentile of the flame pixels' linear brightness in a
render of its example framing), so a candle and a campfire share one exposure, and at Blender's
default exposure the body of each reads orange-yellow with a small white core.

The scene settings are shared by every Flame Source of the scene: choosing a preset on one source
sets them for all (the preset's report says so)."""

#: name -> (label, description, source settings, scene settings)
PRESETS = {
    'CANDLE': (
        "Candle", "A steady candle flame on a wick: r 5 mm, flames about 4 cm tall, a blue base",
        dict(profile='CANDLE', flames=1, radius=0.005, stops=0.0, color_source='PROFILE'),
        dict(points=12, height_persistent=0.024, height_intermittent=0.03, height_max=0.042,
             breakaway_frequency=0.7, lifespan_scale=1.0 / 24.0, buoyancy=0.4, diffusion=2e-6,
             flow_noise=0.04, kolmogorov=0.0001, spine_noise=0.003, voxel_size=0.001,
             temperature_scale=1500.0, merging=True, wind=(0.0, 0.0, 0.0))),
    'TORCH': (
        "Torch", "Five tongues on a pitch-soaked torch head: r 2 cm, flames up to 30 cm",
        dict(profile='TORCH', flames=5, radius=0.02, stops=-10.0, color_source='PROFILE'),
        dict(points=14, height_persistent=0.08, height_intermittent=0.16, height_max=0.3,
             breakaway_frequency=0.0, lifespan_scale=0.3, buoyancy=0.5, diffusion=1e-4,
             flow_noise=0.15, kolmogorov=0.006, spine_noise=0.04, voxel_size=0.004,
             temperature_scale=1700.0, merging=True, wind=(0.0, 0.0, 0.0))),
    'CAMPFIRE': (
        "Campfire", "Broad flames along burning logs: r 4 cm, four flames per log, up to 65 cm",
        dict(profile='CAMPFIRE', flames=4, radius=0.04, stops=-13.0, color_source='PROFILE'),
        dict(points=14, height_persistent=0.2, height_intermittent=0.4, height_max=0.65,
             breakaway_frequency=0.0, lifespan_scale=0.5, buoyancy=0.5, diffusion=5e-4,
             flow_noise=0.15, kolmogorov=0.01, spine_noise=0.04, voxel_size=0.008,
             particles_per_pixel=4.0, max_particles=20000, temperature_scale=1600.0,
             merging=True, wind=(0.0, 0.0, 0.0))),
    'DRAGON': (
        "Dragon Breath", "A long breath of fire blown along +X at 2 m/s (Flames › Wind) that splits "
                         "into long-lived pieces; a Turbulence force field rolls it: r 8 cm, "
                         "five flames",
        dict(profile='TORCH', flames=5, radius=0.08, stops=-22.0, color_source='PROFILE'),
        dict(points=12, height_persistent=0.15, height_intermittent=0.3, height_max=0.5,
             breakaway_frequency=20.0, lifespan_scale=2.0, buoyancy=0.15, diffusion=1e-4,
             flow_noise=0.3, kolmogorov=0.06, spine_noise=0.04, voxel_size=0.012,
             particles_per_pixel=4.0, max_particles=15000, temperature_scale=1700.0,
             merging=False, wind=(2.0, 0.0, 0.0))),
}

ITEMS = tuple((key, label, text) for key, (label, text, _src, _scene) in PRESETS.items())


def source_settings(preset):
    return dict(PRESETS[preset][2])


def scene_settings(preset):
    return dict(PRESETS[preset][3])
