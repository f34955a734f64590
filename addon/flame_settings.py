"""Structural flames settings, no ``bpy`` ([Structural Flames]): the snapshot of a scene's
Flame Sources (per-frame settings, wind, camera, sources, obstacles), the cache file names, and
the validation that runs before anything is written (BakeError naming the setting)."""

import math
import os
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import numpy as np

from .ranges import RANGES, text
from .settings import BakeError
from .ui_words import TAB, label, ui

PROFILES = ('CANDLE', 'TORCH', 'CAMPFIRE', 'CUSTOM')
MANIFEST_NAME = "flames_manifest.json"
#: §6.1 obstacles: voxel size (m) of their signed distance and the band around them.
OBSTACLE_VOXEL = 0.005
OBSTACLE_PADDING = 0.05
FORMAT_VERSION = 1  # files/manifest.py checks it: the cache format shared by every pipeline
#: k of eq. 5 (Blender watts per watt of E), calibrated once: the Candle defaults' flame (r = 5
#: mm, its measured mean |v_c| and h) gives 1 cd = 4π lm = 4π/683 W in Blender's units (683 lm/W,
#: the convention of Blender's glTF exporter). See README "Structural flames: light units".
CANDELA_WATTS = 4.0 * math.pi / 683.0
LIGHT_UNIT = 2.0e6
POINTS_RANGE = RANGES["flames.points"]
FLAMES_PER_SOURCE_RANGE = RANGES["flames.flames_per_source"]
SUBSTEPS_RANGE = RANGES["flames.substeps"]
#: A Flame Source's Intensity in stops (2^stops scales eq. 5's E): 40 stops either way covers a
#: match to a burning house (eq. 5's r^7 puts a candle and a dragon's breath 26 stops apart).
STOPS_RANGE = (-40.0, 40.0)
#: Samples per flame when the scene has no camera (no projected area to size them from).
FIXED_PARTICLES = 4000
NO_SOURCE = ("Plume: the scene has no Flame Source: select a mesh and press "
             f"{TAB} › Flame Source")


def volume_path(folder, frame):
    return os.path.join(folder, f"flames_{frame:04d}.vdb")


def spines_path(folder, frame):
    return os.path.join(folder, f"spines_{frame:04d}.npz")


@dataclass
class FlameSettings:
    """Scene-level settings at one frame (scene.plume_flames), the paper's symbols in comments."""

    # The defaults are the Candle preset's (flame_presets.CANDLE_SCENE): a new Flame Source on
    # any small mesh makes a candle flame.
    points: int = 12                   # n (§4.1)
    height_persistent: float = 0.024   # H_p (§4.3)
    height_intermittent: float = 0.03  # H_i
    height_max: float = 0.042          # H_max
    lifespan_scale: float = 1.0 / 24.0  # A (s)
    breakaway_frequency: float = 0.7   # f (Hz), 0 = 0.50 (g/2r)^½
    buoyancy: float = 0.4              # β of eq. 2
    diffusion: float = 2e-6            # d(T_p) of eq. 1, m²/s
    particles_per_pixel: float = 10.0  # §5.3
    max_particles: int = 50000
    merging: bool = True               # §4.5
    flow_noise: float = 0.04           # §4.5 buoyancy noise (widest radii)
    flow_noise_scale: float = 0.8      # λ, widest radii
    flow_noise_frequency: float = 3.0  # ν, Hz
    flow_noise_rotation: float = 0.5   # ω · 2r, rad·m/s
    kolmogorov: float = 0.0001         # §4.5 Kolmogorov noise (m RMS)
    kolmogorov_scale: float = 0.5      # Λ, m
    kolmogorov_frequency: float = 0.5  # ν, Hz
    kolmogorov_drift: Tuple[float, float, float] = (0.0, 0.0, 0.5)  # c, m/s
    spine_noise: float = 0.003         # §4.2 Kolmogorov velocity on the spine (m/s RMS)
    spine_noise_scale: float = 0.25    # Λ, m
    spine_noise_frequency: float = 1.0  # ν, Hz
    spine_noise_drift: Tuple[float, float, float] = (0.0, 0.0, 0.5)  # c, m/s
    voxel_size: float = 0.001
    temperature_scale: float = 1500.0  # K at d = I (temperature grid, blackbody colour)
    heat_of_combustion: float = 15.0   # H_c, MJ/kg (eq. 5)
    light_unit: float = LIGHT_UNIT     # k of eq. 5: Blender W per W of E
    opacity: float = 1.0               # §5.3: density where d = I


@dataclass
class WindInput:
    """One field of w (eq. 1) at one frame: kind UNIFORM (vector), VORTEX (centre, axis,
    strength), TURBULENCE (strength, size, flow, seed)."""

    kind: str
    vector: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    centre: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    strength: float = 0.0
    size: float = 1.0
    flow: float = 0.0
    seed: int = 0


