"""Toon smoke from a baked cache, no ``bpy`` ([Cartoon Smoke] §2.1-2.3): settings and their
validation, the native ToonParams they map to, and the runner that walks the bake's
volume_####.vdb frames with _native.ToonParticles and writes one toon_####.bin per frame.

    s = ToonSettings(...); validate(s, "Domain")
    m = toon_manifest(folder, "Domain")                 # BakeError when there is no bake
    result = ToonRunner(native, folder, m, s).run()     # toon_<frame>.bin, atomically
"""

import math
import os
import re
from dataclasses import dataclass, fields
from typing import Callable, Optional, Tuple

import numpy as np

from . import cache
from .settings import BakeError
from .ui_words import TAB, TOON, in_ui_words, label, ui

#: Stencils (Figure 3); IMAGE uses the artist's image file.
STENCILS = ('CIRCLE', 'PUFFY', 'HAIRY', 'IMAGE')
COLOR_DRIVERS = ('DENSITY', 'TEMPERATURE', 'SPEED')
INTEGRATIONS = ('EULER', 'MIDPOINT')

_TOON_RE = re.compile(r"^toon_(-?\d+)\.bin$")


def toon_path(folder, frame):
    return os.path.join(folder, f"toon_{frame:04d}.bin")


def toon_frames(folder):
    """Frame numbers of the toon_*.bin files present, sorted."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(int(m.group(1)) for m in map(_TOON_RE.match, names) if m)


@dataclass
class ToonSettings:
    """Everything plume.toon_build reads from obj.plume.domain.toon (names as ToonParams)."""

    # Particles (§2.1, §2.3) -> _native.ToonParams
    emission_count: int = 10
    birth_density: float = 0.5      # ρ_birth
    birth_spacing: float = 0.5      # σ (stencil sizes)
    death_density: float = 0.05     # ρ_death
    ramp_density_low: float = 0.0   # d0
    ramp_density_high: float = 1.0  # d1
    size_low: float = 0.1           # s0 (m)
    size_high: float = 0.25         # s1 (m)
    max_size_change: float = 0.25
    max_count: int = 200000
    integration: str = 'EULER'
    cfl: float = 1.0
    seed: int = 0
    stretch_factor: float = 0.5     # k
    color_driver: str = 'DENSITY'
    color_low: float = 0.0
    color_high: float = 1.0
    threads: int = 0
    # Rendering (§2.2), used by the Blender side only
    depth_threshold: float = 0.15   # γ (m of depth per pixel)
    stencil: str = 'PUFFY'
    stencil_image: str = ""         # absolute path when stencil == 'IMAGE'
    ignore_background: bool = False


#: ToonSettings fields copied one to one into _native.ToonParams (enums converted by name).
PARAM_FIELDS = ('emission_count', 'birth_density', 'birth_spacing', 'death_density',
                'ramp_density_low', 'ramp_density_high', 'size_low', 'size_high',
                'max_size_change', 'max_count', 'integration', 'cfl', 'seed', 'stretch_factor',
                'color_driver', 'color_low', 'color_high', 'threads')


def _finite(name, value, where):
    if not math.isfinite(value):
        raise BakeError(f"Plume: {where}{ui('toon', name)} must be a finite number (got {value:g})")


def validate(s: ToonSettings, domain_name=""):
    """BakeError naming the setting as its panel shows it and its accepted range; the native
    validate() covers the rest of the particle settings (see to_params)."""
    where = f"domain '{domain_name}': " if domain_name else ""
    for f in fields(s):
        v = getattr(s, f.name)
        if isinstance(v, float):
            _finite(f.name, v, where)
    if s.depth_threshold < 0.0:
        raise BakeError(f"Plume: {where}{ui('toon', 'depth_threshold')} must be >= 0, the depth "
                        "difference per pixel above which a pixel is outlined (§2.2; got "
                        f"{s.depth_threshold:g})")
    if s.death_density < 0.0 or s.birth_density <= s.death_density:
        raise BakeError(f"Plume: {where}{ui('toon', 'death_density')} must be >= 0 and below "
                        f"{label('toon', 'birth_density')} (got {s.death_density:g} and "
                        f"{s.birth_density:g})")
    if s.ramp_density_high <= s.ramp_density_low:
        raise BakeError(f"Plume: {where}{ui('toon', 'ramp_density_high')} must be above "
                        f"{label('toon', 'ramp_density_low')} (got {s.ramp_density_high:g} and "
                        f"{s.ramp_density_low:g})")
    if s.size_low < 0.0 or s.size_high < 0.0 or max(s.size_low, s.size_high) <= 0.0:
        raise BakeError(f"Plume: {where}{ui('toon', 'size_low')} and {label('toon', 'size_high')} "
                        f"must be >= 0 m and not both 0 (got {s.size_low:g} and {s.size_high:g})")
    if s.color_high <= s.color_low:
        raise BakeError(f"Plume: {where}{ui('toon', 'color_high')} must be above "
                        f"{label('toon', 'color_low')} (got {s.color_high:g} and {s.color_low:g})")
    if s.stencil not in STENCILS:
        raise BakeError(f"Plume: {where}{ui('toon', 'stencil')} must be Circle, Puffy Cloud, "
                        f"Hairy Cloud or Image (got {s.stencil!r})")
    if s.stencil == 'IMAGE':
        if not s.stencil_image:
            raise BakeError(f"Plume: {where}Stencil is Image but {ui('toon', 'stencil_image')} "
                            "is empty: pick an image file (its alpha is the cut-out)")
        if not os.path.isfile(s.stencil_image):
            raise BakeError(f"Plume: {where}{ui('toon', 'stencil_image')} {s.stencil_image} "
                            "does not exist: pick an image file")
    if s.color_driver not in COLOR_DRIVERS:
        raise BakeError(f"Plume: {where}{ui('toon', 'color_driver')} must be Density, "
                        f"Temperature or Speed (got {s.color_driver!r})")
    if s.integration not in INTEGRATIONS:
        raise BakeError(f"Plume: {where}{ui('toon', 'integration')} must be Euler or Midpoint "
                        f"(got {s.integration!r})")


def to_params(native, s: ToonSettings, domain_name=""):
    """_native.ToonParams of the settings, validated (BakeError with the native message, the
    setting it names as the panel shows it)."""
    p = native.ToonParams()
    for name in PARAM_FIELDS:
        v = getattr(s, name)
        if name == 'integration':
            v = getattr(native.ToonIntegration, v)
        elif name == 'color_driver':
            v = getattr(native.ToonColorDriver, v)
        try:
            setattr(p, name, v)
        except TypeError:  # e.g. a negative seed into an unsigned field
            raise BakeError(f"Plume: domain '{domain_name}': {ui('toon', name)} cannot be "
                            f"{v!r}") from None
    try:
        p.validate()
    except ValueError as e:
        raise BakeError(f"Plume: domain '{domain_name}': {in_ui_words('toon', str(e))}") from None
    return p


def toon_manifest(folder, domain_name):
    """The bake's manifest; BakeError when the domain has no complete frame to read."""
    m = cache.read_manifest(folder)
    if m is None or m.get("last_complete_frame", -1) < m.get("frame_start", 0):
        raise BakeError(f"Plume: domain '{domain_name}' has no bake yet: bake it first "
                        f"({TAB} › Bake), then build the toon smoke")
    first = cache.volume_path(folder, int(m["frame_start"]))
    if not os.path.isfile(first):
        raise BakeError(f"Plume: volume file {first} is missing: bake the domain again")
    return m


