"""Streak surfaces from a baked cache, no ``bpy`` ([Smoke Surfaces] §3.3-3.4): reads the
streak files, computes h per candidate group, clusters with h0, orders greedily, and turns each
cluster into per-frame NURBS control points and density maps.

    frames = load_frames(native, folder, frame_start, last_frame)
    groups = group_distances(native, frames)           # {group: GroupDistances}
    plans = plan_surfaces(native, groups, h0)          # one SurfacePlan per cluster
    anim = surface_animation(native, frames, plan, cell_size)   # control points per frame

The distances are sparse (native StreakDistances): each group holds every pair with h below its
reach, exactly, and no n x n matrix. The reach starts at the group's default h0 (the mean of h)
and grows when a build asks for a larger threshold; clusters, counts and the Figure 4 curve are
exact up to it, the greedy order always.

The surface of a cluster is a least-squares fit, not an interpolation, so that an artist can
edit its control net by hand (the paper's §5): a net that
interpolates every particle slot (nu = particles per streakline, the slots of particles not yet
emitted stacked on the youngest, the particles that left the box flying on at their exit
velocities) swings metres away from the smoke, so an artist moving a control point moved
something far off. The fit (native nurbs/shot_fit.h) goes through the particles of fit_mask(),
keeps each within FIT_TOLERANCE_CELLS of the sheet and every control point within
NET_TOLERANCE_CELLS of it and NEAR_TOLERANCE_CELLS of a particle, with the smallest net that
does so on every frame (fixed for the shot, as Blender's net is), or, where the particles
scatter too much for any, the cubic net whose control points are the particles. Where the streaklines leave
the simulated box through an open side the sheet ends: no smoke is simulated past it (density 0,
as the tracer gives those particles).
"""

import os
from dataclasses import dataclass
from typing import Dict, List

import numpy as np

from . import cache
from .settings import BakeError

#: Orders of the surfaces (cubic, lower when there are fewer points, as Blender allows).
ORDER_U = ORDER_V = 4
#: ε in cells: no particle of fit_mask() is farther than this from its sheet on any frame. Half
#: a cell is the grid's own detail: the velocity the particles follow and the density the map
#: reads are interpolated between cell centres a cell apart, so a sheet within half a cell of a
#: particle reads the density the particle carries, while runs of particles that wobble below
#: that need no control point of their own.
FIT_TOLERANCE_CELLS = 0.5
#: δ in cells: no control point is farther than this from the sheet at its Greville abscissae
#: (the point it pulls hardest), so the net an artist edits hugs the smoke where streaklines
#: curl; with ε this keeps control points within about 3 cells of the particles.
NET_TOLERANCE_CELLS = 1.5
#: ν in cells: no control point is farther than this from the nearest particle the frame's sheet
#: goes through (a control point an artist grabs sits among the particles it shapes), or than
#: half the largest gap between consecutive particles of a streakline on frames where they are
#: farther apart (a fast source early in its shot). Where no net of order 4 or 3 keeps to ε, δ
#: and ν (a plume's top scattering late in its shot), the control points along the streaklines
#: are the particles themselves and the sheet stays cubic (C², no facets in a close-up), cutting
#: the corners of the zig-zags by |Δ²p|/6 (native nurbs/shot_fit.h: the particle net); across
#: them likewise where that keeps the sheet within ν of every particle, else order 2.
NEAR_TOLERANCE_CELLS = 3.0


@dataclass
class GroupDistances:
    """h(α,β) of one candidate group (§3.3): ``h`` is a native StreakDistances holding every pair
    with h < h.reach exactly (members 0..n-1 are the source IDs ``ids``)."""

    group: int
    ids: np.ndarray
    h: object


@dataclass
class HeldDistances:
    """What Blender keeps of one group's h when a job's child computed it (Build Surfaces): the
    held pairs, the mean, the reach and Figure 4's curve, as plain arrays. Enough for the
    panel's live count (summary()) and Most Surfaces' pick; clustering needs the native
    StreakDistances (compute_distances(), or the next build)."""

    size: int
    mean: float
    reach: float
    a: np.ndarray
    b: np.ndarray
    h: np.ndarray
    values: np.ndarray
    surfaces: np.ndarray
    lines: np.ndarray

    def pairs(self):
        return self.a, self.b, self.h

    def curve(self):
        return self.values, self.surfaces, self.lines

    def summary(self, h0):
        """(surfaces, streaklines) for threshold h0, as the native cluster_summary (pairs with
        h < h0 joined); ValueError above the reach or for a bad h0."""
        if not np.isfinite(h0) or h0 < 0.0:
            raise ValueError(f"h0 must be a finite number >= 0 (got {h0})")
        if h0 > self.reach:
            raise ValueError(f"h0 = {h0} is above the reach {self.reach} of these distances")
        below = int(np.searchsorted(self.values, h0, side="left"))
        return (0, 0) if below == 0 else (int(self.surfaces[below - 1]),
                                          int(self.lines[below - 1]))


