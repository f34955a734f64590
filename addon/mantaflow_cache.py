"""A Blender 3.4 Mantaflow gas cache as a streak bake reads it, no ``bpy``: which files a
frame range needs, the per-frame config, and the world placement of the grid.

Layout (cache_data_format 'OPENVDB'; 'MODULAR', 'REPLAY' and 'ALL' caches alike)::

    <cache_directory>/config/config_####.uni   gzip, fluid.cc MANTA::writeConfiguration: fields,
                                               res, dx, dt, p0, p1, dp0, shift, obj_shift_f,
                                               obmat, base_res, res_min, res_max, colour,
                                               time_total (Mantaflow time units), version
    <cache_directory>/data/fluid_data_####.vdb  density, velocity (staggered), temperature,
                                               flame, shadow (native/io/mantaflow_cache.h)

Frame f holds the state after simulating up to frame f: its time_total is (f - cache_frame_start
+ 1) frame lengths, one frame length being 0.1 * 25 / fps * time_scale time units, one second
2.5 time units. The state before cache_frame_start is an empty domain (no smoke, no motion).

Placement: the base_res cells fill the domain mesh's local bounding box p0..p1 (cell size
(p1 - p0) / base_res per axis, not cubic) under the object matrix obmat. An adaptive domain
(res != base_res or a shifted sub-box) and a rotated, mirrored or moving domain are refused.
"""

import gzip
import math
import os
import struct
import zlib
from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

from .settings import BakeError

#: fluid.cc writeConfiguration, up to and including time_total (a 4-character version follows).
_CONFIG = struct.Struct("<i3i2f3f3f3f3i3f16f3i3i3i3ff")
#: Larger config files are not Blender's (the real one is 204 bytes).
_CONFIG_MAX_BYTES = 4096
#: Relative tolerance when comparing frames' placements and matrices.
_TOLERANCE = 1e-5
#: Mantaflow time units per second (fluid_script.h: frameLengthRaw = 0.1 * 25).
TIME_UNITS_PER_SECOND = 2.5
#: Sides in SmokeParams.boundaries order and the Blender border collision setting of each.
BORDER_SETTINGS = ("use_collision_border_left", "use_collision_border_right",
                   "use_collision_border_front", "use_collision_border_back",
                   "use_collision_border_bottom", "use_collision_border_top")

#: Where Blender's own fluid settings are.
FLUID = "Physics Properties › Fluid"


@dataclass
class MantaflowSource:
    """The Mantaflow domain a streak bake traces (motion_source 'MANTAFLOW'), from the scene."""

    domain_name: str  # the Plume domain, for messages
    object_name: str = ""  # mantaflow_domain; "" when not set
    is_gas_domain: bool = False
    cache_directory: str = ""  # absolute
    cache_data_format: str = "OPENVDB"
    cache_frame_start: int = 1
    cache_frame_end: int = 250
    use_adaptive_domain: bool = False
    borders_closed: Tuple[bool, ...] = (False,) * 6  # -x, +x, -y, +y, -z, +z
    fps: float = 24.0
    time_scale: float = 1.0

    def fingerprint(self):
        """What the trace depends on, for the manifest."""
        return {"object": self.object_name, "cache_directory": self.cache_directory,
                "borders_closed": list(self.borders_closed)}


@dataclass
class MantaflowConfig:
    """One config_####.uni."""

    res: Tuple[int, int, int]
    p0: np.ndarray
    p1: np.ndarray
    shift: Tuple[int, int, int]
    obmat: np.ndarray  # 4x4 row-major, world = obmat @ [x, y, z, 1]
    base_res: Tuple[int, int, int]
    res_min: Tuple[int, int, int]
    res_max: Tuple[int, int, int]
    time_total: float


@dataclass
class MantaflowPlan:
    """What a trace of frames frame_start..frame_end reads: the grid, the data file of every
    frame (None: the empty state before the cache) and the length of each traced frame."""

    resolution: Tuple[int, int, int]
    origin: Tuple[float, float, float]
    cell_size: Tuple[float, float, float]
    start_file: Optional[str]  # fields at the start of frame_start
    files: List[str]  # fields at the end of frame_start .. frame_end
    frame_dts: List[float]  # seconds (simulated) of each traced frame


def data_path(cache_directory, frame):
    return os.path.join(cache_directory, "data", f"fluid_data_{frame:04d}.vdb")


def config_path(cache_directory, frame):
    return os.path.join(cache_directory, "config", f"config_{frame:04d}.uni")


def read_config(path):
    """The config of one frame; BakeError naming the file when it is unreadable or malformed."""
    try:
        with gzip.open(path, "rb") as f:
            data = f.read(_CONFIG_MAX_BYTES + 1)
    except (OSError, EOFError, zlib.error) as e:
        raise BakeError(f"Plume: Mantaflow config {path} cannot be read ({e}): bake the "
                        "Mantaflow domain again") from None
    if not (_CONFIG.size <= len(data) <= _CONFIG_MAX_BYTES):
        raise BakeError(f"Plume: Mantaflow config {path} has {len(data)} bytes, not the "
                        f"{_CONFIG.size}+ of Blender 3.4's: bake the Mantaflow domain again")
    v = _CONFIG.unpack_from(data)
    floats = [x for x in v if isinstance(x, float)]
    if not all(math.isfinite(x) for x in floats):
        raise BakeError(f"Plume: Mantaflow config {path} holds numbers that are not finite")
    # Blender's float[4][4] is column-major: each group of four is a column.
    obmat = np.array(v[21:37], dtype=np.float64).reshape(4, 4).T
    return MantaflowConfig(res=tuple(v[1:4]), p0=np.array(v[6:9], np.float64),
                           p1=np.array(v[9:12], np.float64), shift=tuple(v[15:18]), obmat=obmat,
                           base_res=tuple(v[37:40]), res_min=tuple(v[40:43]),
                           res_max=tuple(v[43:46]), time_total=float(v[49]))


