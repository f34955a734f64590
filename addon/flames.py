"""Structural flames bake, no ``bpy`` ([Structural Flames]): the bake loop over a scene's
Flame Sources (settings and validation in flame_settings, cache files in flame_files).

    snap = snapshot.flames.flames_snapshot(context)          # bpy side: FlameBakeSnapshot
    runner = FlameBakeRunner(native, snap)            # BakeError on bad input, nothing written
    result = runner.run()                             # <folder>/flames_####.vdb, spines_####.npz

Every frame: the sources follow their objects (position, and velocity V from the motion between
frames, §4.2), the wind is rebuilt (§4.2, §6, §6.1), the FlameSystem steps `substeps` times
(§4.1-4.3), the FlameShaper samples the flames for the scene camera (§4.4-4.5, §5), and the
particles are rasterized into a VDB (density, temperature, flame, color, velocity: eq. 1 plus
an attached flame's carriage by its source, for motion blur, add_carried_velocity); the spines
and the lights (§5.2) go to an .npz. Files are written to a temporary name and renamed, so a
cancelled or killed bake never leaves a half file.
"""

import os
import time
from dataclasses import dataclass, field
from typing import Callable, List, Optional

import numpy as np

from . import flame_palettes
from .settings import BakeError
from .ui_words import in_ui_words
# The settings, validation and files of a flames bake, also reachable as flames.<name>.
from .flame_files import (SMOKE_ARRAYS, SPINE_ARRAYS, buoyancy_lift, clear_folder,
                          read_manifest, read_spines, remove_frames_above, write_manifest,
                          write_spines)
from .flame_settings import (FIXED_PARTICLES, FLAMES_PER_SOURCE_RANGE, FORMAT_VERSION,
                             MANIFEST_NAME, NO_SOURCE, OBSTACLE_PADDING, OBSTACLE_VOXEL,
                             POINTS_RANGE, PROFILES, SUBSTEPS_RANGE, CameraInput,
                             FlameBakeSnapshot, FlameSettings, FlameSourceInput, ObstacleInput,
                             WindInput, spines_path, validate_settings, validate_snapshot,
                             validate_source_values, volume_path)

__all__ = ["SMOKE_ARRAYS", "SPINE_ARRAYS", "buoyancy_lift", "clear_folder", "read_manifest",
           "remove_frames_above",
           "read_spines", "write_manifest", "write_spines", "FIXED_PARTICLES",
           "FLAMES_PER_SOURCE_RANGE", "FORMAT_VERSION", "MANIFEST_NAME", "NO_SOURCE",
           "OBSTACLE_PADDING", "OBSTACLE_VOXEL", "POINTS_RANGE", "PROFILES", "SUBSTEPS_RANGE",
           "CameraInput", "FlameBakeSnapshot", "FlameSettings", "FlameSourceInput",
           "ObstacleInput", "WindInput", "spines_path", "validate_settings", "validate_snapshot",
           "validate_source_values", "volume_path", "FlameNative", "add_carried_velocity",
           "shape_key", "FlameBakeResult", "FlameBakeRunner"]


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
        p.spine_noise_amplitude = float(s.spine_noise)  # §4.2 Kolmogorov velocity
        p.spine_noise_scale = float(s.spine_noise_scale)
        p.spine_noise_frequency = float(s.spine_noise_frequency)
        p.spine_noise_drift = tuple(float(v) for v in s.spine_noise_drift)
        p.validate()
        return p

    def shaper(self, s: FlameSettings, profiles, images, has_camera):
        """The FlameShaper of settings `s` (§4.4-5.2); ValueError on bad settings. Without a
        scene camera every flame gets FIXED_PARTICLES samples."""
        return self.n.FlameShaper(
            profiles, images=images, seed=int(self.snap.seed),
            particles_per_pixel=float(s.particles_per_pixel), max_particles=int(s.max_particles),
            fixed_count=0 if has_camera else FIXED_PARTICLES,
            flow_noise_amplitude=float(s.flow_noise), flow_noise_scale=float(s.flow_noise_scale),
            flow_noise_frequency=float(s.flow_noise_frequency),
            flow_noise_rotation=float(s.flow_noise_rotation),
            kolmogorov_amplitude=float(s.kolmogorov), kolmogorov_scale=float(s.kolmogorov_scale),
            kolmogorov_frequency=float(s.kolmogorov_frequency),
            kolmogorov_drift=tuple(float(v) for v in s.kolmogorov_drift),
            heat_of_combustion=float(s.heat_of_combustion) * 1e6, merging=bool(s.merging),
            temperature=float(s.temperature_scale), cooling_time=float(s.lifespan_scale))

    def profile(self, src: FlameSourceInput):
        if src.profile == 'CUSTOM':
            return self.n.FlameProfile.from_curve(np.asarray(src.profile_points, np.float64))
        return self.n.FlameProfile.library(src.profile.lower())

    @staticmethod
    def color_image(src: FlameSourceInput):
        """§5.1: (h, w, 3) float32 rows from the bottom: the Colour Image, the profile's palette
        (flame_palettes), or an empty (0, 0, 3) image: the blackbody of each particle's
        temperature."""
        if src.color_source == 'IMAGE' and src.color_image is not None:
            return np.ascontiguousarray(src.color_image[..., :3], np.float32)
        if src.color_source == 'BLACKBODY':
            return np.zeros((0, 0, 3), np.float32)
        return flame_palettes.palette_image(src.profile)


