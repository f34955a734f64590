"""Meshes shared by the pytest files of the native module."""
import numpy as np


def box_mesh(lo, hi):
    """Axis-aligned box [lo, hi] as (vertices (8, 3), triangles (12, 3)), closed and manifold."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    vertices = np.array([[hi[0] if n & 1 else lo[0], hi[1] if n & 2 else lo[1],
                          hi[2] if n & 4 else lo[2]] for n in range(8)], dtype=np.float32)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    triangles = []
    for a, b, c, d in quads:
        triangles += [(a, b, c), (a, c, d)]
    return vertices, np.array(triangles, dtype=np.int32)