@dataclass(frozen=True)
class ToonGrid:
    """The cubic grid the toon particles live on. A Plume bake's own grid; for a traced Mantaflow
    bake, whose cells are not cubic ("cell_size_xyz" in its manifest), cubic cells of its
    smallest cell size over its box, onto which its volume frames are interpolated (resample)."""
    resolution: Tuple[int, int, int]
    origin: Tuple[float, float, float]
    cell_size: float
    resample: bool = False

    def args(self):
        """(resolution, origin, cell_size, resample) as _native.ToonParticles takes them."""
        return self.resolution, self.origin, self.cell_size, self.resample


def toon_grid(manifest):
    res = tuple(int(v) for v in manifest["resolution"])
    origin = tuple(float(v) for v in manifest["origin"])
    cells = manifest.get("cell_size_xyz")
    if cells is None or max(cells) - min(cells) <= 1e-6 * max(cells):
        return ToonGrid(res, origin, float(manifest["cell_size"]))
    h = float(min(cells))
    size = np.asarray(res, np.float64) * np.asarray(cells, np.float64)
    return ToonGrid(tuple(max(1, int(math.ceil(s / h - 1e-4))) for s in size), origin, h, True)


def check_bake(settings: ToonSettings, manifest, domain_name=""):
    """BakeError when the settings need a field the bake does not carry: a traced Mantaflow bake
    holds density and velocity only (no temperature to drive the colour ramp)."""
    if manifest.get("motion_source") == "mantaflow" and settings.color_driver == 'TEMPERATURE':
        raise BakeError(f"Plume: domain '{domain_name}' traces a Mantaflow cache, which carries "
                        "density and velocity only: set Colour Driver to Density or Speed "
                        f"({TOON})")


