"""Plain-Python bake settings: the snapshot dataclasses, their validation and their conversion to
``plume._native.SmokeParams``.  No ``bpy`` here: the snapshot module fills these from the scene,
the bake runner consumes them (possibly on a worker thread)."""

import dataclasses
import hashlib
import math
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

import numpy as np

from .ranges import RANGES

#: Accepted range of the domain's resolution (cells along the longest axis); the native
#: SmokeParams.validate() applies the same bound per axis.
RESOLUTION_RANGE = RANGES["resolution"]

#: Order of the six boundary sides, as in SmokeParams.boundaries.
BOUNDARY_SIDES = ("neg_x", "pos_x", "neg_y", "pos_y", "neg_z", "pos_z")

#: Settings that change nothing in the result (bit-identical at any thread count), so a bake may
#: resume across them.
RESULT_NEUTRAL_FIELDS = ("threads",)


class BakeError(Exception):
    """Bad input found before anything was written; the message names the setting or object."""


@dataclass
class SolverSettings:
    """Mirror of ``_native.SmokeParams`` (same snake_case names); enums stored by name."""

    resolution: Tuple[int, int, int] = (32, 32, 32)
    cell_size: float = 1.0 / 32.0
    origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    boundaries: Tuple[str, ...] = ("OPEN", "OPEN", "OPEN", "OPEN", "CLOSED", "OPEN")
    adaptive_domain: bool = False
    adaptive_margin: int = 6
    adaptive_threshold: float = 0.005
    frame_dt: float = 1.0 / 24.0
    substeps: int = 1
    use_cfl: bool = True
    cfl: float = 4.0
    advection: str = "BFECC"
    interpolation: str = "MONOTONIC_CUBIC"
    linear_velocity: bool = True
    trace: str = "MIDPOINT"
    conserve_mass: bool = True
    gravity: Tuple[float, float, float] = (0.0, 0.0, -9.81)
    alpha: float = 1.0
    beta: float = 1.0
    ambient_temperature: float = 0.0
    wind: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    wind_strength: float = 0.0
    vorticity: float = 0.2
    density_dissipation: float = 0.0
    turbulence: float = 2.0
    turbulence_scale: float = 0.4
    turbulence_rate: float = 0.5
    pressure_tolerance: float = 1e-4
    max_pressure_iterations: int = 200
    combustion: bool = False
    burn_rate: float = 1.5
    soot_yield: float = 0.5
    heat_yield: float = 6.0
    conductivity: float = 0.0
    cooling_rate: float = 8.0
    max_temperature: float = 3.0
    expansion: float = 3.0
    flame_vorticity: float = 24.0
    seed: int = 0
    threads: int = 0


@dataclass
class SourceParams:
    """Mirror of ``_native.SourceSettings``, plus the tracer's emission switch."""

    density: float = 1.0
    temperature: float = 1.0
    fuel: float = 0.0
    velocity: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    motion_factor: float = 1.0
    fuel_noise: float = 0.8
    fuel_noise_scale: float = 0.08
    fuel_noise_rate: float = 3.0
    smoke_noise: float = 0.5
    smoke_noise_scale: float = 0.08
    smoke_noise_rate: float = 2.0
    #: §3.2 / Figure 10: the source's point sources emit particles (not a solver setting).
    emit_particles: bool = True

    def for_solver(self):
        """The settings the solver reads (emit_particles set to its default)."""
        return dataclasses.replace(self, emit_particles=True)


