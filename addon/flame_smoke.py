"""Smoke from structural flames into a Plume domain ([Structural Flames] §6.3), no ``bpy``.

"We procedurally generate smoke as particles above the tip of each flame. The smoke point above
the tip is given simply by h, and the density of particles is the radiation intensity (Eq 5)
multiplied by an arbitrary scale factor. Once generated, the smoke is introduced into a gas
simulator with an initial velocity of V_{p_{n-1}} (from the upper control point) and a
temperature set to maintain the upward buoyancy force specified by Eq (2)."

Two passes: Bake Flames writes <flames cache>/spines_####.npz; a domain with Flame Smoke on
reads, for each frame it advances into, that frame's spines and gives the solver one point
emitter (native/solver/point_emitters.h) per flame with energy E > 0:

- which flames: those at least Smoke Point tall (§6.3: "the smoke point: the minimum laminar
  flame height at which smoke first escapes from the flame tip"), h = |x_{n-1} − x_0| as below;
  shorter ones burn clean and emit nothing;
- position: the smoke point, tip + h t̂: the flame's axis from its first control point x_0 to its
  tip x_{n-1} continued by its own length, h = |x_{n-1} − x_0| along t̂ = (x_{n-1} − x_0) / h
  (the tip itself for a flame of no length). Not the spine's arc length and last segment: the control points
  of a young flame are jumbled by the Brownian diffusion of eq. 1 (torch test, frame 1: arc
  length 0.06 m for a 0.005 m flame, last segment pointing down in 2 flames of 5), which would
  put the smoke point centimetres away from a flame of millimetres, often below it; once a flame
  stands, its axis and length are the tip direction and length within ~15% (frames 6-12);
- radius: the flame's radius r (the solver uses at least one cell);
- mass rate (Σ ρ Δx³ per second): Smoke Yield × E, E the flame's energy of eq. 5 (the sum of its
  lights' energy, §5.2, as written by the flames bake);
- velocity: V_{p_{n-1}}, the velocity of the top control point;
- temperature above ambient: Smoke Temperature, or when that is 0 (automatic) the one whose
  buoyancy matches eq. 2. The flames rise with the acceleration a = β_f |g_f| (T_p − T_0)
  (evolution.h's reading of eq. 2, stored per flame as "lifts"); the solver's heat buoyancy is
  f = β |g| (T − T_amb) (forces.h), so T − T_amb = a / (β |g|) with the domain's β and g. The
  domain's α ρ term (dense smoke rising, Blender's sign) acts on top of it: set α = 0 for the
  paper's smoke, whose buoyancy is thermal only.
"""

import math
import os
from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

from . import flames
from .settings import BakeError

SETTING = "Flame Smoke"
#: Default Smoke Point (m). Laminar smoke points of fuels run from ~2 cm (aromatics, kerosene)
#: to ~16 cm (propane); 0.1 m sits above a candle (real ones 3-5 cm tall burn clean; the
#: candle of the tests breaks by H_max = 0.08 m) and well below a campfire's tongues
#: (0.3-1 m), which smoke.
SMOKE_POINT = 0.1
#: The arrays of one frame, the keyword arguments of SmokeSolver.set_point_emitters.
EMITTER_ARRAYS = ("positions", "radii", "density_rates", "velocities", "temperatures")


@dataclass
class FlameSmokeSettings:
    """A domain's Flame Smoke settings and the flames cache it reads."""

    enabled: bool = False
    smoke_yield: float = 10.0  # the paper's "arbitrary scale factor": mass per second per unit E
    temperature: float = 0.0   # T − T_amb of the smoke; 0 = automatic (eq. 2)
    #: §6.3 smoke point (m): flames shorter than this emit no smoke.
    smoke_point: float = SMOKE_POINT
    folder: str = ""           # absolute flames cache folder (scene.plume_flames.cache_directory)
    #: per frame of the bake: dict of EMITTER_ARRAYS (filled by load_frames)
    frames: List[dict] = field(default_factory=list)

    def fingerprint(self):
        """The result-relevant settings (manifest.json compares them on resume)."""
        return {"smoke_yield": self.smoke_yield, "temperature": self.temperature,
                "smoke_point": self.smoke_point}

    def frame_bytes(self, index):
        """The emitters of frame index `index`, as bytes for the frame input hash."""
        if index >= len(self.frames):
            return b""
        arrays = self.frames[index]
        return b"".join(np.ascontiguousarray(arrays[k], np.float32).tobytes()
                        for k in EMITTER_ARRAYS)


def _owner(domain_name):
    return f"Plume: domain '{domain_name}': {SETTING}"


