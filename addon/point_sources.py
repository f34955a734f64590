"""Tracer point sources of a traced bake ([Smoke Surfaces] §3.2-3.3), no ``bpy``: where each
Source's point sources are and which candidate group each belongs to.

    points, groups, velocities, emitting = domain_point_sources(native, params, snapshot)

A source's point sources are, by its point_placement: a ring around its outline across the flow
(RIM, the default; point_rim.py), cut into arcs that are candidate groups of their own; or
`point_sources` random points in each of its cells (CELLS, §3.2: "10-20 point sources are placed
randomly in a source cell"; a 0.25 m sphere at 40³ has ~670 cells, 10,000 streaklines at 16 per
cell, where the paper's sheets use 11-20); or the vertices of the mesh the artist picked
(point_source_mesh), one streakline per vertex. Placed points are cut down to the domain's
max_streaklines over all Sources. A source split in k candidate groups (candidate_split) is cut
into k groups of equal count along the axis of largest extent, so the streaklines of different
parts are never clustered into one surface (§3.3). Emission pauses on the frames where none of
the Sources with point sources has emit_particles on (Figure 10's gap).
"""

import numpy as np

from . import point_rim
from .settings import BakeError, candidate_groups


def domain_box(params):
    """(lo, hi) corners of the domain in world space, float32 as the native tracer computes them
    (origin + resolution * cell_size), so a point inside here is inside there."""
    lo = np.asarray(params.origin, dtype=np.float32)
    hi = lo + np.asarray(params.resolution, dtype=np.float32) * np.float32(params.cell_size)
    return lo, hi


def _vec(v):
    return "(" + ", ".join(f"{float(x):.4g}" for x in v) + ")"


def vertex_point_sources(params, domain_name, emitter):
    """The vertices of the source's point_source_mesh as point sources, float32 (N, 3); BakeError
    naming the source, the mesh and the domain when it has no vertices or one lies outside."""
    e = emitter
    points = np.ascontiguousarray(e.point_source_vertices, dtype=np.float32).reshape(-1, 3)
    if len(points) == 0:
        raise BakeError(f"Plume: source '{e.name}': point_source_mesh '{e.point_source_mesh}' has "
                        "no vertices (give it vertices, or clear Point Source Mesh in Physics "
                        "Properties › Plume › Source to place Point Sources random points per "
                        "source cell)")
    if not np.all(np.isfinite(points)):
        raise BakeError(f"Plume: source '{e.name}': point_source_mesh '{e.point_source_mesh}' has "
                        "vertices that are not finite numbers")
    lo, hi = domain_box(params)
    outside = np.flatnonzero(np.any((points < lo) | (points > hi), axis=1))
    if len(outside):
        first = int(outside[0])
        raise BakeError(
            f"Plume: source '{e.name}': {len(outside)} of the {len(points)} vertices of "
            f"its Point Source Mesh '{e.point_source_mesh}' lie outside domain '{domain_name}' "
            f"(box {_vec(lo)} to {_vec(hi)}), e.g. vertex {first} at {_vec(points[first])}: "
            "move the mesh inside the domain")
    return points


def _cells(native, params, emitter):
    """(cells int (N, 3), motion float32 (N, 3)) of a Source at the domain's first frame."""
    e = emitter
    try:
        return native.source_cells(e.vertices, e.triangles, e.matrix_at(0), e.matrix_at(1),
                                   params, e.name)
    except ValueError as err:
        raise BakeError(f"Plume: source '{e.name}': {err}") from None


def source_point_sources(native, params, domain_name, seed, emitter, index, gravity, count=None):
    """(positions, velocities), float32 (N, 3) each, of one Source's point sources (§3.2), or None
    when a source without point_source_mesh has no cell in the domain: its point_source_mesh's
    vertices; else for point_placement RIM a ring around its outline across the flow
    (point_rim.py; `count` points, or one per cell of its length when None); else (CELLS)
    point_sources random points per cell, seeded by the domain seed and the source's index
    among the Sources. Their velocity is the source's velocity plus its own motion
    (motion_factor) in their cell, as the solver writes into its cells; vertex point sources
    leave with the source's velocity. BakeError names the source."""
    e = emitter
    velocity = np.asarray(e.source.velocity, np.float32)
    if e.point_source_vertices is not None:
        points = vertex_point_sources(params, domain_name, e)
        return points, np.repeat(velocity[None, :], len(points), axis=0)
    cells, motion = _cells(native, params, e)
    if len(cells) == 0:
        return None
    motion = np.asarray(motion, np.float32).reshape(-1, 3) * np.float32(e.source.motion_factor)
    if e.point_placement == "RIM":
        axis = point_rim.flow_axis(e.source.velocity, gravity)
        grid = (params.resolution, params.cell_size, params.origin)
        if count is None:
            count = point_rim.natural_count(cells, grid, axis)
        points, rows = point_rim.rim_points(cells, grid, axis, count)
        return points, motion[rows] + velocity
    try:
        points = native.random_points_in_cells(
            cells, params.resolution, params.cell_size, params.origin, e.point_sources,
            seed=seed, stream=index)
    except ValueError as err:
        raise BakeError(f"Plume: source '{e.name}': {err}") from None
    return points, np.repeat(motion, e.point_sources, axis=0) + velocity