@dataclass
class EmitterSnapshot:
    """One source or obstacle: object-local triangles and its world matrix per frame."""

    name: str
    role: str  # 'SOURCE' or 'OBSTACLE'
    vertices: np.ndarray  # float32 (N, 3)
    triangles: np.ndarray  # int32 (M, 3)
    #: 4x4 row-major matrices for frames frame_start .. frame_end + 1 (one entry when static).
    matrices: List[np.ndarray]
    source: Optional[SourceParams] = None
    #: Keyframed or driven source settings: the values at frames frame_start .. frame_end (source
    #: holds the first); empty when they are constant.
    source_frames: List[SourceParams] = field(default_factory=list)
    slip: str = "NO_SLIP"
    #: streak surfaces: where the point sources are (§3.2): "RIM", a ring around the outline
    #: (point_rim.py), or "CELLS", point_sources random points per source cell
    point_placement: str = "RIM"
    point_sources: int = 16  # streak surfaces: tracer point sources per source cell (§3.2)
    candidate_group: int = -1  # §3.3 candidate group, -1: the source's own group
    candidate_split: int = 1  # §3.3: the source's point sources split into this many groups
    #: §3.2 "the vertices of a mesh the user picks": that mesh's name and its vertices in world
    #: space at frame_start, float32 (N, 3); None: `point_sources` random points per cell.
    point_source_mesh: str = ""
    point_source_vertices: Optional[np.ndarray] = None
    #: §3.3 hand-made candidate groups: per point-source-mesh vertex, the index of the vertex group
    #: it belongs to most (-1: none), int64 (N,); None when the mesh has no vertex groups.
    point_source_groups: Optional[np.ndarray] = None
    point_source_group_names: List[str] = field(default_factory=list)  # by vertex group index

    @property
    def hand_groups(self):
        """Number of hand-made candidate groups (vertex groups used, plus one for the vertices in
        none), 0 without vertex groups."""
        if self.point_source_groups is None or self.point_source_vertices is None:
            return 0
        return len(np.unique(self.point_source_groups))

    @property
    def animated(self):
        return len(self.matrices) > 1

    def matrix_at(self, index):
        """Matrix at frame frame_start + index (static emitters have a single matrix)."""
        return self.matrices[min(index, len(self.matrices) - 1)]

    def source_at(self, index):
        """Source settings at frame frame_start + index (None for an obstacle)."""
        if self.source_frames:
            return self.source_frames[min(index, len(self.source_frames) - 1)]
        return self.source

    def solver_inputs(self, index):
        """What the solver's copy of this emitter is made from at frame frame_start + index: the
        frame of its matrices and its solver settings; a change means voxelizing it again."""
        source = self.source_at(index)
        return (min(index, len(self.matrices) - 1),
                source.for_solver() if source is not None else None)

    def mesh_hash(self):
        """Hash of the geometry that ignores the order of the triangles (Blender's primitives do
        not list their faces in the same order from one session to the next)."""
        tris = np.asarray(self.triangles, dtype=np.int32).reshape(-1, 3)
        if len(tris):
            # Rotate each triangle to start at its smallest index (keeps its winding), then sort.
            first = np.argmin(tris, axis=1)
            rows = np.arange(len(tris))[:, None]
            tris = tris[rows, (first[:, None] + np.arange(3)) % 3]
            tris = tris[np.lexsort(tris.T[::-1])]
        h = hashlib.sha1()
        h.update(np.ascontiguousarray(self.vertices, dtype=np.float32).tobytes())
        h.update(np.ascontiguousarray(tris, dtype=np.int32).tobytes())
        return h.hexdigest()

    def streak_fingerprint(self):
        """The source's streak settings as JSON-friendly data (the manifest compares it); the
        newer settings only when not default, so older caches still resume."""
        data = [self.name, self.point_sources, self.candidate_group]
        extra = {}
        if self.point_placement != "CELLS":  # caches from before the rim were per cell
            extra["point_placement"] = self.point_placement
        if self.candidate_split != 1:
            extra["candidate_split"] = self.candidate_split
        if self.point_source_vertices is not None:
            v = np.ascontiguousarray(self.point_source_vertices, dtype=np.float32)
            extra["point_source_mesh"] = [self.point_source_mesh,
                                          hashlib.sha1(v.tobytes()).hexdigest()]
        if self.hand_groups:
            g = np.ascontiguousarray(self.point_source_groups, dtype=np.int64)
            extra["hand_groups"] = hashlib.sha1(g.tobytes()).hexdigest()
        return data + [extra] if extra else data

    def fingerprint(self):
        """Everything but the motion, as JSON-friendly data (the manifest compares it)."""
        data = {"name": self.name, "role": self.role, "mesh": self.mesh_hash()}
        if self.role == "SOURCE":
            data["source"] = dataclasses.asdict(self.source)
            if data["source"]["emit_particles"]:  # the default: as older caches stored it
                del data["source"]["emit_particles"]
        else:
            data["slip"] = self.slip
        return data


#: Accepted ranges of the streak settings (ranges.py).
EMISSION_PERIOD_RANGE = RANGES["emission_period"]
MAX_STREAKLINES_RANGE = RANGES["max_streaklines"]
POINT_SOURCES_RANGE = RANGES["point_sources"]
CANDIDATE_SPLIT_RANGE = RANGES["candidate_split"]


@dataclass
class StreakSettings:
    """Streak surfaces ([Smoke Surfaces] §3.2): tracers from point sources during the bake."""

    enabled: bool = False
    emission_period: int = 1  # steps between two emissions
    #: at most this many streaklines over all Sources (point sources thinned at random), 0: all
    max_streaklines: int = 256


