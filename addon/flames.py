"""Structural flames bake, no ``bpy`` (structural_flames.txt): the settings snapshot of a scene's
Flame Sources, its validation and the bake loop.

    snap = snapshot.flames_snapshot(context)          # bpy side: FlameBakeSnapshot
    runner = FlameBakeRunner(native, snap)            # BakeError on bad input, nothing written
    result = runner.run()                             # <folder>/flames_####.vdb, spines_####.npz

Every frame: the sources follow their objects (position, and velocity V from the motion between
frames, §4.2), the wind is rebuilt (§4.2, §6, §6.1), the FlameSystem steps `substeps` times
(§4.1-4.3), the FlameShaper samples the flames for the scene camera (§4.4-4.5, §5), and the
particles are rasterized into a VDB (density, temperature, flame, color, velocity); the spines
and the lights (§5.2) go to an .npz. Files are written to a temporary name and renamed, so a
cancelled or killed bake never leaves a half file.
"""

import math
import os
import time
import zipfile
from dataclasses import asdict, dataclass, field
from typing import Callable, List, Optional, Tuple

import numpy as np

from . import files
from .settings import BakeError

PROFILES = ('CANDLE', 'TORCH', 'CAMPFIRE', 'CUSTOM')
MANIFEST_NAME = "flames_manifest.json"
#: §6.1 obstacles: voxel size (m) of their signed distance and the band around them.
OBSTACLE_VOXEL = 0.005
OBSTACLE_PADDING = 0.05
FORMAT_VERSION = 1
POINTS_RANGE = (2, 256)
FLAMES_PER_SOURCE_RANGE = (1, 1024)
SUBSTEPS_RANGE = (1, 64)
#: Samples per flame when the scene has no camera (no projected area to size them from).
FIXED_PARTICLES = 4000
NO_SOURCE = ("Plume: the scene has no Flame Source (make a mesh one with "
             "plume.role_set(role='FLAME_SOURCE'))")


def volume_path(folder, frame):
    return os.path.join(folder, f"flames_{frame:04d}.vdb")


def spines_path(folder, frame):
    return os.path.join(folder, f"spines_{frame:04d}.npz")


@dataclass
class FlameSettings:
    """Scene-level settings at one frame (scene.plume_flames), the paper's symbols in comments."""

    points: int = 16                   # n (§4.1)
    height_persistent: float = 0.03    # H_p (§4.3)
    height_intermittent: float = 0.06  # H_i
    height_max: float = 0.12           # H_max
    lifespan_scale: float = 0.25       # A (s)
    breakaway_frequency: float = 0.0   # f (Hz), 0 = 0.50 (g/2r)^½
    buoyancy: float = 0.5              # β of eq. 2
    diffusion: float = 1e-4            # d(T_p) of eq. 1, m²/s
    particles_per_pixel: float = 10.0  # §5.3
    max_particles: int = 50000
    merging: bool = True               # §4.5
    flow_noise: float = 0.15           # §4.5 buoyancy noise (widest radii)
    kolmogorov: float = 0.003          # §4.5 Kolmogorov noise (m RMS)
    voxel_size: float = 0.002
    temperature_scale: float = 1500.0
    heat_of_combustion: float = 15.0   # H_c, MJ/kg (eq. 5)


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
    #: §5.1 reference image, (h, w, 3) float32 rows from the bottom; None: white.
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
    #: (radius r, intensity I, temperature T_p) at frames frame_start .. frame_end.
    values: List[Tuple[float, float, float]] = field(default_factory=list)

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
    _check(lo <= s.points <= hi, f"{at} Control Points (n) must be in [{lo}, {hi}] "
                                 f"(got {s.points})")
    hp, hi_, hmax = s.height_persistent, s.height_intermittent, s.height_max
    _check(_finite(hp, hi_, hmax) and hp >= 0.0,
           f"{at} Persistent Height (H_p) must be >= 0 (got {hp})")
    _check(hp < hi_, f"{at} Persistent Height (H_p = {hp:g}) must be below Intermittent Height "
                     f"(H_i = {hi_:g}): the intermittent region is [H_p, H_i] (§4.3)")
    _check(hmax >= hi_, f"{at} Max Height (H_max = {hmax:g}) must be >= Intermittent Height "
                        f"(H_i = {hi_:g})")
    _check(_finite(s.lifespan_scale) and 1.0 / 24.0 - 1e-9 <= s.lifespan_scale <= 2.0,
           f"{at} Lifespan Scale (A) must be in [1/24, 2] s (got {s.lifespan_scale})")
    _check(_finite(s.breakaway_frequency) and 0.0 <= s.breakaway_frequency <= 1000.0,
           f"{at} Breakaway Frequency (f) must be in [0, 1000] Hz, 0 = automatic "
           f"(got {s.breakaway_frequency})")
    _check(_finite(s.buoyancy) and 0.0 <= s.buoyancy <= 100.0,
           f"{at} Buoyancy (β) must be in [0, 100] (got {s.buoyancy})")
    _check(_finite(s.diffusion) and 0.0 <= s.diffusion <= 10.0,
           f"{at} Diffusion must be in [0, 10] m²/s (got {s.diffusion})")
    _check(_finite(s.particles_per_pixel) and s.particles_per_pixel > 0.0,
           f"{at} Particles per Pixel must be > 0 (got {s.particles_per_pixel})")
    _check(64 <= s.max_particles <= 10_000_000,
           f"{at} Max Particles must be in [64, 10000000] (got {s.max_particles})")
    _check(_finite(s.voxel_size) and s.voxel_size > 0.0,
           f"{at} Voxel Size must be > 0 (got {s.voxel_size})")
    _check(_finite(s.flow_noise, s.kolmogorov) and s.flow_noise >= 0.0 and s.kolmogorov >= 0.0,
           f"{at} Flow Noise and Kolmogorov Noise must be >= 0")