def shape_key(s: FlameSettings):
    """The settings the FlameShaper is built from: a change rebuilds it."""
    return (s.particles_per_pixel, s.max_particles, s.merging, s.flow_noise, s.flow_noise_scale,
            s.flow_noise_frequency, s.flow_noise_rotation, s.kolmogorov, s.kolmogorov_scale,
            s.kolmogorov_frequency, tuple(s.kolmogorov_drift), s.heat_of_combustion,
            s.temperature_scale, s.lifespan_scale)


#: The motion blur the velocity grid is made for: a shutter of one frame (Blender's default 0.5
#: frame, and up to 1), and at most this many metres (a runaway particle must not grow the grid).
BLUR_SHUTTER_FRAMES, BLUR_MAX_REACH = 1.0, 2.0


def blur_reach(shaped, fps):
    """How far (m) the velocity grid must reach past the flames for Cycles to blur their outline
    (fields/velocity_extend.h): the fastest particle's travel over a shutter of one frame."""
    v = np.asarray(shaped["velocities"], np.float64)
    if len(v) == 0:
        return 0.0
    fastest = float(np.sqrt((v * v).sum(axis=1).max()))
    return min(BLUR_MAX_REACH, fastest * BLUR_SHUTTER_FRAMES / float(fps))


def add_carried_velocity(shaped, live, source_velocities):
    """The motion-blur velocity of the flame particles (the VDB's `velocity` grid, §5.3). The
    core gives each particle eq. 1's velocity of its spine, in the world frame: for a flame
    attached to a source moving at V that is w + c (still air: buoyancy only), because the
    V_p = -V of eq. 1 cancels the source carrying the flame frame along (§4.2). That is how the
    gas moves, but an attached flame's shape is re-emitted at the source every step and moves
    with it: a torch swung at 4 m/s moves its flames at 4 m/s, which the blur must show. So
    particles of attached flames get their source's V added (nothing changes for still sources
    or separated flames, which drift freely with eq. 1). In place; `live` is
    FlameSystem.flames(), `source_velocities` V (m/s) per system source."""
    v = np.asarray(shaped["velocities"])
    if v.size == 0 or not np.any(source_velocities):
        return
    carried = np.zeros((len(live), 3), v.dtype)
    for f, flame in enumerate(live):
        if not flame["separated"]:
            carried[f] = source_velocities[flame["source"]]
    shaped["velocities"] = v + carried[np.asarray(shaped["flame"], np.intp)]


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
                    raise BakeError(f"Plume: Flame Source '{src.name}': "
                                    f"{in_ui_words('flame_source', str(e))}") from None
                self.profiles += [prof] * src.count
                self.images += [img] * src.count
            for i, s in enumerate(snap.settings):  # every keyed shape setting is valid
                if i == 0 or shape_key(s) != shape_key(snap.settings[i - 1]):
                    self.build.shaper(s, self.profiles[:1], None, True)
            self._check_sources()
            self.obstacles = [native.GridSdf(**native.mesh_signed_distance(
                o.vertices, o.triangles, OBSTACLE_VOXEL, padding=OBSTACLE_PADDING, name=o.name))
                for o in snap.obstacles]
        except ValueError as e:
            raise BakeError(f"Plume: Flames: {in_ui_words('flames', str(e))}") from None

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
                                        f"{self.snap.frame_start + i}): "
                                        f"{in_ui_words('flame_source', str(e))}") from None

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
        r, intensity, temp, stops = src.values[index]
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
        fs.brightness = 2.0 ** float(stops)
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
                sources = [self._source_at(src, k, i, alpha, dt_frame)
                           for src in snap.sources for k in range(src.count)]
                for j, fs in enumerate(sources):
                    system.set_source(j, fs)
                system.step(dt)
            t1 = time.perf_counter()
            has_camera = snap.cameras[i] is not None
            if shaper is None or (shape_key(s), has_camera) != key:
                shaper = self.build.shaper(s, self.profiles, self.images, has_camera)
                shaper.set_obstacles(self.obstacles)  # §6.1: the system's own SDFs, shared
                key = (shape_key(s), has_camera)
            live = system.flames()
            shaped = shaper.shape(live, system.time, self._camera(i))
            add_carried_velocity(shaped, live, [fs.velocity for fs in sources])
            t2 = time.perf_counter()
            n.write_flames_vdb(volume_path(snap.folder, frame), shaped,
                               voxel_size=float(s.voxel_size),
                               temperature_scale=float(s.temperature_scale),
                               light_unit=float(s.light_unit), opacity=float(s.opacity),
                               blur_reach=blur_reach(shaped, snap.fps), frame=frame)
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