#: Accepted range of the pathline settings (ranges.py).
NODES_PER_FRAME_RANGE = RANGES["pathline_nodes_per_frame"]


@dataclass
class PathlineSettings:
    """Pathline groups of a fire bake for flow-graph fire ([Graph Fire Synthesis] §4.2): one
    group per node step Δt_n = frame / nodes_per_frame, sampled over lifetime t_max seconds."""

    enabled: bool = False
    nodes_per_frame: int = 4
    lifetime: float = 1.0  # t_max (s)
    float16: bool = False  # half-precision samples in pathlines.bin


@dataclass
class BakeSnapshot:
    """Everything a bake needs, taken on the main thread before the worker starts."""

    domain_name: str
    resolution: int  # cells along the longest axis (the artist's setting)
    frame_start: int
    frame_end: int
    cache_directory: str  # as typed by the artist (for messages)
    cache_folder: str  # absolute: <cache_directory>/<domain name>
    solver: SolverSettings = field(default_factory=SolverSettings)
    emitters: List[EmitterSnapshot] = field(default_factory=list)
    addon_version: str = "0.1.0"
    streaks: StreakSettings = field(default_factory=StreakSettings)
    #: motion_source 'MANTAFLOW': the Mantaflow domain to trace (mantaflow_cache.MantaflowSource);
    #: None: Plume simulates.
    mantaflow: Optional[object] = None
    pathlines: PathlineSettings = field(default_factory=PathlineSettings)
    #: flame_smoke.FlameSmokeSettings: smoke from the flames cache ([Structural Flames] §6.3)
    flame_smoke: Optional[object] = None
    #: velocity in every cell of the frame VDBs (a flames Wind Domain, [Structural Flames] §6.1)
    velocity_everywhere: bool = False

    @property
    def frame_count(self):
        return self.frame_end - self.frame_start + 1

    def settings_dict(self):
        """Result-relevant settings, as stored in manifest.json and compared on resume."""
        solver = dataclasses.asdict(self.solver)
        for name in RESULT_NEUTRAL_FIELDS:
            solver.pop(name, None)
        if not solver["adaptive_domain"]:
            # Off, the adaptive settings change nothing: caches baked before they existed resume.
            for name in ("adaptive_domain", "adaptive_margin", "adaptive_threshold"):
                solver.pop(name)
        solver["resolution"] = list(solver["resolution"])
        solver["origin"] = list(solver["origin"])
        solver["boundaries"] = list(solver["boundaries"])
        for key in ("gravity", "wind"):
            solver[key] = list(solver[key])
        data = {
            "domain_resolution": self.resolution,
            "frame_start": self.frame_start,
            "solver": solver,
            "emitters": [e.fingerprint() for e in self.emitters],
        }
        if self.streaks.enabled:  # absent when off, so older caches still resume
            data["streaks"] = {
                "emission_period": self.streaks.emission_period,
                "max_streaklines": self.streaks.max_streaklines,
                "sources": [e.streak_fingerprint() for e in self.emitters if e.role == "SOURCE"]}
        if self.pathlines.enabled:  # absent when off, so older caches still resume
            data["pathlines"] = dataclasses.asdict(self.pathlines)
        if self.flame_smoke is not None and self.flame_smoke.enabled:  # absent when off
            data["flame_smoke"] = self.flame_smoke.fingerprint()
        if self.velocity_everywhere:  # absent when off, so older caches still resume
            data["velocity_everywhere"] = True
        return data

    def frame_input_hash(self, frame):
        """Hash of the emitter matrices that drive frame `frame` (matrices at frame and frame+1)
        and of the keyframed source settings at `frame` (constant ones are in settings_dict)."""
        index = frame - self.frame_start
        h = hashlib.sha1()
        for emitter in self.emitters:
            for m in (emitter.matrix_at(index), emitter.matrix_at(index + 1)):
                h.update(np.ascontiguousarray(m, dtype=np.float64).tobytes())
        for emitter in self.emitters:
            if emitter.source_frames:
                s = emitter.source_at(index)
                h.update(np.array([s.density, s.temperature, s.fuel, *s.velocity,
                                   s.motion_factor, s.emit_particles], dtype=np.float64).tobytes())
        if self.flame_smoke is not None and self.flame_smoke.enabled:  # the flames of `frame`
            h.update(self.flame_smoke.frame_bytes(index))
        return h.hexdigest()