def validate_source_values(src: FlameSourceInput):
    for i, (r, intensity, temp) in enumerate(src.values):
        at = f"Flame Source '{src.name}'"
        _check(_finite(r) and r > 0.0, f"{at}: Radius (r) must be > 0 (got {r})")
        _check(_finite(intensity) and intensity >= 0.0,
               f"{at}: Intensity (I) must be >= 0 (got {intensity})")
        _check(_finite(temp) and temp >= 0.0,
               f"{at}: Temperature (T_p) must be >= 0 (got {temp})")


def validate_snapshot(snap: FlameBakeSnapshot):
    _check(bool(snap.sources), NO_SOURCE[len("Plume: "):])
    _check(snap.frame_end >= snap.frame_start, f"Flames: End ({snap.frame_end}) must be >= "
                                               f"Start ({snap.frame_start})")
    lo, hi = SUBSTEPS_RANGE
    _check(lo <= snap.substeps <= hi, f"Flames: Substeps must be in [{lo}, {hi}] "
                                      f"(got {snap.substeps})")
    for i, s in enumerate(snap.settings):
        validate_settings(s, snap.frame_start + i)
    for src in snap.sources:
        validate_source_values(src)


class FlameNative:
    """The native objects of a bake, built from a snapshot (ValueError -> BakeError)."""

    def __init__(self, native, snap: FlameBakeSnapshot):
        self.n, self.snap = native, snap

    def params(self, s: FlameSettings):
        p = self.n.FlameParams()
        p.points = int(s.points)
        p.height_persistent = float(s.height_persistent)
        p.height_intermittent = float(s.height_intermittent)
        p.height_max = float(s.height_max)
        p.lifespan_scale = float(s.lifespan_scale)
        p.breakaway_frequency = float(s.breakaway_frequency)
        p.buoyancy = float(s.buoyancy)
        p.diffusion = float(s.diffusion)
        p.validate()
        return p

    def shaper(self, s: FlameSettings, profiles, images, has_camera):
        """The FlameShaper of settings `s` (§4.4-5.2); ValueError on bad settings. Without a
        scene camera every flame gets FIXED_PARTICLES samples."""
        return self.n.FlameShaper(
            profiles, images=images, seed=int(self.snap.seed),
            particles_per_pixel=float(s.particles_per_pixel), max_particles=int(s.max_particles),
            fixed_count=0 if has_camera else FIXED_PARTICLES,
            flow_noise_amplitude=float(s.flow_noise), kolmogorov_amplitude=float(s.kolmogorov),
            heat_of_combustion=float(s.heat_of_combustion) * 1e6, merging=bool(s.merging))

    def profile(self, src: FlameSourceInput):
        if src.profile == 'CUSTOM':
            return self.n.FlameProfile.from_curve(np.asarray(src.profile_points, np.float64))
        return self.n.FlameProfile.library(src.profile.lower())

    @staticmethod
    def color_image(src: FlameSourceInput):
        """(h, w, 3) float32 rows from the bottom; white (1x1) without an image."""
        if src.color_image is None:
            return np.ones((1, 1, 3), np.float32)
        return np.ascontiguousarray(src.color_image[..., :3], np.float32)


