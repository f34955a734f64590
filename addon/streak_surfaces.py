"""Streak surfaces from a baked cache, no ``bpy`` (smoke_surfaces.txt §3.3-3.4): reads the
streak files, computes h per candidate group, clusters with h0, orders greedily, and turns each
cluster into per-frame NURBS control points and density maps.

    frames = load_frames(native, folder, frame_start, last_frame)
    groups = group_distances(native, frames)           # {group: GroupDistances}
    plans = plan_surfaces(native, groups, h0)          # one SurfacePlan per cluster
    anim = surface_animation(native, frames, plan)     # control points per frame

The distances are sparse (native StreakDistances): each group holds every pair with h below its
reach, exactly, and no n x n matrix. The reach starts at the group's default h0 (the mean of h)
and grows when a build asks for a larger threshold; clusters, counts and the Figure 4 curve are
exact up to it, the greedy order always.
"""

import os
from dataclasses import dataclass
from typing import Dict, List

import numpy as np

from . import cache
from .settings import BakeError

#: Orders of the surfaces (cubic, lower when there are fewer points, as Blender allows).
ORDER_U = ORDER_V = 4


@dataclass
class GroupDistances:
    """h(α,β) of one candidate group (§3.3): ``h`` is a native StreakDistances holding every pair
    with h < h.reach exactly (members 0..n-1 are the source IDs ``ids``)."""

    group: int
    ids: np.ndarray
    h: object


@dataclass
class SurfacePlan:
    group: int
    threshold: float
    sources: List[int]  # source IDs ordered across the surface (v)


@dataclass
class SurfaceAnimation:
    """Control net of one surface at every frame; the net's size is fixed for the whole shot."""

    nu: int
    nv: int
    order_u: int
    order_v: int
    particles: int  # particles per streakline at the last frame (u samples of the surface)
    control_points: np.ndarray  # float32 (frames, nv * nu, 4), Blender's flat order v*nu+u
    surfaces: list  # per frame: the interpolate_surface dict (for the density map)


def streak_manifest(folder, domain_name):
    """The manifest of a bake with streak surfaces; BakeError saying what is missing."""
    m = cache.read_manifest(folder)
    if m is None or m.get("last_complete_frame", -1) < m.get("frame_start", 0):
        raise BakeError(f"Plume: domain '{domain_name}' has no bake yet: turn on Streak Surfaces "
                        "and bake it first (plume.bake)")
    if not m.get("streaks"):
        raise BakeError(f"Plume: domain '{domain_name}' was baked without streak surfaces: turn "
                        "on Streak Surfaces (domain.plume.domain.streaks) and bake again")
    return m


def load_frames(native, folder, frame_start, last_frame):
    """Snapshot dicts of frames frame_start..last_frame; BakeError naming a missing/bad file."""
    frames = []
    for f in range(frame_start, last_frame + 1):
        path = cache.streak_path(folder, f)
        if not os.path.isfile(path):
            raise BakeError(f"Plume: streak file {path} is missing: bake the domain again")
        try:
            frames.append(native.read_streak_file(path))
        except RuntimeError as e:
            raise BakeError(f"Plume: {e} (bake the domain again)") from None
    return frames


def group_distances(native, frames) -> Dict[int, GroupDistances]:
    """Sparse h of each candidate group (groups of the last frame), up to the group's default
    h0: the pairs with h < mean of h, found through a grid and a lower bound, never all n²/2."""
    groups = np.asarray(frames[-1]["groups"])
    names = sorted(set(int(x) for x in groups))
    for g in names:
        ids = np.flatnonzero(groups == g)
        if len(ids) < 2:
            raise BakeError(
                f"Plume: candidate group {g} has a single point source (source ID {int(ids[0])}); "
                "a surface needs at least 2: raise the source's point_sources or give it the "
                "candidate_group of another source")
    try:
        shared = native.StreakFrames(frames)  # converted once for every group
    except ValueError as e:
        raise BakeError(f"Plume: streak files: {e} (bake the domain again)") from None
    out = {}
    for g in names:
        ids = np.flatnonzero(groups == g)
        try:
            h = native.streak_distances(shared, ids)
        except ValueError as e:
            raise BakeError(f"Plume: candidate group {g}: {e}") from None
        out[g] = GroupDistances(group=g, ids=ids, h=h)
    return out