def split_groups(points, first_group, split, source_name=""):
    """Candidate group of each of a source's point sources (§3.3), int64 (N,): all `first_group`
    when split <= 1; else groups first_group .. first_group + split - 1 of equal count (sizes
    differ by at most one), in order of the position along the axis of largest extent (the first
    such axis on a tie; equal positions in index order). BakeError when a group would hold fewer
    than the 2 streaklines a surface needs."""
    points = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    n = len(points)
    if split <= 1:
        return np.full(n, first_group, dtype=np.int64)
    if n < 2 * split:
        raise BakeError(f"Plume: source '{source_name}': candidate_split {split} needs at least "
                        f"{2 * split} point sources (2 per candidate group, §3.3); it has {n}: "
                        "lower Split Into Groups (Physics Properties › Plume › Source) or add "
                        "point sources")
    axis = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
    order = np.argsort(points[:, axis], kind="stable")
    groups = np.empty(n, dtype=np.int64)
    groups[order] = first_group + (np.arange(n, dtype=np.int64) * split) // n
    return groups


def hand_groups(emitter, first_group):
    """Candidate group of each vertex of a Source's point source mesh from its vertex groups
    (§3.3: "close points can be assigned to different groups if desired by the user"): the
    groups used, in vertex-group order (vertices in none last), numbered from first_group.
    BakeError naming the group when one holds fewer than the 2 streaklines a surface needs."""
    e = emitter
    values, index, sizes = np.unique(np.asarray(e.point_source_groups, dtype=np.int64),
                                     return_inverse=True, return_counts=True)
    order = np.argsort(np.where(values < 0, np.iinfo(np.int64).max, values), kind="stable")
    rank = np.empty(len(values), dtype=np.int64)
    rank[order] = np.arange(len(values))
    for value, size in zip(values, sizes):
        if size < 2:
            names = e.point_source_group_names
            which = ("the vertices in no vertex group" if value < 0 else
                     f"vertex group '{names[value] if value < len(names) else value}'")
            raise BakeError(f"Plume: source '{e.name}': point_source_mesh '{e.point_source_mesh}':"
                            f" {which} holds {size} vertex; a hand-made candidate group needs at "
                            "least 2 (§3.3: a surface needs 2 streaklines)")
    return first_group + rank[index]


def thinning_quotas(counts, cap):
    """How many of each Source's placed point sources to keep so that about `cap` remain in all
    (`counts`: point sources per Source, Point Source Meshes left out): all when cap is 0 or not
    exceeded, else shares in proportion to the counts (largest remainders), each at least the 2
    a surface needs (or all, when a Source has fewer); so at most max(cap, 2 per Source)."""
    counts = np.asarray(counts, dtype=np.int64)
    total = int(counts.sum())
    if cap <= 0 or total <= cap:
        return counts.copy()
    exact = counts * (cap / total)
    quotas = np.floor(exact).astype(np.int64)
    for i in np.argsort(-(exact - quotas), kind="stable")[:cap - int(quotas.sum())]:
        quotas[i] += 1
    return np.minimum(counts, np.maximum(quotas, np.minimum(counts, 2)))


def thin(points, velocities, keep, seed, index):
    """`keep` of the rows of points/velocities, chosen at random (seeded by the domain seed and
    the Source's index), in their original order."""
    if keep >= len(points):
        return points, velocities
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0x7e57, int(index)])
    rows = np.sort(rng.choice(len(points), size=int(keep), replace=False))
    return points[rows], velocities[rows]


def group_counts(sources, placed):
    """Candidate groups each Source's point sources fall in (§3.3): a rim's arcs (point_rim.py),
    else its hand-made groups or candidate_split (settings.candidate_groups); `placed` maps a
    Source's index to its point sources."""
    counts = []
    for index, e in enumerate(sources):
        rim = e.point_placement == "RIM" and e.point_source_vertices is None
        if rim and index in placed:
            counts.append(point_rim.arc_count(len(placed[index][0]), e.candidate_split))
        else:
            counts.append(e.hand_groups or e.candidate_split)
    return counts


