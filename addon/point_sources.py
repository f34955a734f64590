"""Tracer point sources of a traced bake (smoke_surfaces.txt §3.2-3.3), no ``bpy``: where each
Source's point sources are and which candidate group each belongs to.

    points, velocities = source_point_sources(native, params, domain_name, seed, emitter, index)
    groups = split_groups(points, first_group, emitter.candidate_split, emitter.name)

A source's point sources are `point_sources` random points in each of its cells (§3.2: "10-20
point sources are placed randomly in a source cell"), or the vertices of the mesh the artist
picked (point_source_mesh), one streakline per vertex. A source split in k candidate groups
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


def domain_point_sources(native, params, snapshot):
    """The point sources of every Source of a traced bake on the grid of SmokeParams `params`
    (§3.2-3.3), Sources in order: world positions float32 (N, 3), candidate groups int64 (N,),
    velocities float32 (N, 3) and the Sources that have point sources (emitter snapshots, for
    emits_during). BakeError when no Source has a point source in the domain."""
    snap = snapshot
    sources = [e for e in snap.emitters if e.role == "SOURCE"]
    emitting, all_points, all_groups, all_vel = [], [], [], []
    for index, (e, group) in enumerate(zip(sources, candidate_groups(snap.emitters))):
        placed = source_point_sources(native, params, snap.domain_name, snap.solver.seed, e, index)
        if placed is None:
            continue
        points, vel = placed
        emitting.append(e)
        all_points.append(points)
        all_vel.append(vel)
        all_groups.append(split_groups(points, group, e.candidate_split, e.name))
    if not all_points:
        raise BakeError(f"Plume: domain '{snap.domain_name}': streak surfaces need point "
                        "sources, but no Source object has a cell inside the domain")
    return (np.concatenate(all_points), np.concatenate(all_groups), np.concatenate(all_vel),
            emitting)


def emits_during(sources, index):
    """Whether the tracer emits during frame frame_start + index (§3.2, Figure 10: "particle
    emission was turned off"): when one of `sources` (the Sources with point sources) has
    emit_particles on at that frame. The switch is per tracer, so that every streakline keeps the
    same particle count; a source that is off while another emits keeps emitting too, and its
    particles carry the density of the field there."""
    return any(e.source_at(index).emit_particles for e in sources)