@dataclass
class CameraInput:
    """The scene camera at one frame (FlameCamera); None in the snapshot: no camera."""

    position: Tuple[float, float, float]
    focal_length: float
    sensor_width: float
    width: int
    height: int


@dataclass
class FlameSourceInput:
    """One Flame Source object: its flames' places and spread values (fixed), and its keyable
    values and world positions per frame."""

    name: str
    profile: str
    #: CUSTOM: (k, 2) points (radius, height) of the profile curve, base first.
    profile_points: Optional[np.ndarray] = None
    #: §5.1: PROFILE (the profile's palette), IMAGE (color_image) or BLACKBODY.
    color_source: str = 'PROFILE'
    #: §5.1 reference image, (h, w, 3) float32 scene-linear, rows from the bottom (IMAGE).
    color_image: Optional[np.ndarray] = None
    local_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))   # (k, 3)
    local_normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (k, 3)
    start_times: np.ndarray = field(default_factory=lambda: np.zeros(0))         # s
    end_times: np.ndarray = field(default_factory=lambda: np.zeros(0))           # s (inf)
    intensity_scale: np.ndarray = field(default_factory=lambda: np.zeros(0))
    diameter_scale: np.ndarray = field(default_factory=lambda: np.zeros(0))
    height_scale: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: 4x4 world matrices at frames frame_start - 1 .. frame_end.
    matrices: List[np.ndarray] = field(default_factory=list)
    #: (radius r, intensity I, temperature T_p, Intensity in stops) at frames frame_start ..
    #: frame_end.
    values: List[Tuple[float, float, float, float]] = field(default_factory=list)

    @property
    def count(self):
        return len(self.local_points)


@dataclass
class ObstacleInput:
    name: str
    vertices: np.ndarray  # world, float32 (N, 3)
    triangles: np.ndarray  # int (M, 3)


@dataclass
class FlameBakeSnapshot:
    folder: str
    frame_start: int
    frame_end: int
    fps: float
    seed: int
    substeps: int
    sources: List[FlameSourceInput]
    #: per frame frame_start .. frame_end
    settings: List[FlameSettings]
    winds: List[List[WindInput]]
    cameras: List[Optional[CameraInput]]
    obstacles: List[ObstacleInput] = field(default_factory=list)
    #: §6.1: (domain name, its cache folder) whose volume_####.vdb velocity adds to w
    wind_domain: Optional[Tuple[str, str]] = None

    @property
    def frame_count(self):
        return self.frame_end - self.frame_start + 1


def _check(ok, message):
    if not ok:
        raise BakeError("Plume: " + message)


def _finite(*values):
    return all(math.isfinite(v) for v in values)


def validate_settings(s: FlameSettings, frame):
    """BakeError naming the setting (the panel's name and the paper's symbol) and its range."""
    at = f"Flames (frame {frame}):"
    lo, hi = POINTS_RANGE
    _check(lo <= s.points <= hi, f"{at} {ui('flames', 'points')} must be in [{lo}, {hi}] "
                                 f"(got {s.points})")
    hp, hi_, hmax = s.height_persistent, s.height_intermittent, s.height_max
    _check(_finite(hp, hi_, hmax) and hp >= 0.0,
           f"{at} {ui('flames', 'height_persistent')} must be >= 0 (got {hp:g})")
    _check(hp < hi_, f"{at} {ui('flames', 'height_persistent')} must be below "
                     f"{label('flames', 'height_intermittent')}: the intermittent region is "
                     f"[H_p, H_i] (§4.3) (got H_p = {hp:g}, H_i = {hi_:g})")
    _check(hmax >= hi_, f"{at} {ui('flames', 'height_max')} must be >= "
                        f"{label('flames', 'height_intermittent')} (got H_max = {hmax:g}, "
                        f"H_i = {hi_:g})")
    _check(_finite(s.lifespan_scale) and 1.0 / 24.0 - 1e-9 <= s.lifespan_scale <= 2.0,
           f"{at} {ui('flames', 'lifespan_scale')} must be in [1/24, 2] s "
           f"(got {s.lifespan_scale:g})")
    _check(_finite(s.breakaway_frequency) and 0.0 <= s.breakaway_frequency <= 1000.0,
           f"{at} {ui('flames', 'breakaway_frequency')} must be in [0, 1000] Hz, 0 = "
           f"automatic (got {s.breakaway_frequency:g})")
    _check(_finite(s.buoyancy) and 0.0 <= s.buoyancy <= 100.0,
           f"{at} {ui('flames', 'buoyancy')} must be in [0, 100] (got {s.buoyancy:g})")
    _check(_finite(s.diffusion) and 0.0 <= s.diffusion <= 10.0,
           f"{at} {ui('flames', 'diffusion')} must be in [0, 10] m²/s (got {s.diffusion:g})")
    _check(_finite(s.particles_per_pixel) and s.particles_per_pixel > 0.0,
           f"{at} {ui('flames', 'particles_per_pixel')} must be > 0 "
           f"(got {s.particles_per_pixel:g})")
    _check(64 <= s.max_particles <= 10_000_000,
           f"{at} {ui('flames', 'max_particles')} must be in [64, 10000000] "
           f"(got {s.max_particles})")
    _check(_finite(s.voxel_size) and s.voxel_size > 0.0,
           f"{at} {ui('flames', 'voxel_size')} must be > 0 (got {s.voxel_size:g})")
    for name, unit, open_low in NOISE_SETTINGS:
        _check_noise(s, at, name, unit, open_low)
    _check(_finite(s.temperature_scale) and 500.0 <= s.temperature_scale <= 40000.0,
           f"{at} {ui('flames', 'temperature_scale')} must be in [500, 40000] K "
           f"(got {s.temperature_scale:g})")
    _check(_finite(s.light_unit) and s.light_unit > 0.0,
           f"{at} {ui('flames', 'light_unit')} (k of eq. 5) must be > 0 Blender watts per "
           f"watt of E (got {s.light_unit:g}; the calibrated default is {LIGHT_UNIT:g})")
    _check(_finite(s.opacity) and 0.0 <= s.opacity <= 1e4,
           f"{at} {ui('flames', 'opacity')} must be in [0, 10000] (got {s.opacity:g})")


