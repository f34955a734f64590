"""Rim placement of a Source's point sources ([Smoke Surfaces] §3.2-3.3), no ``bpy``: a ring
of point sources around the source's outline, seen along the direction the smoke leaves it.

The paper's sheets come from 10-20 point sources in one to four source cells: a source a cell or
two wide. On a source many cells wide, point sources in every cell fill the smoke's whole volume
with streaklines, and any sheet through them folds back and forth across the column (a 0.25 m
sphere at 40³: 256 streaklines in one sheet, about 25 layers over a pixel, a solid white column).
Streaklines from a ring around the outline instead give sheets that wrap the smoke, the way a
smoke wire around a nozzle shows a jet: two layers over a pixel, bright at the silhouettes
(p = d e^(−|n·v|), §3.4). The ring is cut into arcs of about ARC_POINTS point sources, each its own
candidate group (§3.3: "point sources located far from each other are likely to belong to
different candidate groups"), so a source gives a few sheets of the paper's size.

    points, rows = rim_points(cells, grid, axis, count)   # grid: (resolution, cell_size, origin)
    groups = arc_groups(len(points), split, first_group)
"""

import numpy as np

#: Point sources per arc (one candidate group each): the paper's surfaces join up to 11 of its
#: 20 streaklines (Figure 1).
ARC_POINTS = 8
#: Fewest point sources on a rim (a one-cell source: a ring of this many inside the cell).
MIN_POINTS = 8
#: Directions the rim's length is measured with before its point count is known.
PROBE_DIRECTIONS = 64
#: A ray passes through a cell when the cell's centre is within this many cells of it (half
#: the diagonal of a cell's square).
HALF_DIAGONAL = 0.5 * 2.0 ** 0.5
#: Directions (and ring points) handled at a time: memory CHUNK x slab cells.
CHUNK = 64
#: How far out towards the outline the ring lies (1: on it). At the outline the smoke is thin (its
#: density falls to the air's within a cell or two of the source's edge, and sheets there render
#: faint face-on); four fifths of the way out the streaklines still wrap the smoke.
RADIUS = 0.8
#: Share of a cell's distance from a direction's ray taken off its distance along it when the
#: farthest cell is chosen: small enough not to pass over a cell a whole cell farther out within
#: 20 cells of the ray, large enough to break ties between level cells.
TIE_WEIGHT = 0.05


def flow_axis(velocity, gravity):
    """Unit direction the smoke leaves the source along: its initial velocity when it has one,
    else against gravity (buoyancy lifts it), else +z."""
    for v, sign in ((velocity, 1.0), (gravity, -1.0)):
        v = np.asarray(v, dtype=np.float64) * sign
        n = float(np.linalg.norm(v))
        if n > 1e-9:
            return v / n
    return np.array([0.0, 0.0, 1.0])


