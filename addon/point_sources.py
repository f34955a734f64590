"""Tracer point sources of a traced bake (smoke_surfaces.txt §3.2-3.3), no ``bpy``: where each
Source's point sources are and which candidate group each belongs to.

    points, velocities = source_point_sources(native, params, domain_name, seed, emitter, index)
    groups = split_groups(points, first_group, emitter.candidate_split, emitter.name)

A source's point sources are `point_sources` random points in each of its cells (§3.2: "10-20
point sources are placed randomly in a source cell"), thinned at random to the domain's
max_streaklines over all Sources (a 0.25 m sphere at 40³ has ~500 cells, 8,000 streaklines at 16
per cell, where the paper's sheets use 11-20), or the vertices of the mesh the artist picked
(point_source_mesh), one streakline per vertex. A source split in k candidate groups
(candidate_split) is cut into k groups of equal count along the axis of largest extent, so the
streaklines of different parts are never clustered into one surface (§3.3). Emission pauses on
the frames where none of the Sources with point sources has emit_particles on (Figure 10's gap).
"""

import numpy as np

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
                        "no vertices (give it vertices, or clear point_source_mesh to place "
                        "point_sources random points per source cell)")
    if not np.all(np.isfinite(points)):
        raise BakeError(f"Plume: source '{e.name}': point_source_mesh '{e.point_source_mesh}' has "
                        "vertices that are not finite numbers")
    lo, hi = domain_box(params)
    outside = np.flatnonzero(np.any((points < lo) | (points > hi), axis=1))
    if len(outside):
        first = int(outside[0])
        raise BakeError(
            f"Plume: source '{e.name}': {len(outside)} of the {len(points)} vertices of "
            f"point_source_mesh '{e.point_source_mesh}' lie outside domain '{domain_name}' "
            f"(box {_vec(lo)} to {_vec(hi)}), e.g. vertex {first} at {_vec(points[first])}: "
            "move the mesh inside the domain")
    return points


def source_point_sources(native, params, domain_name, seed, emitter, index):
    """(positions, velocities), float32 (N, 3) each, of one Source's point sources (§3.2), or None
    when a source without point_source_mesh has no cell in the domain. Random points are seeded by
    the domain seed and the source's index among the Sources; their velocity is the source's
    velocity plus its own motion (motion_factor), as the solver writes into its cells. Vertex
    point sources leave with the source's velocity. BakeError names the source."""
    e = emitter
    velocity = np.asarray(e.source.velocity, np.float32)
    if e.point_source_vertices is not None:
        points = vertex_point_sources(params, domain_name, e)
        return points, np.repeat(velocity[None, :], len(points), axis=0)
    try:
        cells, motion = native.source_cells(e.vertices, e.triangles, e.matrix_at(0),
                                            e.matrix_at(1), params, e.name)
        if len(cells) == 0:
            return None
        points = native.random_points_in_cells(
            cells, params.resolution, params.cell_size, params.origin, e.point_sources,
            seed=seed, stream=index)
    except ValueError as err:
        raise BakeError(f"Plume: source '{e.name}': {err}") from None
    vel = (np.repeat(np.asarray(motion, np.float32), e.point_sources, axis=0)
           * np.float32(e.source.motion_factor) + velocity)
    return points, vel


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
                        "lower candidate_split or add point sources")
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
    """How many of each Source's random point sources to keep so that about `cap` remain in all
    (`counts`: random point sources per Source): all when cap is 0 or not exceeded, else shares
    in proportion to the counts (largest remainders), each at least the 2 a surface needs (or
    all, when a Source has fewer); so at most max(cap, 2 per Source)."""
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


def domain_point_sources(native, params, snapshot):
    """The point sources of every Source of a traced bake on the grid of SmokeParams `params`
    (§3.2-3.3), Sources in order: world positions float32 (N, 3), candidate groups int64 (N,),
    velocities float32 (N, 3) and the Sources that have point sources (emitter snapshots, for
    emits_during). The random point sources (per source cell) are thinned to the domain's
    max_streaklines (thinning_quotas); a Point Source Mesh's vertices are kept as picked.
    BakeError when no Source has a point source in the domain."""
    snap = snapshot
    sources = [e for e in snap.emitters if e.role == "SOURCE"]
    placed = []
    for index, (e, group) in enumerate(zip(sources, candidate_groups(snap.emitters))):
        p = source_point_sources(native, params, snap.domain_name, snap.solver.seed, e, index)
        if p is not None:
            placed.append((index, e, group, *p))
    random = [k for k, (_i, e, *_rest) in enumerate(placed) if e.point_source_vertices is None]
    quotas = thinning_quotas([len(placed[k][3]) for k in random], snap.streaks.max_streaklines)
    for k, keep in zip(random, quotas):
        index, e, group, points, vel = placed[k]
        placed[k] = (index, e, group, *thin(points, vel, keep, snap.solver.seed, index))
    emitting, all_points, all_groups, all_vel = [], [], [], []
    for _index, e, group, points, vel in placed:
        emitting.append(e)
        all_points.append(points)
        all_vel.append(vel)
        all_groups.append(hand_groups(e, group) if e.hand_groups else
                          split_groups(points, group, e.candidate_split, e.name))
    if not all_points:
        raise BakeError(f"Plume: domain '{snap.domain_name}': streak surfaces need point "
                        "sources, but no Source object has a cell inside the domain")
    check_memory(snap.domain_name, sum(len(p) for p in all_points), snap.frame_count,
                 max(1, snap.solver.substeps) / max(1, snap.streaks.emission_period))
    return (np.concatenate(all_points), np.concatenate(all_groups), np.concatenate(all_vel),
            emitting)


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
            "memory free: lower max_streaklines (or the Sources' point_sources), or bake fewer "
            "frames")


def emits_during(sources, index):
    """Whether the tracer emits during frame frame_start + index (§3.2, Figure 10: "particle
    emission was turned off"): when one of `sources` (the Sources with point sources) has
    emit_particles on at that frame. The switch is per tracer, so that every streakline keeps the
    same particle count; a source that is off while another emits keeps emitting too, and its
    particles carry the density of the field there."""
    return any(e.source_at(index).emit_particles for e in sources)
