"""Hand edits of streak surfaces (smoke_surfaces.txt §5, Figure 13) and "Bake to keyframes".

An edit is stored as offsets in (u, v) control-point index space: offset = edited co − the co the
cache gives for the frame the points were written for. They live on the object as a float array
custom property (EDITS_KEY, nu * nv * 3, Blender's flat order v * nu + u), so they are saved with
the .blend and undone with it, and the frame handler writes cache(frame) + offsets on every frame:
a warp made once moves with the surface for the whole shot.

Edits are captured by comparing the current points with what was last written (FRAME_KEY = the
cache frame index written), either by the handler before it overwrites them or by the
plume.surface_edits_store operator (which also loads edit-mode data first).
"""

import bpy
import numpy as np

from .. import blender_compat as compat

#: Offsets (float64, nu * nv * 3) of the hand edits.
EDITS_KEY = "plume_surface_edits"
#: Index into the control-point cache of the frame whose points were last written.
FRAME_KEY = "plume_surface_frame"
#: Set by "Bake to keyframes": the points are F-curves now, the handler leaves them alone.
BAKED_KEY = "plume_surface_baked"
#: A point moved by more than this (world units) since it was written counts as edited.
TOLERANCE = 1e-6


def offsets(ob):
    """The edits as float32 (n, 3), or None when there are none (or they do not fit the net)."""
    e = ob.get(EDITS_KEY)
    if e is None:
        return None
    a = np.asarray(e, dtype=np.float32)
    n = len(ob.data.splines[0].points)
    return a.reshape(n, 3) if a.size == n * 3 else None


def set_offsets(ob, off):
    if off is None or not np.any(off):
        if EDITS_KEY in ob:
            del ob[EDITS_KEY]
    else:
        ob[EDITS_KEY] = np.ascontiguousarray(off, dtype=np.float64).ravel()


def edited_points(ob, cps, index):
    """cache(index) + offsets, float32 (n, 4) (w from the cache)."""
    co = np.array(cps[index], dtype=np.float32)
    off = offsets(ob)
    if off is not None:
        co[:, :3] += off
    return co


def current_points(ob):
    points = ob.data.splines[0].points
    co = np.empty(len(points) * 4, dtype=np.float32)
    points.foreach_get("co", co)
    return co.reshape(-1, 4)


def written_index(ob, cps, frame_index=None):
    """The cache index the points belong to (FRAME_KEY, else `frame_index`), clamped."""
    i = ob.get(FRAME_KEY, frame_index)
    if i is None:
        return None
    return min(max(int(i), 0), len(cps) - 1)


def capture(ob, cps, frame_index=None):
    """Folds moves made since the last write into the offsets; number of points edited."""
    i = written_index(ob, cps, frame_index)
    if i is None:
        return 0
    cur = current_points(ob)[:, :3]
    moved = np.abs(cur - edited_points(ob, cps, i)[:, :3]).max(axis=1) > TOLERANCE
    if not moved.any():
        return 0
    off = offsets(ob)
    off = np.zeros_like(cur) if off is None else off.copy()
    off[moved] = cur[moved] - cps[i][moved, :3]
    set_offsets(ob, off)
    return int(moved.sum())


def write(ob, cps, index):
    """Writes cache(index) + offsets into the spline and remembers `index`."""
    ob.data.splines[0].points.foreach_set("co", edited_points(ob, cps, index).ravel())
    ob[FRAME_KEY] = int(index)
    ob.data.update_tag()


def point_paths(n):
    return [f"splines[0].points[{k}].co" for k in range(n)]


def bake_keyframes(ob, cps, frame_start):
    """Plain F-curves (x, y, z of every control point, one key per cached frame, cache + edits)
    on the curve datablock, then detaches the surface from the handler. Returns the key count."""
    cu = ob.data
    frames, n = cps.shape[0], cps.shape[1]
    off = offsets(ob)
    xyz = np.array(cps[:, :, :3], dtype=np.float32)
    if off is not None:
        xyz += off[None]
    ad = cu.animation_data or cu.animation_data_create()
    action = ad.action
    if action is None:
        action = bpy.data.actions.new(f"{ob.name}_plume_keys")
        ad.action = action
    paths = set(point_paths(n))
    curves = compat.fcurves(cu)
    for fc in [fc for fc in curves if fc.data_path in paths]:
        curves.remove(fc)
    keys = np.empty((frames, 2), dtype=np.float32)
    keys[:, 0] = np.arange(frame_start, frame_start + frames, dtype=np.float32)
    for k, path in enumerate(point_paths(n)):
        for c in range(3):
            fc = compat.fcurve_new(cu, path, index=c, group="Plume Surface")
            fc.keyframe_points.add(frames)
            keys[:, 1] = xyz[:, k, c]
            fc.keyframe_points.foreach_set("co", keys.ravel())
            fc.update()
    ob[BAKED_KEY] = True
    return frames * n * 3