def _close(a, b):
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return bool(np.all(np.abs(a - b) <= _TOLERANCE * max(1.0, float(np.max(np.abs(b))))))


def _placement(cfg, m, path):
    """World origin and cell size per axis of the grid of one config; BakeError when the
    domain is adaptive, rotated or mirrored."""
    name = f"Plume: Mantaflow domain '{m.object_name}'"
    if (cfg.res != cfg.base_res or any(cfg.res_min) or cfg.res_max != cfg.base_res
            or any(cfg.shift)):
        raise BakeError(f"{name}: {path} is an adaptive domain's sub-grid; streak tracing needs "
                        "the whole grid: turn Adaptive Domain off and bake it again")
    if not all(1 <= r <= 2048 for r in cfg.base_res):
        raise BakeError(f"{name}: {path} has a resolution {cfg.base_res} outside [1, 2048]")
    linear = cfg.obmat[:3, :3]
    scale = np.diag(linear)
    off = linear - np.diag(scale)
    if np.any(np.abs(off) > _TOLERANCE * np.max(np.abs(scale))) or np.any(scale <= 0.0):
        raise BakeError(f"{name} is rotated or mirrored; streak tracing needs its axes along the "
                        "world axes with a positive scale: apply its rotation and bake it again")
    size = (cfg.p1 - cfg.p0) * scale
    if np.any(size <= 0.0):
        raise BakeError(f"{name}: {path} describes a flat domain")
    origin = linear @ cfg.p0 + cfg.obmat[:3, 3]
    return origin, size / np.asarray(cfg.base_res, np.float64)


def check_source(m, frame_start, frame_end):
    """Validates the Mantaflow domain and its cache for the frames frame_start..frame_end and
    returns the MantaflowPlan; BakeError naming the setting and what to do. Reads the configs
    only (the VDB files are checked when read)."""
    owner = f"Plume: domain '{m.domain_name}'"
    if not m.object_name:
        raise BakeError(f"{owner}: motion_source is Mantaflow Cache but mantaflow_domain is not "
                        "set: pick the Blender fluid domain (type Gas) whose cache moves the "
                        "particles")
    name = f"Plume: Mantaflow domain '{m.object_name}'"
    if not m.is_gas_domain:
        raise BakeError(f"{owner}: mantaflow_domain '{m.object_name}' is not a Blender fluid "
                        "domain of type Gas")
    if m.cache_data_format != "OPENVDB":
        fmt = {"UNI": "Uni Cache", "RAW": "Raw Cache"}.get(m.cache_data_format,
                                                         m.cache_data_format.title())
        raise BakeError(f"{name}: its volumes are cached as {fmt}; streak tracing reads OpenVDB "
                        f"caches: set {FLUID} › Cache › Format Volumes to OpenVDB and bake it "
                        "again")
    if m.use_adaptive_domain:
        raise BakeError(f"{name}: its Adaptive Domain is on; streak tracing needs the whole "
                        f"grid: turn {FLUID} › Settings › Adaptive Domain off and bake it again")
    if frame_start < m.cache_frame_start or frame_end > m.cache_frame_end:
        raise BakeError(f"{owner}: frames {frame_start}-{frame_end} are outside the Mantaflow "
                        f"cache's frames {m.cache_frame_start}-{m.cache_frame_end} of "
                        f"'{m.object_name}': change the frame range of one of them")
    first = max(frame_start - 1, m.cache_frame_start)
    needed = range(first, frame_end + 1)
    for f in needed:
        for path in (data_path(m.cache_directory, f), config_path(m.cache_directory, f)):
            if not os.path.isfile(path):
                raise BakeError(
                    f"{name} is not baked over frames {first}-{frame_end} ({path} is missing): "
                    f"bake it ({FLUID} › Settings › Bake Data, or play the frames of a "
                    "Replay cache)")
    configs = {f: read_config(config_path(m.cache_directory, f)) for f in needed}
    ref = configs[first]
    origin, cell = _placement(ref, m, config_path(m.cache_directory, first))
    for f, cfg in configs.items():
        if (cfg.base_res != ref.base_res or cfg.res != ref.res or not _close(cfg.p0, ref.p0)
                or not _close(cfg.p1, ref.p1) or not _close(cfg.obmat, ref.obmat)):
            raise BakeError(f"{name} moves or changes between frames {first} and {f}; streak "
                            "tracing needs a still domain of fixed resolution")
    frame_dts = []
    for f in range(frame_start, frame_end + 1):
        if f - 1 in configs:
            length = configs[f].time_total - configs[f - 1].time_total
        else:  # the first cached frame starts from time 0
            length = 0.1 * (25.0 / m.fps) * m.time_scale
        if not (length > 0.0 and math.isfinite(length)):
            raise BakeError(f"{name}: frame {f} has a time step of {length} Mantaflow time units "
                            f"(Time Scale 0?); bake it again with {FLUID} › Settings › Time "
                            "Scale > 0")
        frame_dts.append(length / TIME_UNITS_PER_SECOND)
    traced = range(frame_start, frame_end + 1)
    start = None  # the empty state before the cache
    if frame_start > m.cache_frame_start:
        start = data_path(m.cache_directory, frame_start - 1)
    return MantaflowPlan(resolution=tuple(int(r) for r in ref.base_res),
                         origin=tuple(float(x) for x in origin),
                         cell_size=tuple(float(x) for x in cell), start_file=start,
                         files=[data_path(m.cache_directory, f) for f in traced],
                         frame_dts=frame_dts)
