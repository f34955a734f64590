"""How many streaklines a domain's next bake will trace ([Smoke Surfaces] §3.2), for the Streak
Surfaces panel: every Source's point sources (a rim one per cell of its length, point_sources per
source cell, or its Point Source Mesh's vertices) and what max_streaklines keeps of them. Computed from the objects' own mesh data
(no depsgraph evaluation: this runs while the panel draws) and cached until a setting, a Source
or the domain changes; nothing is read from or written to disk."""

import numpy as np
from mathutils import Vector

from . import point_rim, point_sources
from .native_params import to_native_params
from .settings import domain_grid
from .snapshot import solver_settings

#: domain name -> (key of what the count depends on, (kept, placed)).
_cache = {}


def _triangles(mesh):
    """Vertices float32 (N, 3) and fan triangles int32 (M, 3) of a mesh's own (unevaluated)
    polygons, read only."""
    verts = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", verts)
    loops = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    start = np.empty(len(mesh.polygons), dtype=np.int32)
    total = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", start)
    mesh.polygons.foreach_get("loop_total", total)
    fans = np.maximum(total - 2, 0)  # polygon of n corners: n - 2 triangles (l0, lk, lk+1)
    first = np.repeat(start, fans)
    k = np.arange(int(fans.sum())) - np.repeat(np.cumsum(fans) - fans, fans) + 1
    tris = np.stack([loops[first], loops[first + k], loops[first + k + 1]], axis=1)
    return verts.reshape(-1, 3), tris.astype(np.int32)


def _sources(scene, domain):
    return [o for o in scene.objects if o is not domain and o.type == 'MESH'
            and o.plume.role == 'SOURCE']


def _key(scene, domain, sources):
    d = domain.plume.domain
    parts = [domain.name, int(d.resolution), int(d.max_streaklines), tuple(d.gravity),
             tuple(tuple(r) for r in domain.matrix_world), tuple(domain.dimensions)]
    for o in sources:
        s = o.plume.source
        mesh = s.point_source_mesh
        parts.append((o.name, tuple(tuple(r) for r in o.matrix_world), len(o.data.vertices),
                      len(o.data.polygons), int(s.point_sources), s.point_placement,
                      tuple(s.velocity),
                      (mesh.name, len(mesh.data.vertices)) if mesh is not None else None))
    return tuple(parts)


def count(native, scene, domain):
    """(kept, placed): the streaklines the next bake traces, and the point sources placed before
    max_streaklines thinned them. ValueError (a bad domain) propagates; cached."""
    sources = _sources(scene, domain)
    key = _key(scene, domain, sources)
    hit = _cache.get(domain.name)
    if hit is not None and hit[0] == key:
        return hit[1]
    corners = [domain.matrix_world @ Vector(c) for c in domain.bound_box]
    lo = tuple(min(c[a] for c in corners) for a in range(3))
    hi = tuple(max(c[a] for c in corners) for a in range(3))
    cells, cell_size, origin = domain_grid(lo, hi, domain.plume.domain.resolution)
    params = to_native_params(solver_settings(domain, scene, cells, cell_size, origin), native)
    random, fixed = [], 0
    for o in sources:
        s = o.plume.source
        if s.point_source_mesh is not None:
            fixed += len(s.point_source_mesh.data.vertices)
            continue
        verts, tris = _triangles(o.data)
        m = np.array(o.matrix_world, dtype=np.float64)
        inside = native.source_cells(verts, tris, m, m, params, o.name)[0] if len(tris) else ()
        if len(inside) == 0:
            random.append(0)
        elif s.point_placement == 'RIM':
            axis = point_rim.flow_axis(s.velocity, domain.plume.domain.gravity)
            random.append(point_rim.natural_count(
                inside, (params.resolution, params.cell_size, params.origin), axis))
        else:
            random.append(len(inside) * int(s.point_sources))
    kept = int(point_sources.thinning_quotas(random, domain.plume.domain.max_streaklines).sum())
    result = (kept + fixed, sum(random) + fixed)
    _cache[domain.name] = (key, result)
    return result


def label(native, scene, domain):
    """The panel's line: "256 streaklines (of 8,064 point sources)", or why there are none."""
    try:
        kept, placed = count(native, scene, domain)
    except (ValueError, RuntimeError) as e:
        return f"Streaklines: unknown ({e})"
    if placed == 0:
        return "No Source cell in the domain: no streaklines"
    if kept < placed:
        return f"{kept:,} streaklines (of {placed:,} point sources; Max Streaklines)"
    return f"{kept:,} streaklines"