def _plane(axis):
    """Two unit vectors e1, e2 that, with axis, make a right-handed orthonormal frame (e1 from
    the world axis least aligned with `axis`, so the frame is the same on every call)."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    e1 = np.cross(helper, axis)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(axis, e1)


def _centres(cells, grid):
    """World centres (N, 3) of the cells with linear indices i + nx (j + ny k) `cells` on
    `grid` = (resolution, cell_size, origin)."""
    resolution, cell_size, origin = grid
    nx, ny = int(resolution[0]), int(resolution[1])
    c = np.asarray(cells, dtype=np.int64).ravel()
    ijk = np.stack([c % nx, (c // nx) % ny, c // (nx * ny)], axis=1)
    return np.asarray(origin, np.float64) + (ijk + 0.5) * float(cell_size)


def _slab(cells, grid, axis):
    """World centres (N, 3) of the source cells in the layer through the source's centroid,
    across `axis` (the layer of the cell whose height is nearest the centroid's, one cell
    thick), and their indices into `cells`."""
    cell_size = grid[1]
    centres = _centres(cells, grid)
    height = (centres - centres.mean(axis=0)) @ axis
    middle = height[int(np.argmin(np.abs(height)))]
    half = 0.5 * float(cell_size) * float(np.abs(axis).sum())  # a cell's half-extent along axis
    rows = np.flatnonzero(np.abs(height - middle) <= half + 1e-9 * float(cell_size))
    return centres[rows], rows


def _reach(x, y, c, s, cell_size):
    """Distance from the slab's centre to its outline along each direction (c, s): the farthest
    reach along the ray of the cells it passes through (centre within half a cell's diagonal of
    it), plus half a cell; where the ray meets no cell (a gap in a hollow source), that of the
    farthest cell, the one nearest the ray among level ones (TIE_WEIGHT)."""
    along = np.outer(c, x) + np.outer(s, y)
    across = np.abs(np.outer(c, y) - np.outer(s, x))  # each cell's distance from each ray
    on_ray = np.where(across <= HALF_DIAGONAL * cell_size, along, -np.inf).max(axis=1)
    far = np.argmax(along - TIE_WEIGHT * across, axis=1)
    fallback = along[np.arange(len(c)), far]
    return np.where(np.isfinite(on_ray), on_ray, fallback) + 0.5 * cell_size


def _ring(centres, cell_size, axis, count):
    """`count` points, one per direction 2πk/count around the slab's centre, RADIUS of the way
    out to its outline (_reach); and the row in `centres` of the cell each lies in."""
    cell_size = float(cell_size)
    e1, e2 = _plane(axis)
    middle = centres.mean(axis=0)
    x, y = (centres - middle) @ e1, (centres - middle) @ e2
    theta = 2.0 * np.pi * np.arange(count) / count
    c, s = np.cos(theta), np.sin(theta)
    reach = np.concatenate([_reach(x, y, c[k:k + CHUNK], s[k:k + CHUNK], cell_size)
                            for k in range(0, count, CHUNK)])
    ring = middle + (RADIUS * reach)[:, None] * (np.outer(c, e1) + np.outer(s, e2))
    # The slab cell each ring point lies in (nearest centre); a point of a hollow source that
    # falls outside every cell moves to the centre of the nearest one.
    nearest = np.concatenate([
        np.argmin(((ring[k:k + CHUNK, None, :] - centres[None, :, :]) ** 2).sum(axis=2), axis=1)
        for k in range(0, count, CHUNK)])
    inside = np.all(np.abs(ring - centres[nearest]) <= 0.5 * cell_size, axis=1)
    return np.where(inside[:, None], ring, centres[nearest]), nearest


def natural_count(cells, grid, axis):
    """Point sources a rim gets when nothing caps it: one per cell of its length (at least
    MIN_POINTS)."""
    cell_size = float(grid[1])
    centres, _rows = _slab(cells, grid, axis)
    ring, _far = _ring(centres, cell_size, axis, PROBE_DIRECTIONS)
    length = float(np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1).sum())
    return max(MIN_POINTS, int(round(length / cell_size)))


def rim_points(cells, grid, axis, count):
    """`count` point sources around the outline of the source cells `cells` (linear indices
    i + nx (j + ny k) on `grid` = (resolution, cell_size, origin)) across `axis`: float32
    (count, 3) world positions in ring order, each inside a source cell; and the index into
    `cells` of that cell (int64)."""
    centres, rows = _slab(cells, grid, axis)
    points, far = _ring(centres, float(grid[1]), axis, int(count))
    return points.astype(np.float32), rows[far].astype(np.int64)


def arc_groups(count, split, first_group):
    """Candidate group of each of `count` rim point sources in ring order, int64: `split` arcs of
    equal count (sizes differ by at most one) when split > 1, else arcs of about ARC_POINTS;
    numbered from first_group."""
    arcs = arc_count(count, split)
    return first_group + (np.arange(count, dtype=np.int64) * arcs) // max(count, 1)


def arc_count(count, split):
    """Arcs (candidate groups) a rim of `count` point sources is cut into: `split` when > 1 (at
    most count // 2, two streaklines a surface), else about one per ARC_POINTS."""
    if split > 1:
        return max(1, min(int(split), count // 2))
    return max(1, int(round(count / ARC_POINTS)))