def physical_buoyancy(alpha, beta, units, longest_side):
    """(α, β) for the solver, f = -g (α ρ + β (T - T_amb)), from the domain's α and β in `units`:
    'PHYSICAL' as they are; 'MANTAFLOW' as Mantaflow's Density and Heat, divided by the domain's
    longest side L in metres. Mantaflow's smoke script calls addBuoyancy(gravity=g_grid,
    coefficient=α / L, scale=False), its velocity step Δu = -g_grid Δt α/L ρ in cells per its
    time unit, with g_grid = g (res / L) (1 s / 2.5 time units)²; back in metres and seconds
    (u = u_grid (L / res) 2.5) the acceleration is g α ρ / L, independent of the resolution."""
    if units == 'PHYSICAL':
        return float(alpha), float(beta)
    if units != 'MANTAFLOW':
        raise BakeError(f"Buoyancy Units must be Physical or Mantaflow (got {units!r})")
    if not longest_side > 0.0:
        raise BakeError(f"the domain's longest side must be > 0 m (got {longest_side})")
    return float(alpha) / longest_side, float(beta) / longest_side


def domain_grid(bbox_min, bbox_max, resolution):
    """Cells per axis, cell size and origin of a domain box: the
    longest axis gets `resolution` cells, the others round(dim / cell_size), at least 2."""
    dims = [float(b) - float(a) for a, b in zip(bbox_min, bbox_max)]
    longest = max(dims)
    if not (longest > 0.0) or not math.isfinite(longest):
        raise BakeError("Plume: the domain has no volume (its bounding box is flat)")
    cell_size = longest / resolution
    cells = tuple(max(2, int(round(d / cell_size))) for d in dims)
    return cells, cell_size, tuple(float(a) for a in bbox_min)


def validate_python_side(domain_name, resolution, frame_start, frame_end, solver):
    """Rules the native validate() cannot see (it would fail later or less clearly)."""
    lo, hi = RESOLUTION_RANGE
    if not (lo <= resolution <= hi):
        raise BakeError(
            f"Plume: domain '{domain_name}': resolution must be in [{lo}, {hi}] cells along the "
            f"longest axis (got {resolution})")
    if frame_end < frame_start:
        raise BakeError(
            f"Plume: domain '{domain_name}': frame_end must not be before frame_start (got "
            f"{frame_end} < {frame_start})")
    for name, value in dataclasses.asdict(solver).items():
        values = value if isinstance(value, (tuple, list)) else (value,)
        for v in values:
            if isinstance(v, float) and not math.isfinite(v):
                raise BakeError(
                    f"Plume: domain '{domain_name}': {name} must be a finite number (got {v})")
    if solver.substeps < 1:
        raise BakeError(
            f"Plume: domain '{domain_name}': substeps must be at least 1 (got {solver.substeps})")


def validate_source(emitter, frame_start=None):
    """Finite, non-negative amounts on a source, on every frame when they are keyframed (the
    message names the frame; frame_start is the bake's first frame)."""
    frames = emitter.source_frames or [emitter.source]
    for index, s in enumerate(frames):
        at = (f" at frame {frame_start + index}"
              if emitter.source_frames and frame_start is not None else "")
        for name in ("density", "temperature", "fuel", "motion_factor"):
            v = getattr(s, name)
            if not math.isfinite(v):
                raise BakeError(f"Plume: source '{emitter.name}': {name} must be a finite number "
                                f"(got {v}{at})")
        for name in ("density", "fuel"):
            v = getattr(s, name)
            if v < 0.0:
                raise BakeError(
                    f"Plume: source '{emitter.name}': {name} must be >= 0 (got {v}{at})")
        if not all(math.isfinite(v) for v in s.velocity):
            raise BakeError(f"Plume: source '{emitter.name}': velocity must be finite "
                            f"(got {tuple(s.velocity)}{at})")