def held_distances(groups):
    """{group: GroupDistances with h a HeldDistances}: the plain-data copy a child returns."""
    out = {}
    for key, g in groups.items():
        a, b, h = g.h.pairs()
        values, surfaces, lines = g.h.curve()
        out[key] = GroupDistances(group=g.group, ids=np.asarray(g.ids), h=HeldDistances(
            size=int(g.h.size), mean=float(g.h.mean), reach=float(g.h.reach), a=np.asarray(a),
            b=np.asarray(b), h=np.asarray(h), values=np.asarray(values),
            surfaces=np.asarray(surfaces), lines=np.asarray(lines)))
    return out


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
    particles: int  # particles per streakline at the last frame (sets the density map's width)
    control_points: np.ndarray  # float32 (frames, nv * nu, 4), Blender's flat order v*nu+u
    surfaces: list  # per frame: a surface dict (control points, orders, particle parameters)
    max_residual: np.ndarray  # per frame: largest particle-to-sheet distance (an upper bound)
    net_deviation: np.ndarray  # per frame: largest control point-to-sheet distance
    #: The control points along the streaklines are the particles (the cubic particle net where
    #: they scatter), and across them the rows are the lines' curves (NEAR_TOLERANCE_CELLS).
    particle_net_u: bool = False
    particle_net_v: bool = False


def streak_manifest(folder, domain_name):
    """The manifest of a bake with streak surfaces; BakeError saying what is missing."""
    m = cache.read_manifest(folder)
    if m is None or m.get("last_complete_frame", -1) < m.get("frame_start", 0):
        raise BakeError(f"Plume: domain '{domain_name}' has no bake yet: turn on Streak Surfaces "
                        "and bake it first (Physics Properties › Plume › Streak Surfaces, then "
                        "Bake)")
    if not m.get("streaks"):
        raise BakeError(f"Plume: domain '{domain_name}' was baked without streak surfaces: turn "
                        "on Streak Surfaces (Physics Properties › Plume › Streak Surfaces) and "
                        "bake again")
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
                "a surface needs at least 2: raise the source's Point Sources or give it the "
                "Candidate Group of another source (Physics Properties › Plume › Source)")
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
    if h0 > 0.0:
        return float(h0)
    return g.h.mean if isinstance(g.h, HeldDistances) else float(native.default_threshold(g.h))