def source_groups(e, points, first_group):
    """Candidate group of each of a placed Source's point sources (§3.3)."""
    if e.hand_groups:
        return hand_groups(e, first_group)
    if e.point_placement == "RIM" and e.point_source_vertices is None:
        return point_rim.arc_groups(len(points), e.candidate_split, first_group)
    return split_groups(points, first_group, e.candidate_split, e.name)


def domain_point_sources(native, params, snapshot):
    """The point sources of every Source of a traced bake on the grid of SmokeParams `params`
    (§3.2-3.3), Sources in order: world positions float32 (N, 3), candidate groups int64 (N,),
    velocities float32 (N, 3) and the Sources that have point sources (emitter snapshots, for
    emits_during). Placed point sources (a rim, or random per source cell) are cut down to the
    domain's max_streaklines (thinning_quotas: a rim placed again with fewer points, random
    ones thinned at random); a Point Source Mesh's vertices are kept as picked. BakeError when
    no Source has a point source in the domain."""
    snap = snapshot
    sources = [e for e in snap.emitters if e.role == "SOURCE"]
    gravity = snap.solver.gravity
    placed = {}
    for index, e in enumerate(sources):
        p = source_point_sources(native, params, snap.domain_name, snap.solver.seed, e, index,
                                 gravity)
        if p is not None:
            placed[index] = p
    cut = [i for i in placed if sources[i].point_source_vertices is None]
    quotas = thinning_quotas([len(placed[i][0]) for i in cut], snap.streaks.max_streaklines)
    for index, keep in zip(cut, quotas):
        e = sources[index]
        if keep >= len(placed[index][0]):
            continue
        if e.point_placement == "RIM":
            placed[index] = source_point_sources(native, params, snap.domain_name,
                                                 snap.solver.seed, e, index, gravity, keep)
        else:
            placed[index] = thin(*placed[index], keep, snap.solver.seed, index)
    if not placed:
        raise BakeError(f"Plume: domain '{snap.domain_name}': streak surfaces need point "
                        "sources, but no Source object has a cell inside the domain")
    firsts = candidate_groups(snap.emitters, group_counts(sources, placed))
    emitting = [sources[i] for i in placed]
    points = [placed[i][0] for i in placed]
    groups = [source_groups(sources[i], placed[i][0], firsts[i]) for i in placed]
    check_memory(snap.domain_name, sum(len(p) for p in points), snap.frame_count,
                 max(1, snap.solver.substeps) / max(1, snap.streaks.emission_period))
    return (np.concatenate(points), np.concatenate(groups),
            np.concatenate([placed[i][1] for i in placed]), emitting)


#: Bytes per stored particle (position float32 x 3 + density float32) in the streak files, each
#: of which Build Surfaces holds in memory.
PARTICLE_BYTES = 16


def streak_bytes(streaklines, frames, particles_per_frame):
    """Bytes of every frame's streak file held together (Build Surfaces reads them all): each
    streakline gains `particles_per_frame` particles a frame and keeps them."""
    total_particles = particles_per_frame * frames * (frames + 1) / 2.0
    return streaklines * total_particles * PARTICLE_BYTES


def available_bytes():
    """MemAvailable of /proc/meminfo (Linux), or None where it cannot be read."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def check_memory(domain_name, streaklines, frames, particles_per_frame):
    """BakeError, before anything is written, when the streaklines of the whole shot would not
    fit in the memory this machine has free; names the count and the memory it needs."""
    need = streak_bytes(streaklines, frames, particles_per_frame)
    have = available_bytes()
    if have is not None and need > have:
        raise BakeError(
            f"Plume: domain '{domain_name}': {streaklines:,} streaklines over {frames} frames "
            f"hold {need / 2**30:.1f} GB of particles, more than the {have / 2**30:.1f} GB of "
            "memory free: lower Max Streaklines (Physics Properties › Plume › Streak "
            "Surfaces) or the Sources' Point Sources, or bake fewer "
            "frames")


def emits_during(sources, index):
    """Whether the tracer emits during frame frame_start + index (§3.2, Figure 10: "particle
    emission was turned off"): when one of `sources` (the Sources with point sources) has
    emit_particles on at that frame. The switch is per tracer, so that every streakline keeps the
    same particle count; a source that is off while another emits keeps emitting too, and its
    particles carry the density of the field there."""
    return any(e.source_at(index).emit_particles for e in sources)