def validate_pathlines(domain_name, pathlines, solver, streaks, emitters, bake_frames=None):
    """Pathline recording ([Graph Fire Synthesis] §4.2) needs a fire bake with fuel sources,
    lasting long enough (bake_frames) for groups to complete their lifetime."""
    if not pathlines.enabled:
        return
    owner = f"Plume: domain '{domain_name}'"
    if not solver.combustion:
        raise BakeError(f"{owner}: pathlines are recorded from a fire bake: turn on combustion "
                        "or turn pathlines off")
    if streaks.enabled:
        raise BakeError(f"{owner}: pathlines and streak surfaces cannot be recorded in one bake: "
                        "turn one of them off")
    lo, hi = NODES_PER_FRAME_RANGE
    if not (lo <= pathlines.nodes_per_frame <= hi):
        raise BakeError(f"{owner}: pathline_nodes_per_frame must be in [{lo}, {hi}] "
                        f"(got {pathlines.nodes_per_frame})")
    if not (math.isfinite(pathlines.lifetime) and 0.0 < pathlines.lifetime <= 60.0):
        raise BakeError(f"{owner}: pathline_lifetime (t_max) must be in (0, 60] s "
                        f"(got {pathlines.lifetime})")
    frames = bake_frames if bake_frames is not None else 0
    seconds = frames * solver.frame_dt
    if bake_frames is not None and seconds < 2.0 * pathlines.lifetime:
        raise BakeError(f"{owner}: the bake ({frames} frames, {seconds:.2f} s) must last at least "
                        f"twice the pathline lifetime t_max ({pathlines.lifetime:g} s), so that "
                        "pathline groups complete over half of it: bake more frames or shorten "
                        "pathline_lifetime")
    if not any(e.role == "SOURCE" and e.source.fuel > 0.0 for e in emitters):
        raise BakeError(f"{owner}: pathlines are seeded in the fuel-injection region: give a "
                        "Source fuel > 0")


def validate_streaks(domain_name, streaks, emitters):
    """Streak settings of a bake with streak surfaces on ([Smoke Surfaces] §3.2)."""
    if not streaks.enabled:
        return
    lo, hi = EMISSION_PERIOD_RANGE
    if not (lo <= streaks.emission_period <= hi):
        raise BakeError(f"Plume: domain '{domain_name}': emission_period must be in [{lo}, {hi}] "
                        f"steps (got {streaks.emission_period})")
    lo, hi = MAX_STREAKLINES_RANGE
    if not (lo <= streaks.max_streaklines <= hi) or streaks.max_streaklines == 1:
        raise BakeError(f"Plume: domain '{domain_name}': max_streaklines must be 0 (no limit) or "
                        f"in [2, {hi}] (got {streaks.max_streaklines})")
    sources = [e for e in emitters if e.role == "SOURCE"]
    if not sources:
        raise BakeError(f"Plume: domain '{domain_name}': streak surfaces need at least one Source "
                        "object (its cells hold the point sources)")
    lo, hi = POINT_SOURCES_RANGE
    split_lo, split_hi = CANDIDATE_SPLIT_RANGE
    for e in sources:
        # Unused (and not checked) when a point source mesh gives the points.
        if (e.point_source_vertices is None and e.point_placement == "CELLS"
                and not (lo <= e.point_sources <= hi)):
            raise BakeError(f"Plume: source '{e.name}': point_sources must be in [{lo}, {hi}] "
                            f"(got {e.point_sources})")
        if not (split_lo <= e.candidate_split <= split_hi):
            raise BakeError(f"Plume: source '{e.name}': candidate_split must be in [{split_lo}, "
                            f"{split_hi}] candidate groups (got {e.candidate_split})")
        if e.candidate_group < -1:
            raise BakeError(f"Plume: source '{e.name}': candidate_group must be >= -1 "
                            f"(-1 = its own group; got {e.candidate_group})")


def candidate_groups(emitters, counts=None):
    """Candidate group of each Source (§3.3), in source order: the explicit group, or for -1 a
    number of its own that no explicit group uses. A source split in k > 1 groups
    (candidate_split, k hand-made groups: the vertex groups of its point source mesh, or `counts`
    [i] for the i-th Source when given: a rim's arcs) gets the first of k consecutive numbers,
    all after every other source's group (its candidate_group is then unused)."""
    sources = [e for e in emitters if e.role == "SOURCE"]
    split = dict(zip(map(id, sources), counts)) if counts is not None else {}

    def _group_count(e):
        return split.get(id(e)) or e.hand_groups or e.candidate_split

    whole = [e for e in sources if _group_count(e) <= 1]
    used = {e.candidate_group for e in whole if e.candidate_group >= 0}
    groups, next_free = [], 0
    for e in sources:
        if _group_count(e) > 1:
            groups.append(None)  # numbered below, once every other group is known
        elif e.candidate_group >= 0:
            groups.append(e.candidate_group)
        else:
            while next_free in used:
                next_free += 1
            used.add(next_free)
            groups.append(next_free)
    next_split = max(used, default=-1) + 1
    for n, e in enumerate(sources):
        if groups[n] is None:
            groups[n] = next_split
            next_split += _group_count(e)
    return groups