#: The noise settings (§4.2, §4.5): (FlameSettings field, unit, whether 0 is excluded); their
#: bounds are the core's (ranges.RANGES["flames.<field>"]), their labels ui_words'.
NOISE_SETTINGS = (
    ("flow_noise", " widest radii", False),
    ("flow_noise_scale", " widest radii", True),
    ("flow_noise_frequency", " Hz", False),
    ("flow_noise_rotation", " rad·m/s", False),
    ("kolmogorov", " m", False),
    ("kolmogorov_scale", " m", True),
    ("kolmogorov_frequency", " Hz", False),
    ("kolmogorov_drift", " m/s per axis", False),
    ("spine_noise", " m/s", False),
    ("spine_noise_scale", " m", True),
    ("spine_noise_frequency", " Hz", False),
    ("spine_noise_drift", " m/s per axis", False),
)


def _check_noise(s, at, name, unit, open_low):
    """BakeError "<label> (<panel>) must be in [lo, hi]<unit> (got v)" (a vector: every
    component)."""
    value = getattr(s, name)
    values = tuple(value) if isinstance(value, (tuple, list)) else (value,)
    lo, hi = RANGES[f"flames.{name}"]
    ok = all(_finite(v) and (v > lo if open_low else v >= lo) and v <= hi for v in values)
    _check(ok, f"{at} {ui('flames', name)} must be in {text(f'flames.{name}', open_low)}{unit} "
               f"(got {value if len(values) > 1 else format(values[0], 'g')})")


def validate_source_values(src: FlameSourceInput):
    lo, hi = STOPS_RANGE
    for i, (r, intensity, temp, stops) in enumerate(src.values):
        at = f"Flame Source '{src.name}'"
        _check(_finite(r) and r > 0.0, f"{at}: {ui('flame_source', 'radius')} must be > 0 "
                                       f"(got {r:g})")
        _check(_finite(intensity) and intensity >= 0.0,
               f"{at}: {ui('flame_source', 'intensity')} must be >= 0 (got {intensity:g})")
        _check(_finite(temp) and temp >= 0.0,
               f"{at}: {ui('flame_source', 'temperature')} must be >= 0 (got {temp:g})")
        _check(_finite(stops) and lo <= stops <= hi,
               f"{at}: {ui('flame_source', 'stops')} must be in [{lo:g}, {hi:g}] stops "
               f"(got {stops:g})")


def validate_snapshot(snap: FlameBakeSnapshot):
    _check(bool(snap.sources), NO_SOURCE[len("Plume: "):])
    _check(snap.frame_end >= snap.frame_start, f"Flames: {ui('flames', 'frame_end')} must be "
                                               f">= Start (got {snap.frame_start} to "
                                               f"{snap.frame_end})")
    lo, hi = SUBSTEPS_RANGE
    _check(lo <= snap.substeps <= hi, f"Flames: {ui('flames', 'substeps')} must be in "
                                      f"[{lo}, {hi}] (got {snap.substeps})")
    for i, s in enumerate(snap.settings):
        validate_settings(s, snap.frame_start + i)
    for src in snap.sources:
        validate_source_values(src)