def check_threshold(h0, domain_name=""):
    if not np.isfinite(h0) or h0 < 0.0:
        raise BakeError(f"Plume: domain '{domain_name}': streak_threshold (h0) must be >= 0 "
                        f"(0 = the mean of h in each candidate group; got {h0})")


def group_threshold(native, g, h0):
    """h0 if > 0, else the group's default: the mean of its h values (§3.3)."""
    return float(h0) if h0 > 0.0 else float(native.default_threshold(g.h))


def summary(native, groups, h0):
    """(surfaces, streaklines) for threshold h0 over all groups (Figure 4), from each group's
    curve in O(log pairs). Exact whenever each group's threshold (h0 > 0, else its default) is
    <= its reach: always for h0 = 0 and for any h0 up to the smallest group mean, and up to the
    largest threshold built so far. Above a group's reach, ValueError naming it (the pairs that
    would decide are not held; Build Surfaces at that h0 widens them)."""
    surfaces = lines = 0
    for g in groups.values():
        s, n = native.cluster_summary(g.h, group_threshold(native, g, h0))
        surfaces += s
        lines += n
    return surfaces, lines


def most_surfaces_threshold(native, groups):
    """The h0 > 0 giving the most surfaces over all candidate groups (ties: the most streaklines,
    then the smallest h0): what an artist looks for on the (h0 -> surfaces) curve of Figure 4.
    Searched over 0 < h0 <= R, R the smallest reach of the groups (their default h0, the mean of
    h, unless a build widened them). The counts only change where h0 passes a value of h, and
    every pair with h < R is held, so h0 just above each held value covers every clustering in
    that range exactly, in one pass over the groups' curves (single linkage, Kruskal). Larger
    h0 are not searched: the pairs that decide them are not held (the peak of Figure 4 lies far
    below the mean of h in practice, where the mean joins nearly everything)."""
    reach = min(float(g.h.reach) for g in groups.values())
    curves = [g.h.curve() for g in groups.values()]
    values = np.unique(np.concatenate([c[0] for c in curves]))
    h0s = np.nextafter(values, np.inf)
    keep = h0s <= reach
    values, h0s = values[keep], h0s[keep]
    surfaces = np.zeros(len(values), dtype=np.int64)
    lines = np.zeros(len(values), dtype=np.int64)
    for c_values, c_surfaces, c_lines in curves:
        # Counts at h0 just above v: every pair with h <= v joined.
        k = np.searchsorted(c_values, values, side="right") - 1
        has = k >= 0
        surfaces[has] += np.asarray(c_surfaces, dtype=np.int64)[k[has]]
        lines[has] += np.asarray(c_lines, dtype=np.int64)[k[has]]
    if len(values) == 0 or surfaces.max() == 0:
        raise BakeError("Plume: no threshold h0 joins two streaklines (all h are 0 or not "
                        "finite): check the point sources")
    best = np.lexsort((-h0s, lines, surfaces))[-1]  # most surfaces, then lines, then smallest h0
    return float(h0s[best])


def plan_surfaces(native, groups, h0) -> List[SurfacePlan]:
    """Clusters (h < h0, transitively) of every group, each in greedy minimum-length order. A
    group whose threshold is above its reach first gets the pairs up to it (``g.h`` widened in
    place, so that the live summary covers that h0 from then on)."""
    plans = []
    for g in groups.values():
        thr = group_threshold(native, g, h0)
        if thr > g.h.reach:
            g.h = g.h.with_reach(thr)
        for members in native.cluster_sources(g.h, thr):
            order = native.order_greedy(g.h, list(members))
            plans.append(SurfacePlan(group=g.group, threshold=thr,
                                     sources=[int(g.ids[i]) for i in order]))
    return plans