def smoke_temperature(settings, lifts, solver, domain_name):
    """T − T_amb per flame: the setting, or (0, automatic) the eq. 2 match of the module doc."""
    if settings.temperature != 0.0:
        return np.full(len(lifts), settings.temperature, np.float32)
    per_unit = solver.beta * math.sqrt(sum(g * g for g in solver.gravity))
    if not (math.isfinite(per_unit) and per_unit > 0.0):
        raise BakeError(f"{_owner(domain_name)}: an automatic Smoke Temperature (0) matches the "
                        "flames' buoyancy (eq. 2) with the domain's heat buoyancy β |g|, which is "
                        f"{per_unit:g}: give the domain a Beta (β) > 0 and gravity, or set a "
                        "Smoke Temperature")
    return (np.asarray(lifts, np.float64) / per_unit).astype(np.float32)


def frame_emitters(spines, settings, solver, domain_name):
    """The point emitters of one spines dict (flames.read_spines) as EMITTER_ARRAYS."""
    counts = np.asarray(spines["counts"], np.int64)
    points = np.asarray(spines["points"], np.float64).reshape(-1, 3)
    ends = np.cumsum(counts)
    # E of each flame: the energy of its lights (eq. 5 × intensity, one per flame segment §5.2).
    energy = np.zeros(len(counts))
    index = {int(fid): n for n, fid in enumerate(spines["ids"])}
    for fid, e in zip(spines["light_ids"], spines["light_energy"]):
        n = index.get(int(fid))
        if n is not None:
            energy[n] += float(e)
    bases, tips = points[ends - counts], points[ends - 1]
    heights = np.linalg.norm(tips - bases, axis=1)  # h = |x_{n-1} − x_0|
    # §6.3: a flame shorter than the smoke point burns clean.
    keep = [n for n in range(len(counts)) if counts[n] >= 2 and energy[n] > 0.0
            and heights[n] >= settings.smoke_point]
    positions, velocities = np.zeros((len(keep), 3)), np.zeros((len(keep), 3))
    for row, n in enumerate(keep):
        base, tip = bases[n], tips[n]
        positions[row] = tip + (tip - base)  # h t̂ = x_{n-1} − x_0: h above the tip on its axis
        velocities[row] = spines["velocities"][ends[n] - 1]  # V_{p_{n-1}}
    arrays = {
        "positions": positions.astype(np.float32),
        "radii": np.asarray(spines["radii"], np.float32)[keep],
        "density_rates": (settings.smoke_yield * energy[keep]).astype(np.float32),
        "velocities": velocities.astype(np.float32),
        "temperatures": smoke_temperature(settings, np.asarray(spines["lifts"])[keep], solver,
                                          domain_name),
    }
    for name, a in arrays.items():
        if not np.all(np.isfinite(a)):
            raise ValueError(f"non-finite {name} (a corrupt spines file?)")
    return arrays


def load_frames(settings: Optional[FlameSmokeSettings], frame_start, frame_end, solver,
                domain_name):
    """Reads the flames cache for frames frame_start .. frame_end into settings.frames. BakeError
    naming the setting when the flames are not baked over that range or their files are
    unreadable or from a version without the smoke data; nothing is written."""
    if settings is None or not settings.enabled:
        return
    owner = _owner(domain_name)
    if not math.isfinite(settings.smoke_yield) or settings.smoke_yield < 0.0:
        raise BakeError(f"{owner}: Smoke Yield must be >= 0 (got {settings.smoke_yield})")
    if not math.isfinite(settings.smoke_point) or settings.smoke_point < 0.0:
        raise BakeError(f"{owner}: Smoke Point must be >= 0 m, the flame height above which "
                        f"smoke escapes (§6.3) (got {settings.smoke_point:g})")
    if not math.isfinite(settings.temperature):
        raise BakeError(f"{owner}: Smoke Temperature must be a finite number "
                        f"(got {settings.temperature})")
    manifest = flames.read_manifest(settings.folder)
    if manifest is None:
        raise BakeError(f"{owner} is on but no flames are baked in '{settings.folder}': bake "
                        "the flames first (Bake Flames) or turn Flame Smoke off")
    first = manifest.get("frame_start")
    last = manifest.get("last_complete_frame")
    if not (isinstance(first, int) and isinstance(last, int)
            and first <= frame_start and frame_end <= last):
        raise BakeError(f"{owner}: the flames are baked over frames {first}..{last}, which does "
                        f"not cover the domain's frames {frame_start}..{frame_end}: bake the "
                        "flames over the domain's range or change the domain's Start/End")
    frames = []
    for frame in range(frame_start, frame_end + 1):
        path = flames.spines_path(settings.folder, frame)
        try:
            spines = flames.read_spines(path)
            missing = [a for a in flames.SMOKE_ARRAYS if a not in spines]
            if missing:
                raise ValueError(f"no {', '.join(missing)} (baked by an older version): "
                                 "bake the flames again")
            frames.append(frame_emitters(spines, settings, solver, domain_name))
        except (OSError, ValueError) as e:
            raise BakeError(f"{owner}: flames frame {frame} ({os.path.basename(path)}): "
                            f"{e}") from None
    settings.frames = frames


def set_frame(solver, settings, index):
    """Gives the native solver the emitters of frame index `index` (nothing when off)."""
    if settings is not None and settings.enabled:
        solver.set_point_emitters(**settings.frames[index])