def shape_key(s: FlameSettings):
    """The settings the FlameShaper is built from: a change rebuilds it."""
    return (s.particles_per_pixel, s.max_particles, s.merging, s.flow_noise, s.kolmogorov,
            s.heat_of_combustion)


@dataclass
class FlameBakeResult:
    frame_start: int
    last_frame: int
    cancelled: bool = False
    step_seconds: float = 0.0   # FlameSystem steps (§4.1-4.3)
    shape_seconds: float = 0.0  # FlameShaper (§4.4-5.2)
    write_seconds: float = 0.0  # rasterizing and writing the files
    flames: List[int] = field(default_factory=list)     # live flames per frame
    particles: List[int] = field(default_factory=list)  # particles per frame

    @property
    def frames(self):
        return self.last_frame - self.frame_start + 1


class FlameBakeRunner:
    """Bakes a snapshot; progress(done, total) and cancel() -> bool are optional hooks (polled
    between frames), like flowgraph.SynthesisRunner. The constructor validates everything and
    builds the native objects, so bad input raises BakeError before any file is written."""

    def __init__(self, native, snap: FlameBakeSnapshot,
                 progress: Optional[Callable[[int, int], None]] = None,
                 cancel: Optional[Callable[[], bool]] = None):
        validate_snapshot(snap)
        self.native, self.snap, self.progress, self.cancel = native, snap, progress, cancel
        self.build = FlameNative(native, snap)
        try:
            self.params = [self.build.params(s) for s in snap.settings]
            self.profiles, self.images = [], []
            for src in snap.sources:
                try:
                    prof, img = self.build.profile(src), self.build.color_image(src)
                except ValueError as e:
                    raise BakeError(f"Plume: Flame Source '{src.name}': {e}") from None
                self.profiles += [prof] * src.count
                self.images += [img] * src.count
            if not any(src.color_image is not None for src in snap.sources):
                self.images = None
            for i, s in enumerate(snap.settings):  # every keyed shape setting is valid
                if i == 0 or shape_key(s) != shape_key(snap.settings[i - 1]):
                    self.build.shaper(s, self.profiles[:1], None, True)
            self._check_sources()
            self.obstacles = [native.GridSdf(**native.mesh_signed_distance(
                o.vertices, o.triangles, OBSTACLE_VOXEL, padding=OBSTACLE_PADDING, name=o.name))
                for o in snap.obstacles]
        except ValueError as e:
            raise BakeError(f"Plume: Flames: {e}") from None

    def _check_sources(self):
        """Every source at every frame through the core's own validation (ValueError naming
        the setting), so a bad keyed value stops the bake before anything is written."""
        probe = self.native.FlameSystem(self.params[0], 0)
        dt_frame = 1.0 / self.snap.fps
        for src in self.snap.sources:
            for i in range(self.snap.frame_count):
                for k in range(src.count):
                    try:
                        probe.add_source(self._source_at(src, k, i, 1.0, dt_frame))
                    except ValueError as e:
                        raise BakeError(f"Plume: Flame Source '{src.name}' (frame "
                                        f"{self.snap.frame_start + i}): {e}") from None

    # --- per frame inputs ---
    def _source_at(self, src, k, index, alpha, dt_frame):
        """FlameSource k of `src` at frame index `index` (0 = frame_start) and fraction alpha
        of the step from the previous frame: position on the moving surface, V from the motion
        between the two frames (§4.2)."""
        m0, m1 = src.matrices[index], src.matrices[index + 1]
        p = np.append(src.local_points[k], 1.0)
        x0, x1 = (m0 @ p)[:3], (m1 @ p)[:3]
        n = m1[:3, :3] @ src.local_normals[k]
        n = n / max(float(np.linalg.norm(n)), 1e-12)
        r, intensity, temp = src.values[index]
        fs = self.native.FlameSource()
        fs.position = tuple(x0 + alpha * (x1 - x0))
        fs.normal = tuple(n)
        fs.velocity = tuple((x1 - x0) / dt_frame)
        fs.radius = float(r)
        fs.start_time = float(src.start_times[k])
        fs.end_time = float(src.end_times[k])
        fs.intensity = float(intensity * src.intensity_scale[k])
        fs.diameter_scale = float(src.diameter_scale[k])
        fs.height_scale = float(src.height_scale[k])
        fs.temperature = float(temp)
        return fs

    def _wind(self, system, index):
        n = self.native
        system.clear_wind()
        for f in self.snap.winds[index]:
            if f.kind == 'UNIFORM':
                system.add_wind(n.UniformWind(tuple(f.vector)))
            elif f.kind == 'VORTEX':
                system.add_wind(n.VortexWind(tuple(f.centre), tuple(f.vector), f.strength,
                                             core_radius=0.1 * f.size))
            elif f.kind == 'TURBULENCE':
                system.add_wind(n.TurbulenceWind(f.strength, f.size, flow=f.flow, seed=f.seed))
        if self.snap.wind_domain is not None:
            grid = self._domain_wind(self.snap.frame_start + index)
            if grid is not None:
                system.add_wind(grid)

    def _domain_wind(self, frame):
        """§6.1: the baked domain's cell-centred velocity of `frame` as a GridWind (None when
        the frame is not baked or stores no velocity: no smoke, Velocity Everywhere off)."""
        from . import cache
        name, folder = self.snap.wind_domain
        path = cache.volume_path(folder, frame)
        if not os.path.isfile(path):
            return None
        g = self.native.read_vdb_grid(path, "velocity")
        if np.asarray(g["values"]).size == 0:
            return None
        origin = tuple(np.asarray(g["world_of_voxel_zero"]) - 0.5 * g["voxel_size"]
                       + np.asarray(g["min"]) * g["voxel_size"])
        return self.native.GridWind(np.asarray(g["values"], np.float32), float(g["voxel_size"]),
                                    origin)

    def _camera(self, index):
        """FlameCamera of frame `index` (the default one when the scene has no camera)."""
        c = self.snap.cameras[index]
        if c is None:
            return self.native.FlameCamera((0.0, -5.0, 1.0))
        return self.native.FlameCamera(tuple(c.position), focal_length=float(c.focal_length),
                                       sensor_width=float(c.sensor_width), width=int(c.width),
                                       height=int(c.height))

    # --- the bake ---
    def run(self) -> FlameBakeResult:
        snap, n = self.snap, self.native
        os.makedirs(snap.folder, exist_ok=True)
        clear_folder(snap.folder)
        system = n.FlameSystem(self.params[0], int(snap.seed))
        for src in snap.sources:
            for k in range(src.count):
                system.add_source(self._source_at(src, k, 0, 0.0, 1.0 / snap.fps))
        for o in self.obstacles:
            system.add_obstacle(o)
        result = FlameBakeResult(frame_start=snap.frame_start, last_frame=snap.frame_start - 1)
        shaper, key = None, None
        dt_frame = 1.0 / snap.fps
        dt = dt_frame / snap.substeps
        total = snap.frame_count
        for i in range(total):
            if self.cancel is not None and self.cancel():
                result.cancelled = True
                break
            frame = snap.frame_start + i
            s = snap.settings[i]
            t0 = time.perf_counter()
            system.params = self.params[i]
            self._wind(system, i)
            for sub in range(snap.substeps):
                alpha = (sub + 1) / snap.substeps
                j = 0
                for src in snap.sources:
                    for k in range(src.count):
                        system.set_source(j, self._source_at(src, k, i, alpha, dt_frame))
                        j += 1
                system.step(dt)
            t1 = time.perf_counter()
            has_camera = snap.cameras[i] is not None
            if shaper is None or (shape_key(s), has_camera) != key:
                shaper = self.build.shaper(s, self.profiles, self.images, has_camera)
                shaper.set_obstacles(self.obstacles)  # §6.1: the system's own SDFs, shared
                key = (shape_key(s), has_camera)
            live = system.flames()
            shaped = shaper.shape(live, system.time, self._camera(i))
            t2 = time.perf_counter()
            n.write_flames_vdb(volume_path(snap.folder, frame), shaped,
                               voxel_size=float(s.voxel_size),
                               temperature_scale=float(s.temperature_scale), frame=frame)
            write_spines(spines_path(snap.folder, frame), live, shaped["lights"],
                         self.params[i])
            result.step_seconds += t1 - t0
            result.shape_seconds += t2 - t1
            result.write_seconds += time.perf_counter() - t2
            result.flames.append(len(live))
            result.particles.append(len(shaped["density"]))
            result.last_frame = frame
            write_manifest(snap, result)
            if self.progress is not None:
                self.progress(i + 1, total)
        return result


