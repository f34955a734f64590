"""How long Build Surfaces will take, said before it starts (a long build asks first in the UI and
prints the forecast headless: jobs/operator.py). A cost model of the build's stages, read
off the bake's last streak file (lines L, particles per line P) and its frame count F:

    h(α,β) of every pair closer than h0 (§3.3, sparse):  H_PAIR_S × pairs × F × P̄
    least-squares nets and density maps (§3.3, §3.4):    FIT_S × L × P × F
    reading the files, building the objects:            OVERHEAD_S

with P̄ = P/2 (a streakline grows by one particle per frame) and pairs = PAIR_SHARE × L²/2 (the
default h0, the mean of h, keeps about half the pairs of a source covering a sphere; a smaller
h0 keeps fewer, so the figure is an upper one there). The rates were fitted to Build Surfaces of
the 40³ sphere scene (60 frames, 113 particles per line) on the 2-core machine the README's
tables come from: 256, 1,024 and 4,096 streaklines took 6.5, 25-31 and 134 s (forecast 7.8, 28
and 134 s); a faster machine finishes sooner."""

import numpy as np

from . import cache, point_sources
from .settings import BakeError

#: Seconds per (pair of streaklines × particle-frame) of the sparse h.
H_PAIR_S = 2.5e-9
#: Seconds per particle-frame of the nets and density maps.
FIT_S = 3.5e-6
#: Seconds of reading the files and building the objects.
OVERHEAD_S = 1.5
#: Share of the pairs within the default h0.
PAIR_SHARE = 0.5
#: Bytes per pair held by the sparse h (measured: 10,752 streaklines, 33.4 M pairs below the
#: mean, 2.77 GB at the peak of Build Surfaces, 0.59 GB of it the frames).
PAIR_BYTES = 65


def work(lines, particles, frames):
    """(pairs × particle-frames of h, particle-frames of the fit) of a shot."""
    pairs = PAIR_SHARE * lines * (lines - 1) / 2.0
    return pairs * frames * particles / 2.0, float(lines) * particles * frames


def seconds(lines, particles, frames):
    """The forecast in seconds for L lines of P particles over F frames."""
    h_work, fit_work = work(lines, particles, frames)
    return OVERHEAD_S + H_PAIR_S * h_work + FIT_S * fit_work


def memory_bytes(lines, particles, frames):
    """Bytes Build Surfaces holds at its peak: every frame's particles (streak_bytes) and the
    pairs of the sparse h (computed up to the default h0, whatever h0 the build uses)."""
    pairs = PAIR_SHARE * lines * (lines - 1) / 2.0
    per_frame = particles / max(frames, 1)
    return point_sources.streak_bytes(lines, frames, per_frame) + PAIR_BYTES * pairs


def check_memory(domain_name, lines, particles, frames):
    """BakeError, before anything is computed or written, when the build would not fit in the
    memory this machine has free; names the count and the memory it needs."""
    need = memory_bytes(lines, particles, frames)
    have = point_sources.available_bytes()
    if have is not None and need > have:
        raise BakeError(
            f"Plume: surfaces of '{domain_name}': {lines:,} streaklines over {frames} frames need "
            f"about {need / 2**30:.1f} GB (their particles and the distances h between them), "
            f"more than the {have / 2**30:.1f} GB of memory free: lower Max Streaklines "
            "(Physics Properties › Plume › Streak Surfaces) and bake again")


def shot_size(native, folder, manifest):
    """(lines, particles per line, frames) of a streak bake, from its last streak file; None
    when the file is missing or unreadable (Build Surfaces reports that itself)."""
    first, last = int(manifest["frame_start"]), int(manifest["last_complete_frame"])
    try:
        frame = native.read_streak_file(cache.streak_path(folder, last))
    except (OSError, RuntimeError, ValueError):
        return None
    counts = np.asarray(frame["counts"])
    if counts.size == 0:
        return None
    return int(counts.size), int(counts.max()), last - first + 1