def streakline_grid(frame, sources, particles):
    """Points (nv, particles, 3) of the ordered streaklines at one frame, oldest particle first;
    particles not yet emitted sit at their source (where the youngest particle is born)."""
    counts = np.asarray(frame["counts"], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    pos = np.asarray(frame["positions"], dtype=np.float64)
    grid = np.empty((len(sources), particles, 3), dtype=np.float64)
    for row, s in enumerate(sources):
        line = pos[offsets[s]:offsets[s + 1]][:particles]
        grid[row, :len(line)] = line
        grid[row, len(line):] = line[-1]
    return grid


def surface_animation(native, frames, plan) -> SurfaceAnimation:
    """interpolate_surface (§3.3) of the cluster's streaklines at every frame."""
    particles = int(np.max(np.asarray(frames[-1]["counts"])[plan.sources]))
    particles = max(particles, 1)
    cps, dicts = [], []
    for frame in frames:
        s = native.interpolate_surface(streakline_grid(frame, plan.sources, particles),
                                       order_u=ORDER_U, order_v=ORDER_V)
        cps.append(np.asarray(s["control_points"], dtype=np.float32))
        dicts.append(s)
    s = dicts[-1]
    return SurfaceAnimation(nu=int(s["nu"]), nv=int(s["nv"]), order_u=int(s["order_u"]),
                            order_v=int(s["order_v"]), particles=particles,
                            control_points=np.stack(cps), surfaces=dicts)


def dense_density(native, path, resolution):
    """The density grid of a VDB frame as a dense float32 (nx, ny, nz) array."""
    out = np.zeros(tuple(resolution), dtype=np.float32)
    try:
        g = native.read_vdb_grid(path, "density")
    except RuntimeError as e:
        raise BakeError(f"Plume: {e} (bake the domain again)") from None
    vals = np.asarray(g["values"], dtype=np.float32)
    if vals.size == 0:
        return out
    lo = np.asarray(g["min"], dtype=np.int64)
    src_lo = np.maximum(-lo, 0)
    dst_lo = np.maximum(lo, 0)
    size = np.minimum(np.asarray(vals.shape[:3]) - src_lo, np.asarray(resolution) - dst_lo)
    if np.any(size <= 0):
        return out
    out[dst_lo[0]:dst_lo[0] + size[0], dst_lo[1]:dst_lo[1] + size[1],
        dst_lo[2]:dst_lo[2] + size[2]] = vals[src_lo[0]:src_lo[0] + size[0],
                                              src_lo[1]:src_lo[1] + size[1],
                                              src_lo[2]:src_lo[2] + size[2]]
    return out


def _uniform_columns(image, nodes, domain, rate):
    """Resamples the map's columns (at the particles' parameters plus `rate` between them) onto
    evenly spaced parameters over the drawn domain, which is how Blender lays out a SURFACE's
    generated UVs (u = sample index / (samples - 1))."""
    params = np.asarray(nodes, dtype=np.float64)
    cols = params if rate == 0 else np.concatenate(
        [np.linspace(a, b, rate + 2)[:-1] for a, b in zip(params[:-1], params[1:])] + [params[-1:]])
    if len(cols) != image.shape[1] or len(cols) < 2:
        return image
    xs = np.linspace(domain[0], domain[1], image.shape[1])
    return np.stack([np.interp(xs, cols, row) for row in image])


def density_image(native, surface, density, origin, cell_size, k_u, k_v, interpolation, particles,
                  lines):
    """§3.4 density map (rows = v, columns = u) on Blender's UV layout, float32."""
    img = np.asarray(native.density_map(surface, density, origin, cell_size, k_u, k_v,
                                        interpolation), dtype=np.float64)
    pu = np.asarray(surface["params_u"])[:particles]
    pv = np.asarray(surface["params_v"])[:lines]
    img = _uniform_columns(img, pu, surface["domain_u"], k_u)
    img = _uniform_columns(img.T, pv, surface["domain_v"], k_v).T
    return np.clip(img, 0.0, None).astype(np.float32)