def clear_folder(folder):
    """Removes the frames of an older bake (they would mix in) and its manifest."""
    for name in os.listdir(folder):
        if ((name.startswith("flames_") and name.endswith(".vdb"))
                or (name.startswith("spines_") and name.endswith(".npz"))
                or name == MANIFEST_NAME or name.endswith(".tmp")):
            os.remove(os.path.join(folder, name))


def write_manifest(snap, result):
    data = {"format_version": FORMAT_VERSION, "kind": "flames",
            "frame_start": snap.frame_start, "frame_end": snap.frame_end,
            "last_complete_frame": result.last_frame, "seed": snap.seed,
            "substeps": snap.substeps, "sources": [s.name for s in snap.sources],
            "settings": asdict(snap.settings[0]),
            # per baked frame: live flames and rendered particles (for scripts and the UI)
            "flames": list(result.flames), "particles": list(result.particles)}
    files.write_manifest(snap.folder, data, MANIFEST_NAME)


def read_manifest(folder):
    """The manifest dict, or None when missing or unreadable."""
    return files.read_manifest(folder, "flames", MANIFEST_NAME)


SPINE_ARRAYS = ("ids", "sources", "separated", "counts", "points", "light_ids", "light_centres",
                "light_radii", "light_energy", "light_colors")
