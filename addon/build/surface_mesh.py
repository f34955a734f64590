"""Mesh export of a streak surface: the current frame's control net refined with OpenSubdiv
(_native.subdivide_mesh, Catmull-Clark to the limit surface) into a MESH object carrying the §3.4
density map of that frame as the float point attribute "density" (clamped to [0, 1], like the
sheet material's opacity), for other render engines and quick previews."""

import os
import re

import bpy
import numpy as np

from .. import cache
from ..native import _native
from ..settings import BakeError
from ..jobs import kinds
from . import surface_edits
from .surfaces import CACHE_KEY, cache_of

#: Custom property of an exported mesh object: the surface it came from.
SOURCE_KEY = "plume_mesh_of"


def mesh_name(ob):
    return f"{ob.name}_mesh"


def expected_vertex_count(nu, nv, level):
    return ((nu - 1) * 2 ** level + 1) * ((nv - 1) * 2 ** level + 1)


def sheet_file(ob, frame):
    """The density-map EXR of the surface at `frame` (clamped to the cached frames)."""
    path = bpy.path.abspath(ob[CACHE_KEY])
    m = re.search(r"surface_(\d+)\.npz$", path)
    hit = cache_of(ob)
    if m is None or hit is None:
        raise BakeError(f"Plume: the control-point cache of surface '{ob.name}' ({path}) is "
                        "missing or does not match its control net: build the surfaces again")
    frame_start, cps = hit
    f = min(max(frame, frame_start), frame_start + len(cps) - 1)
    sheet = cache.sheet_path(os.path.dirname(path), int(m.group(1)), f)
    if not os.path.isfile(sheet):
        raise BakeError(f"Plume: density map {sheet} of surface '{ob.name}' is missing: build "
                        "the surfaces again (Physics Properties › Plume › Streak Surfaces › Build "
                        "Surfaces)")
    return sheet


def read_density(path):
    """The density map (rows = v, columns = u) of a sheet EXR, float32."""
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return np.ascontiguousarray(px.reshape(h, w, 4)[..., 0])


def net_layout(density, sp):
    """The sheet's density map, laid out evenly over the drawn domain as Blender's generated UVs
    are, resampled (bilinearly) onto the layout subdivide_mesh refines as a primvar: pixel
    (a (k + 1), b (k + 1)) at control point (a, b)'s Greville abscissae, k pixels evenly between
    neighbours (k as fine as the map)."""
    def coords(n, order, endpoint, size):
        g = np.asarray(_native.greville_abscissae(n, order, endpoint), dtype=np.float64)
        lo, hi = _native.nurbs_domain(n, order, endpoint)
        k = max(int(round((size - 1) / (n - 1))) - 1, 0)
        t = np.concatenate([np.linspace(a, b, k + 2)[:-1] for a, b in zip(g[:-1], g[1:])] +
                           [g[-1:]])
        return np.clip((t - lo) / (hi - lo), 0.0, 1.0) * (size - 1)

    h, w = density.shape
    x = coords(sp.point_count_u, sp.order_u, sp.use_endpoint_u, w)
    y = coords(sp.point_count_v, sp.order_v, sp.use_endpoint_v, h)
    x0 = np.minimum(np.floor(x).astype(np.int64), w - 1)
    y0 = np.minimum(np.floor(y).astype(np.int64), h - 1)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[None, :], (y - y0)[:, None]
    rows0 = density[y0][:, x0] * (1 - fx) + density[y0][:, x1] * fx
    rows1 = density[y1][:, x0] * (1 - fx) + density[y1][:, x1] * fx
    return np.ascontiguousarray(rows0 * (1 - fy) + rows1 * fy, dtype=np.float32)


def export_mesh(ob, frame, level):
    """Creates or replaces the MESH object f"{ob.name}_mesh"; returns it. BakeError on bad input
    (the scene is unchanged then). Blocking: inputs(), refine() and mesh_object() in a row."""
    return mesh_object(ob, *refine(*inputs(ob, frame), level))


def inputs(ob, frame):
    """(surface name, control points, nu, nv, density map) of the surface at `frame`: what
    refine() needs, read on the main thread. BakeError when the cache is missing."""
    sp = ob.data.splines[0]
    density = net_layout(read_density(sheet_file(ob, frame)), sp)
    return ob.name, surface_edits.current_points(ob), sp.point_count_u, sp.point_count_v, density


def refine(name, points, nu, nv, density, level):
    """(vertices, quads, density per vertex in [0, 1]) of the control net refined `level` times
    (OpenSubdiv), no bpy; BakeError naming the surface on bad input (jobs/kinds.py)."""
    return kinds.refine(name, points, nu, nv, density, level)


def mesh_object(ob, verts, quads, dens):
    """Creates or replaces the MESH object f"{ob.name}_mesh" of refine()'s arrays; returns it."""
    name = mesh_name(ob)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(verts))
    me.vertices.foreach_set("co", verts.ravel())
    me.loops.add(quads.size)
    me.loops.foreach_set("vertex_index", quads.ravel())
    me.polygons.add(len(quads))
    me.polygons.foreach_set("loop_start", np.arange(0, quads.size, 4, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(len(quads), 4, dtype=np.int32))
    me.update(calc_edges=True)
    me.attributes.new("density", 'FLOAT', 'POINT').data.foreach_set("value", dens)
    me.polygons.foreach_set("use_smooth", np.ones(len(quads), dtype=bool))

    out = bpy.data.objects.get(name)
    if out is not None and out.type == 'MESH':
        old = out.data
        out.data = me
        if old.users == 0:
            bpy.data.meshes.remove(old)
    else:
        out = bpy.data.objects.new(name, me)
        for coll in ob.users_collection:
            coll.objects.link(out)
    out.matrix_world = ob.matrix_world.copy()
    out[SOURCE_KEY] = ob.name
    return out
