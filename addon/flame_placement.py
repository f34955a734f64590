"""Where and when the flames of a Flame Source burn, no ``bpy`` ([Structural Flames] §4.1 "a
fixed point on the burning surface", §6.2 flame spread): flames placed deterministically on a
mesh's up-facing faces, greyscale maps sampled at their UVs, and the spread model of eq. 7."""

import numpy as np

#: A face is "up-facing" when its world normal has a Z component of at least this.
UP_FACING = 0.3
#: Candidate points drawn per flame before the even (farthest-point) selection.
CANDIDATES_PER_FLAME = 64


def face_data(vertices, triangles):
    """(areas (M,), unit normals (M, 3)) of the triangles of world-space `vertices`."""
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    cross = np.cross(b - a, c - a)
    norm = np.linalg.norm(cross, axis=1)
    return 0.5 * norm, cross / np.maximum(norm, 1e-30)[:, None]


def canonical_order(triangles):
    """A permutation putting the triangles in an order that does not depend on how Blender
    listed them (its primitives do not list faces in the same order from one session to the
    next): each triangle keyed by its vertex indices rotated to start at the smallest (winding
    kept), sorted. Placement through it gives the same flames for a seed in every session."""
    tris = np.asarray(triangles, np.int64).reshape(-1, 3)
    if not len(tris):
        return np.zeros(0, np.int64)
    first = np.argmin(tris, axis=1)
    keyed = tris[np.arange(len(tris))[:, None], (first[:, None] + np.arange(3)) % 3]
    return np.lexsort(keyed.T[::-1])


def place_flames(world_vertices, triangles, count, seed):
    """`count` flame places on the mesh: (face index (k,), barycentric (k, 3)), deterministic for
    a seed. Candidates are area-weighted random points on the up-facing faces (all faces when
    none faces up); one flame takes the candidate nearest to their area-weighted centre (the top
    of a wick or a torch head), more flames are spread evenly by farthest-point selection from
    there."""
    triangles = np.asarray(triangles, np.int64).reshape(-1, 3)
    vertices = np.asarray(world_vertices, np.float64).reshape(-1, 3)
    areas, normals = face_data(vertices, triangles)
    weights = np.where(normals[:, 2] >= UP_FACING, areas, 0.0)
    if weights.sum() <= 0.0:
        weights = areas
    weights = weights / weights.sum()
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, count])
    m = max(CANDIDATES_PER_FLAME * count, 16)
    faces = rng.choice(len(triangles), size=m, p=weights)
    r1, r2 = rng.random(m), rng.random(m)
    s = np.sqrt(r1)
    bary = np.stack([1.0 - s, s * (1.0 - r2), s * r2], axis=1)
    points = np.einsum("ki,kij->kj", bary, vertices[triangles[faces]])
    centroids = vertices[triangles].mean(axis=1)
    centre = (weights[:, None] * centroids).sum(axis=0)
    chosen = [int(np.argmin(np.linalg.norm(points - centre, axis=1)))]
    dist = np.linalg.norm(points - points[chosen[0]], axis=1)
    for _ in range(1, count):
        nxt = int(np.argmax(dist))
        chosen.append(nxt)
        dist = np.minimum(dist, np.linalg.norm(points - points[nxt], axis=1))
    chosen = np.asarray(chosen)
    return faces[chosen], bary[chosen]


def interpolate(corner_values, faces, bary):
    """Per-corner values (M, 3, c) of the chosen faces mixed by the barycentrics: (k, c)."""
    return np.einsum("ki,kic->kc", bary, np.asarray(corner_values)[faces])


def sample_map(image, uvs):
    """Greyscale (mean of R, G, B) of `image` (h, w, ≥3 floats, row 0 at the bottom: Blender's
    pixel order) at `uvs` (k, 2), bilinear. UVs outside [0, 1) repeat the image, but the filter
    holds the edge texels (no blending across the border): a map describes one surface, and
    blending its opposite edge in would light a left-to-right ramp's edge flames half-way."""
    h, w = image.shape[:2]
    grey = np.asarray(image[..., :3], np.float64).mean(axis=2)
    c = np.asarray(uvs, np.float64)
    c = np.where((c >= 0.0) & (c <= 1.0), c, c % 1.0)  # a UV of exactly 1 is the right edge
    x, y = c[:, 0] * w - 0.5, c[:, 1] * h - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - x0, y - y0
    out = np.zeros(len(x))
    for dx, dy, wgt in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)),
                        (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        out += wgt * grey[np.clip(y0 + dy, 0, h - 1), np.clip(x0 + dx, 0, w - 1)]
    return out


def spread_times(points, ignition, flame_temperature, thickness, height, minimum=0.05):
    """Eq. 7 (Perry & Picard 1994): activation time (s) of each point (k, 3) for a front leaving
    `ignition` at v_s = T_f / L (cos θ + h sin θ). Read here with θ the elevation of the
    direction from the ignition point to the point (upward spread is faster: the flame leans
    over the unburnt surface) and the time = straight distance / v_s; v_s is kept at least
    `minimum` · T_f / L so that downward spread (cos θ + h sin θ < 0) is slow but happens."""
    d = np.asarray(points, np.float64) - np.asarray(ignition, np.float64)
    dist = np.linalg.norm(d, axis=1)
    theta = np.arcsin(np.clip(d[:, 2] / np.maximum(dist, 1e-12), -1.0, 1.0))
    base = flame_temperature / thickness
    v = base * np.maximum(np.cos(theta) + height * np.sin(theta), minimum)
    return np.where(dist > 0.0, dist / v, 0.0)