#: What the smoke of §6.3 needs besides (flame_smoke.py); absent from caches of older versions:
#: the points' velocities (Σ counts, 3), each flame's radius r and its buoyancy lift (eq. 2).
SMOKE_ARRAYS = ("velocities", "radii", "lifts")


def buoyancy_lift(flame, params):
    """The upward acceleration of eq. 2 for a flame, m/s²: β |g| (T_p − T_0), the reading of
    evolution.h (the velocity c = β |g| (T_p − T_0) t_p grows at this rate)."""
    g = float(np.linalg.norm(params.gravity))
    return params.buoyancy * g * (flame["temperature"] - params.ambient_temperature)


def write_spines(path, flames, lights, params):
    """spines_####.npz: per flame its id, source, separated flag and point count, the points
    (Σ counts, 3) float32 base to tip and their velocities, its radius r and the lift of eq. 2
    under FlameParams `params`; per light (§5.2) its flame id, centre, radius h/3, energy
    (eq. 5 × intensity) and colour."""
    pts = [np.asarray(f["points"], np.float32).reshape(-1, 3) for f in flames]
    vel = [np.asarray(f["velocities"], np.float32).reshape(-1, 3) for f in flames]
    files.save_npz(path, ids=np.asarray([f["id"] for f in flames], np.uint32),
                   sources=np.asarray([f["source"] for f in flames], np.int32),
                   separated=np.asarray([f["separated"] for f in flames], bool),
                   counts=np.asarray([len(p) for p in pts], np.int32),
                   points=(np.concatenate(pts) if pts else np.zeros((0, 3), np.float32)),
                   velocities=(np.concatenate(vel) if vel else np.zeros((0, 3), np.float32)),
                   radii=np.asarray([f["radius"] for f in flames], np.float32),
                   lifts=np.asarray([buoyancy_lift(f, params) for f in flames], np.float32),
                   light_ids=np.asarray([li["flame_id"] for li in lights], np.uint32),
                   light_centres=np.asarray([li["centre"] for li in lights],
                                            np.float32).reshape(-1, 3),
                   light_radii=np.asarray([li["radius"] for li in lights], np.float32),
                   light_energy=np.asarray([li["energy"] for li in lights], np.float32),
                   light_colors=np.asarray([li["color"] for li in lights],
                                           np.float32).reshape(-1, 3))


def read_spines(path):
    """The arrays of a spines file (SMOKE_ARRAYS too when present); OSError or ValueError when it
    cannot be read or its sizes disagree (checked, never trusted)."""
    try:
        with np.load(path, allow_pickle=False) as data:
            d = {k: np.array(data[k]) for k in SPINE_ARRAYS}
            d.update({k: np.array(data[k]) for k in SMOKE_ARRAYS if k in data.files})
    except KeyError as e:
        raise ValueError(f"{path}: no {e} array") from None
    except zipfile.BadZipFile as e:
        raise ValueError(f"{path}: {e}") from None
    k, m = len(d["ids"]), len(d["light_ids"])
    if (any(len(d[a]) != k for a in ("sources", "separated", "counts"))
            or d["points"].shape != (int(d["counts"].sum()), 3) or np.any(d["counts"] < 0)
            or d["light_centres"].shape != (m, 3) or d["light_colors"].shape != (m, 3)
            or len(d["light_radii"]) != m or len(d["light_energy"]) != m
            or ("velocities" in d and d["velocities"].shape != d["points"].shape)
            or any(a in d and d[a].shape != (k,) for a in ("radii", "lifts"))):
        raise ValueError(f"{path}: arrays of mismatched sizes")
    return d