def frame_dt(manifest):
    """Seconds per frame of the bake (time scale / fps, as the solver used)."""
    dt = manifest.get("settings", {}).get("solver", {}).get("frame_dt")
    if dt is None or not math.isfinite(float(dt)) or float(dt) <= 0.0:
        raise BakeError("Plume: the bake's manifest has no frame time: bake the domain again")
    return float(dt)


@dataclass
class ToonResult:
    frame_start: int
    last_frame: int          # last toon frame written (frame_start - 1 when none)
    cancelled: bool = False
    count: int = 0           # particles at the last frame written
    max_count_seen: int = 0  # most particles at any frame


class ToonRunner:
    """Walks the bake frame by frame: frame_start advances from its own fields, each next frame
    from the previous volume to its own (§2.1 advection, §2.3 evolution), introducing particles
    at the cells `sources` gives for the frame (the Sources where and when they emit), and
    writes toon_<frame>.bin after each, into out_folder (default: the bake's folder; the toon job
    gives its staging folder). progress(frames_done, frames_total) and cancel() are optional
    callables; a cancelled run keeps the frames written so far."""

    def __init__(self, native, folder, manifest, settings: ToonSettings, domain_name="",
                 progress: Optional[Callable[[int, int], None]] = None,
                 cancel: Optional[Callable[[], bool]] = None, sources=None,
                 out_folder=None):
        self.native = native
        self.folder = folder
        self.out_folder = folder if out_folder is None else out_folder
        self.manifest = manifest
        self.params = to_params(native, settings, domain_name)
        self.progress = progress
        self.cancel = cancel
        #: toon_sources.ToonSourceCells (or None): the Sources' cells of each frame, where
        #: emission_count particles per frame are introduced (§2.1)
        self.sources = sources
        self.frame_start = int(manifest["frame_start"])
        self.last_frame = int(manifest["last_complete_frame"])
        self.dt = frame_dt(manifest)
        self.grid = toon_grid(manifest)

    def run(self) -> ToonResult:
        native, folder, out = self.native, self.folder, self.out_folder
        try:
            particles = native.ToonParticles(self.params, *self.grid.args())
        except ValueError as e:
            raise BakeError(f"Plume: toon particles: {in_ui_words('toon', str(e))}") from None
        result = ToonResult(frame_start=self.frame_start, last_frame=self.frame_start - 1)
        total = self.last_frame - self.frame_start + 1
        # Frames of an older build would mix with this one (a cancel keeps a prefix): remove them.
        for f in toon_frames(out):
            os.remove(toon_path(out, f))
        for frame in range(self.frame_start, self.last_frame + 1):
            if self.cancel is not None and self.cancel():
                result.cancelled = True
                break
            before = cache.volume_path(folder, max(frame - 1, self.frame_start))
            after = cache.volume_path(folder, frame)
            try:
                cells = self.sources.cells_at(frame) if self.sources else None
                particles.advance_frame_from_vdb(before, after, self.dt, source_cells=cells)
                particles.write(toon_path(out, frame))
            except (RuntimeError, ValueError) as e:
                raise BakeError(f"Plume: toon frame {frame}: {e} (bake the domain again)") from None
            result.last_frame = frame
            result.count = int(particles.count)
            result.max_count_seen = max(result.max_count_seen, result.count)
            if self.progress is not None:
                self.progress(frame - self.frame_start + 1, total)
        return result