def summary(native, groups, h0):
    """(surfaces, streaklines) for threshold h0 over all groups (Figure 4), from each group's
    curve in O(log pairs). Exact whenever each group's threshold (h0 > 0, else its default) is
    <= its reach: always for h0 = 0 and for any h0 up to the smallest group mean, and up to the
    largest threshold built so far. Above a group's reach, ValueError naming it (the pairs that
    would decide are not held; Build Surfaces at that h0 widens them)."""
    surfaces = lines = 0
    for g in groups.values():
        h0_g = group_threshold(native, g, h0)
        s, n = (g.h.summary(h0_g) if isinstance(g.h, HeldDistances)
                else native.cluster_summary(g.h, h0_g))
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
    below the mean of h in practice, where the mean joins nearly everything).

    The h0 returned lies midway in the step of the curve it picks (every h0 in (v_k, v_k+1]
    gives the same clustering), as a float32: the domain's streak_threshold is a single-precision
    property, and a value just above v_k would round to v_k or below it and lose the peak."""
    reach = min(float(g.h.reach) for g in groups.values())
    curves = [g.h.curve() for g in groups.values()]
    values = np.unique(np.concatenate([c[0] for c in curves]))
    values = values[values < reach]
    h0s = step_midpoints(values, reach)
    keep = np.isfinite(h0s)
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


def step_midpoints(values, reach):
    """For sorted values v_k < reach: a float32 h0 in each step (v_k, min(v_k+1, reach)] of the
    curve, near its middle; NaN for a step too narrow to hold a float32 strictly above v_k."""
    upper = np.append(values[1:], reach)
    mid = (0.5 * (values + upper)).astype(np.float32).astype(np.float64)
    above = np.nextafter(values.astype(np.float32), np.float32(np.inf)).astype(np.float64)
    low = mid <= values
    mid[low] = above[low]  # float32 rounding fell to v_k or below: the next float32 up
    mid[(mid <= values) | (mid > upper)] = np.nan
    return mid


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
    particles not yet emitted sit at their source, where the youngest is (fit_mask leaves them
    out)."""
    counts = np.asarray(frame["counts"], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    pos = np.asarray(frame["positions"], dtype=np.float64)
    grid = np.empty((len(sources), particles, 3), dtype=np.float64)
    for row, s in enumerate(sources):
        line = pos[offsets[s]:offsets[s + 1]][:particles]
        grid[row, :len(line)] = line
        grid[row, len(line):] = line[-1]
    return grid


def fit_mask(frame, sources, particles):
    """Which particles (nv, particles) bool the frame's sheet goes through: on every streakline
    the particles emitted so far from its source up to the first one that left the simulated
    box through an open side (those carry no smoke: the tracer gives them density 0, and each
    flies on with its own exit velocity, so a line past them is a scatter metres long, which a
    smooth sheet cannot follow). Older particles still inside beyond such a gap are stragglers
    of a line that has mostly left; the sheet ends before them. The youngest particle is always
    kept, so every streakline has a place on the sheet."""
    counts = np.asarray(frame["counts"], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    outside = np.asarray(frame["outside"], dtype=bool)
    keep = np.zeros((len(sources), particles), dtype=bool)
    for row, s in enumerate(sources):
        n = min(int(counts[s]), particles)
        gone = np.flatnonzero(outside[offsets[s]:offsets[s] + n])
        first = int(gone[-1]) + 1 if len(gone) else 0
        keep[row, min(first, n - 1):n] = True
    return keep


def surface_animation(native, frames, plan, cell_size, tolerance_cells=FIT_TOLERANCE_CELLS,
                      net_tolerance_cells=NET_TOLERANCE_CELLS,
                      near_tolerance_cells=NEAR_TOLERANCE_CELLS, box=None) -> SurfaceAnimation:
    """The least-squares surfaces (§3.3, native fit_streak_shot) of the cluster's streaklines at
    every frame, on one control net chosen for the whole shot, through the particles of
    fit_mask() (not those not yet emitted, nor those past the open sides). With `box` (lo, hi),
    the domain's corners, control points are kept inside it: a net fitted to a line that ends
    at an open side may put its last control point up to δ past it (a stirred plume reaching
    the top: 0.9 cells), where no smoke is simulated and an artist would find it off the box."""
    particles = max(int(np.max(np.asarray(frames[-1]["counts"])[plan.sources])), 1)
    grids = np.stack([streakline_grid(f, plan.sources, particles) for f in frames])
    keep = np.stack([fit_mask(f, plan.sources, particles) for f in frames])
    shot = native.fit_streak_shot(grids.astype(np.float32), keep.astype(np.uint8),
                                  tolerance=tolerance_cells * cell_size,
                                  net_tolerance=net_tolerance_cells * cell_size,
                                  particle_tolerance=near_tolerance_cells * cell_size,
                                  order_u=ORDER_U, order_v=ORDER_V)
    cps = np.array(shot["control_points"], dtype=np.float32)
    if box is not None:
        np.clip(cps[..., :3], np.asarray(box[0], np.float32), np.asarray(box[1], np.float32),
                out=cps[..., :3])
    head = {k: int(shot[k]) for k in ("nu", "nv", "order_u", "order_v")}
    dicts = [dict(head, control_points=cps[n], endpoint_u=True, endpoint_v=True,
                  params_u=np.asarray(shot["params_u"][n]), params_v=np.asarray(shot["params_v"][n]),
                  keep=keep[n]) for n in range(len(frames))]
    return SurfaceAnimation(particles=particles, control_points=cps, surfaces=dicts,
                            max_residual=np.asarray(shot["max_residual"]),
                            net_deviation=np.asarray(shot["net_deviation"]),
                            particle_net_u=bool(shot["particle_net_u"]),
                            particle_net_v=bool(shot["particle_net_v"]), **head)


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


#: Largest side of a density map, pixels. The paper's supersampling is for particles far apart
#: (§3.4); a surface of thousands of streaklines has them closer than the grid resolves, and a
#: map of (lines - 1)(k_v + 1) + 1 rows would only cost memory, EXR writing time (about 0.1 µs a
#: pixel) and, past 16,384, GPU textures that EEVEE cannot load.
MAX_MAP_SIDE = 2048


def density_image_size(particles, lines, k_u, k_v):
    """(width, height) of a surface's §3.4 map: as many samples as the paper's k_u (k_v) between
    consecutive particles (streaklines) would give, (n - 1)(k + 1) + 1, at least 2 and at most
    MAX_MAP_SIDE (the samples stay evenly spread over the surface's parameters)."""
    return tuple(min(max((n - 1) * (k + 1) + 1, 2), MAX_MAP_SIDE)
                 for n, k in ((particles, k_u), (lines, k_v)))


def density_image(native, surface, density, origin, cell_size, k_u, k_v, interpolation, particles,
                  lines):
    """§3.4 density map (rows = v, columns = u) on Blender's UV layout, float32: sampled at
    evenly spaced parameters over the drawn domain, where Blender's generated UVs put pixel x at
    u = x / (width - 1) (the fitted surface's particles sit at chord-length parameters, so the
    even samples are also evenly spread along the smoke). 0 outside the simulated box."""
    width, height = density_image_size(particles, lines, k_u, k_v)
    img = native.density_map_on_domain(surface, density, origin, cell_size, width, height,
                                       interpolation)
    return np.clip(np.asarray(img, dtype=np.float32), 0.0, None)
