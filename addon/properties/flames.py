"""Structural flames settings ([Structural Flames]): ``obj.plume.flame`` on a Flame Source and
``scene.plume_flames`` for the whole bake, read frame by frame by plume.flames_bake, so every
number is keyable. Soft limits only: the bake validates with messages naming the setting and its
range (flames.validate_*)."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from ..flame_presets import PRESETS
from ..flame_settings import LIGHT_UNIT
from ..ranges import text

#: The defaults are the Candle preset's: a new Flame Source on any small mesh makes a candle.
CANDLE_SOURCE, CANDLE = PRESETS['CANDLE'][2], PRESETS['CANDLE'][3]

PROFILE_ITEMS = (
    ('CANDLE', "Candle", "Figure 3, left: a slim candle flame"),
    ('TORCH', "Torch", "Figure 3, middle: a torch flame"),
    ('CAMPFIRE', "Campfire", "Figure 3, right: a broad campfire flame"),
    ('CUSTOM', "Custom Curve", "The profile r(s) drawn as a curve object (Profile Curve)"),
)
COLOR_ITEMS = (
    ('PROFILE', "Profile Colours", "The profile's own colour image, painted from "
                                   "photographs (candle: blue base, yellow-white core, orange to "
                                   "red tip; torch and campfire: yellow base, orange, red tip)"),
    ('IMAGE', "Colour Image", "Your reference photograph (Colour Image) mapped on the "
                              "profile's side view, base at the bottom"),
    ('BLACKBODY', "Blackbody", "The blackbody colour of each particle's temperature "
                               "(Temperature × d(x)/I, §5.1: hotter regions are bluer)"),
)
SPREAD_ITEMS = (
    ('NONE', "Always Burning", "Every flame of the source burns from the first frame"),
    ('MAPS', "Maps", "Greyscale images on the mesh's UVs give each flame's activation "
                     "time (and optionally burn duration, intensity, diameter, height)"),
    ('MODEL', "Spread Model", "The flame front leaves the ignition point at "
                              "v_s = T_f / L (cos θ + h sin θ)"),
)


def _image(name, what):
    return PointerProperty(name=name, type=bpy.types.Image, description=what)


class PlumeFlameSourceSettings(bpy.types.PropertyGroup):
    # --- Shape (§4.4, §5.1) ---
    profile: EnumProperty(name="Profile", items=PROFILE_ITEMS, default='CANDLE',
                          description="The normalized profile r(s) whose surface "
                                      "of revolution around the spine is the visible flame")
    profile_curve: PointerProperty(
        name="Profile Curve", type=bpy.types.Object, poll=lambda _s, ob: ob.type == 'CURVE',
        description="Custom profile (§4.4): the first spline of this curve, drawn from the base "
                    "to the tip; local X is the radius, the longer of local Y and Z the height")
    color_source: EnumProperty(name="Colour", items=COLOR_ITEMS, default='PROFILE',
                               description="Where each particle's base colour comes from "
                                           "(its brightness comes from eq. 5-6)")
    color_image: _image("Colour Image", "A reference photograph (RGB) mapped on the 2D "
                                        "profile's side view, base at the bottom, tip at the "
                                        "top: each particle's base colour and relative "
                                        "brightness (Colour: Colour Image)")
    flames: IntProperty(
        name="Flames", default=1, soft_min=1, soft_max=64,
        description="Flames on this source: 1 at the centre of its up-facing faces, more spread "
                    "evenly over them (area-weighted, deterministic); in "
                    + text('flames.flames_per_source'))
    radius: FloatProperty(
        name="Radius (r)", default=CANDLE_SOURCE["radius"], soft_min=0.001, soft_max=1.0, unit='LENGTH',
        precision=4, description="r: radius of each flame's source (m): the profile's width and "
                                 "the breakaway frequency f = 0.50 (g/2r)^½ (§4.3); > 0")
    stops: FloatProperty(
        name="Intensity", default=0.0, soft_min=-16.0, soft_max=16.0, step=50, precision=1,
        description="Brightness of this source's flames and of their lights, in stops (+1 doubles, "
                    "-1 halves) on top of the scene's Light Unit: lets a candle and a campfire "
                    "share one exposure (k of eq. 5, \"for visual control\"); in [-40, 40]")
    intensity: FloatProperty(name="Density (I)", default=1.0, soft_min=0.0, soft_max=10.0,
                             description="I of eq. 4: density of the flame's glowing gas (its "
                                         "light's share and its opacity); >= 0")
    temperature: FloatProperty(
        name="Temperature (T_p)", default=1.0, soft_min=0.0, soft_max=10.0,
        description="T_p of eq. 1-2 (normalized, ambient T_0 = 0): scales the Brownian "
                    "diffusion and the buoyancy of the spine's points; >= 0")
    # --- Spread (§6.2) ---
    spread: EnumProperty(name="Spread", items=SPREAD_ITEMS, default='NONE',
                         description="When each flame of the source starts to burn")
    activation_map: _image("Activation Map", "Greyscale on the UVs; value v starts the "
                                              "flame there at v × Time Scale seconds")
    time_scale: FloatProperty(name="Time Scale", default=2.0, soft_min=0.0, soft_max=60.0,
                              unit='TIME_ABSOLUTE',
                              description="Seconds for an activation-map value of 1; >= 0")
    duration_map: _image("Duration Map", "Greyscale; the flame burns v × Duration Scale "
                                          "seconds (none: until the end)")
    duration_scale: FloatProperty(name="Duration Scale", default=5.0, soft_min=0.0,
                                  soft_max=60.0, unit='TIME_ABSOLUTE',
                                  description="Seconds of burning for a duration value of 1")
    intensity_map: _image("Intensity Map", "Greyscale; multiplies the flame's intensity")
    diameter_map: _image("Diameter Map", "Greyscale; multiplies the flame's radius r")
    height_map: _image("Height Map", "Greyscale; multiplies H_p, H_i and H_max")
    ignition: PointerProperty(
        name="Ignition", type=bpy.types.Object,
        description="Spread model: where the fire starts (none: the source's origin)")
    spread_temperature: FloatProperty(
        name="Flame Temperature (T_f)", default=1.0, soft_min=0.0, soft_max=10.0,
        description="T_f of eq. 7 (v_s = T_f / L (cos θ + h sin θ)); > 0")
    spread_thickness: FloatProperty(
        name="Thermal Thickness (L)", default=10.0, soft_min=0.01, soft_max=1000.0,
        description="L of eq. 7: thermal thickness of the burning material (larger: slower "
                    "spread); > 0")


class PlumeFlamesSettings(bpy.types.PropertyGroup):
    # --- Bake ---
    frame_start: IntProperty(name="Start", default=1, description="First baked frame")
    frame_end: IntProperty(name="End", default=48, description="Last baked frame")
    seed: IntProperty(name="Seed", default=0, soft_min=0,
                      description="Seed of every random choice: same seed, same flames")
    substeps: IntProperty(name="Substeps", default=2, soft_min=1, soft_max=16,
                          description="Steps of eq. 1 per frame (§4.1); in "
                                      + text('flames.substeps'))
    # --- Structure (§4.1-4.3) ---
    points: IntProperty(name="Control Points (n)", default=CANDLE["points"], soft_min=2, soft_max=64,
                        description="n: points of a flame's spine (§4.1); in "
                                    + text('flames.points'))
    height_persistent: FloatProperty(
        name="Persistent Height (H_p)", default=CANDLE["height_persistent"], soft_min=0.0, soft_max=10.0,
        unit='LENGTH', description="H_p: top of the continuous region (Figure 2, §4.3); "
                                   "0 <= H_p < H_i")
    height_intermittent: FloatProperty(
        name="Intermittent Height (H_i)", default=CANDLE["height_intermittent"], soft_min=0.0, soft_max=10.0,
        unit='LENGTH', description="H_i: top of the intermittent region; longer flames may "
                                   "flicker or break (§4.3); H_p < H_i <= H_max")
    height_max: FloatProperty(
        name="Max Height (H_max)", default=CANDLE["height_max"], soft_min=0.0, soft_max=20.0, unit='LENGTH',
        description="H_max: artistic limit on flame length, D(h) = 1 past it (§4.3); >= H_i")
    lifespan_scale: FloatProperty(
        name="Lifespan Scale (A)", default=CANDLE["lifespan_scale"], soft_min=1.0 / 24.0, soft_max=2.0,
        unit='TIME_ABSOLUTE', description="A: a separated flame lives A·i³, i uniform in [0,1] "
                                          "(§4.3); in [1/24, 2] s")
    breakaway_frequency: FloatProperty(
        name="Breakaway Frequency (f)", default=CANDLE["breakaway_frequency"], soft_min=0.0, soft_max=50.0,
        description="f: breakaway rate past H_i in Hz (§4.3); 0 = automatic, 0.50 (g/2r)^½")
    buoyancy: FloatProperty(name="Buoyancy (β)", default=CANDLE["buoyancy"], soft_min=0.0, soft_max=10.0,
                            description="β of eq. 2: thermal buoyancy c = β |g| (T_p − T_0) t_p; "
                                        "in [0, 100]")
    diffusion: FloatProperty(
        name="Diffusion", default=CANDLE["diffusion"], soft_min=0.0, soft_max=0.01, precision=5,
        description="d(T_p) of eq. 1: Brownian diffusion coefficient (m²/s) scaled by T_p; "
                    "in [0, 10]")
    # --- Shape and detail (§4.4-4.5) ---
    particles_per_pixel: FloatProperty(
        name="Particles per Pixel", default=10.0, soft_min=0.1, soft_max=100.0,
        description="Particles per pixel of the flame's projected area on the scene "
                    "camera (the paper: about ten); > 0")
    max_particles: IntProperty(name="Max Particles", default=50000, soft_min=100,
                               soft_max=1000000,
                               description="Most particles per flame (the paper: 1,000 to 50,000)")
    merging: BoolProperty(name="Merging", default=True,
                          description="Drop particles inside a neighbouring flame and "
                                      "outside their own (flames appear to merge)")
    # --- Noise (§4.2 on the spine, §4.5 on the render particles) ---
    flow_noise: FloatProperty(name="Flow Noise", default=CANDLE["flow_noise"], soft_min=0.0, soft_max=1.0,
                              description="Buoyancy (flow) noise amplitude, in widest "
                                          "radii of the profile; 0 turns it off; in "
                                          + text('flames.flow_noise'))
    flow_noise_scale: FloatProperty(
        name="Flow Noise Scale (λ)", default=0.8, soft_min=0.05, soft_max=5.0,
        description="λ: feature size of the flow noise across the flame, in widest radii of "
                    "the profile (§4.5, Perlin & Neyret); in "
                    + text('flames.flow_noise_scale', open_low=True))
    flow_noise_frequency: FloatProperty(
        name="Flow Noise Frequency (ν)", default=3.0, soft_min=0.0, soft_max=20.0,
        description="ν: noise cells leaving the flame's base per second (Hz), rising with the "
                    "spine's points (§4.5); in " + text('flames.flow_noise_frequency'))
    flow_noise_rotation: FloatProperty(
        name="Flow Noise Rotation (ω·2r)", default=0.5, soft_min=0.0, soft_max=5.0,
        description="ω × source diameter 2r (rad·m/s): the flow noise's gradients turn at "
                    "ω = this / 2r, faster on small sources (§4.5); in "
                    + text('flames.flow_noise_rotation'))
    kolmogorov: FloatProperty(name="Kolmogorov Noise", default=CANDLE["kolmogorov"], soft_min=0.0,
                              soft_max=0.1, unit='LENGTH', precision=4,
                              description="RMS displacement of the render particles by the "
                                          "Kolmogorov-spectrum turbulence (m); 0 turns it off; "
                                          "in " + text('flames.kolmogorov'))
    kolmogorov_scale: FloatProperty(
        name="Kolmogorov Scale (Λ)", default=0.5, soft_min=0.01, soft_max=10.0, unit='LENGTH',
        description="Λ: the largest eddy of the render particles' Kolmogorov noise, the period "
                    "of its E(k) ∝ k^(−5/3) tile (m, §4.5); in "
                    + text('flames.kolmogorov_scale', open_low=True))
    kolmogorov_frequency: FloatProperty(
        name="Kolmogorov Frequency (ν)", default=0.5, soft_min=0.0, soft_max=10.0,
        description="ν: how fast the render particles' Kolmogorov noise changes in place (Hz, "
                    "Generated per frame); in " + text('flames.kolmogorov_frequency'))
    kolmogorov_drift: FloatVectorProperty(
        name="Kolmogorov Drift (c)", size=3, subtype='VELOCITY', unit='VELOCITY',
        default=(0.0, 0.0, 0.5), soft_min=-5.0, soft_max=5.0,
        description="c: velocity carrying the render particles' frozen Kolmogorov turbulence "
                    "(m/s, §4.5); each axis in " + text('flames.kolmogorov_drift'))
    spine_noise: FloatProperty(
        name="Spine Noise", default=CANDLE["spine_noise"], soft_min=0.0, soft_max=0.5, unit='VELOCITY',
        precision=3,
        description="RMS speed (m/s) of the Kolmogorov-spectrum velocity added to eq. "
                    "1 for every control point of the spines (the torch's \"thermal buoyancy and "
                    "Kolmogorov noise\"): the flames sway and curl; 0 turns it off; in "
                    + text('flames.spine_noise'))
    spine_noise_scale: FloatProperty(
        name="Spine Noise Scale (Λ)", default=0.25, soft_min=0.01, soft_max=10.0, unit='LENGTH',
        description="Λ: the largest eddy of the spine's Kolmogorov noise (m, §4.2); about a "
                    "flame's length sways whole flames; in "
                    + text('flames.spine_noise_scale', open_low=True))
    spine_noise_frequency: FloatProperty(
        name="Spine Noise Frequency (ν)", default=1.0, soft_min=0.0, soft_max=10.0,
        description="ν: how fast the spine's Kolmogorov noise changes in place (Hz, §4.2); in "
                    + text('flames.spine_noise_frequency'))
    spine_noise_drift: FloatVectorProperty(
        name="Spine Noise Drift (c)", size=3, subtype='VELOCITY', unit='VELOCITY',
        default=(0.0, 0.0, 0.5), soft_min=-5.0, soft_max=5.0,
        description="c: velocity carrying the spine's frozen Kolmogorov turbulence (m/s, "
                    "§4.2), up with the hot gas; each axis in " + text('flames.spine_noise_drift'))
    # --- Wind (§4.2, §6, §6.1) ---
    wind: FloatVectorProperty(name="Wind", size=3, subtype='VELOCITY', unit='VELOCITY',
                              default=(0.0, 0.0, 0.0),
                              description="w of eq. 1: a uniform wind (m/s)")
    use_force_fields: BoolProperty(
        name="Force Fields", default=True,
        description="Add the scene's Wind (Strength m/s along its Z), Vortex (tangential "
                    "Strength m/s about its Z) and Turbulence (RMS Strength m/s, Size, Flow) "
                    "force fields to w (falloff ignored)")
    wind_domain: PointerProperty(
        name="Wind Domain", type=bpy.types.Object,
        poll=lambda _s, ob: getattr(ob, "plume", None) is not None and ob.plume.role == 'DOMAIN',
        description="A baked Plume domain whose velocity adds to w, frame by frame, "
                    "where it holds smoke, or everywhere when baked with Velocity Everywhere "
                    "(the paper used a 40³ solver around obstacles)")
    use_obstacles: BoolProperty(
        name="Obstacles", default=True,
        description="Spine points are pushed out of the scene's Obstacle objects (closed "
                    "meshes, voxelized at Voxel Size at the first frame)")
    # --- Rendering (§5) ---
    voxel_size: FloatProperty(name="Voxel Size", default=CANDLE["voxel_size"], soft_min=0.0005, soft_max=0.1,
                              unit='LENGTH', precision=4,
                              description="Δx of the flame VDB grids (m); > 0")
    temperature_scale: FloatProperty(
        name="Temperature (K)", default=CANDLE["temperature_scale"], soft_min=500.0, soft_max=4000.0,
        description="Kelvin where d = I: the temperature grid, and the particle colour of "
                    "sources whose Colour is Blackbody (§5.1); in [500, 40000]")
    emission: FloatProperty(
        name="Flame Brightness", default=1.0, soft_min=0.0, soft_max=100.0,
        description="Multiplies the visible flame's emission in the material (1: the flame "
                    "looks as bright as the light it casts, both E × Light Unit)")
    opacity: FloatProperty(
        name="Opacity", default=1.0, soft_min=0.0, soft_max=20.0,
        description="Absorption density where d = I, falling as (d/I)^2 with the "
                    "particles' relative brightness: real flames are highly transparent, only "
                    "bright things show through their core; in [0, 10000]")
    heat_of_combustion: FloatProperty(
        name="Heat of Combustion (H_c)", default=15.0, soft_min=1.0, soft_max=60.0,
        description="H_c of eq. 5 in MJ/kg (15 wood, 48 gasoline)")
    light_unit: FloatProperty(
        name="Light Unit", default=LIGHT_UNIT, soft_min=1e-3 * LIGHT_UNIT,
        soft_max=1e3 * LIGHT_UNIT, precision=1,
        description="k of eq. 5: Blender watts per watt of E = ½ k 0.3 m H_c 2 A_f r³ / h, for "
                    "both the flames' emission and their lights. The default is calibrated once "
                    "so that the Candle defaults give a candle's luminous intensity, about 1 cd "
                    "(0.018 W in Blender's units, 683 lm/W); > 0")
    lights: BoolProperty(
        name="Flame Lights", default=True,
        description="A point light of radius h/3 at the middle of each flame, of power "
                    "E × Light Unit and the flame's mean colour")
    cache_directory: StringProperty(
        name="Cache", subtype='DIR_PATH', default="//plume_cache/flames/",
        description="Folder of flames_####.vdb and spines_####.npz ('//' = next to the .blend)")
    # --- Built data ---
    volume_object: StringProperty(name="Volume Object", default="",
                                  description="Name of the Volume object showing the flames bake")
    spines_object: StringProperty(name="Spines Object", default="",
                                  description="Name of the curve object showing the flame spines")
    frames_baked: IntProperty(name="Frames Baked", default=0, min=0,
                              description="Frames of the last flames bake available in the cache")
    summary: StringProperty(name="Summary", default="",
                            description="What the last flames bake made")


classes = (PlumeFlameSourceSettings, PlumeFlamesSettings)
