"""Hand edits of streak surfaces ([Smoke Surfaces] §5, Figure 13) and "Bake to keyframes".

An edit is stored per control point (u, v index) as an offset in the surface's local frame there:
tangent t (along the streaklines, S_u), binormal b = n × t and normal n = S_u × S_v, evaluated on
the cached (unedited) surface of the frame at the control point's Greville abscissae
(_native.control_point_frames). Offset = R(frame)ᵀ (edited co − the co the cache gives for the
frame the points were written for). They live on the object as a float array custom property
(EDITS_KEY, nu * nv * 3 as (t, b, n) components, Blender's flat order v * nu + u), so they are
saved with the .blend and undone with it, and the frame handler writes cache(f) + R(f) offset on
every frame f: a warp made once moves and turns with the sheet for the whole shot.

Where the sheet has no tangent plane at a control point on some frame (collapsed to a curve or a
point, e.g. on the first frames), the frame of the nearest cached frame that has one is used.

Files saved before edits turned with the sheet hold world-space offsets under LEGACY_EDITS_KEY;
the first capture, write or bake converts them with the frames of the cache frame they were
last written for, so that frame looks the same, and removes the old property.

Edits are captured by comparing the current points with what was last written (FRAME_KEY = the
cache frame index written), either by the handler before it overwrites them or by the
plume.surface_edits_store operator (which also loads edit-mode data first).
"""

import bpy
import numpy as np

from ..native import _native
from .. import blender_compat as compat

#: Offsets (float64, nu * nv * 3) of the hand edits in each control point's (t, b, n) frame.
EDITS_KEY = "plume_surface_edits_local"
#: World-space offsets of files saved before edits turned with the sheet (migrated on use).
LEGACY_EDITS_KEY = "plume_surface_edits"
#: Index into the control-point cache of the frame whose points were last written.
FRAME_KEY = "plume_surface_frame"
#: Share (0..1) of the way to the next cached frame the written points are at: motion blur
#: evaluates the scene between frames (Cycles' shutter), and the handler writes the sheet there
#: as the blend of the two frames around it. Absent: on the frame itself.
SUBFRAME_KEY = "plume_surface_subframe"
#: Set by "Bake to keyframes": the points are F-curves now, the handler leaves them alone.
BAKED_KEY = "plume_surface_baked"
#: A point moved by more than this (world units) since it was written counts as edited.
TOLERANCE = 1e-6


def offsets(ob):
    """The edits as float64 (n, 3) (t, b, n) components, or None when there are none (or they do
    not fit the net)."""
    e = ob.get(EDITS_KEY)
    if e is None:
        return None
    a = np.asarray(e, dtype=np.float64)
    n = len(ob.data.splines[0].points)
    return a.reshape(n, 3) if a.size == n * 3 else None


def set_offsets(ob, off):
    """Stores (t, b, n) offsets; None or all zeros removes the edits (old world ones too)."""
    if LEGACY_EDITS_KEY in ob:
        del ob[LEGACY_EDITS_KEY]
    if off is None or not np.any(off):
        if EDITS_KEY in ob:
            del ob[EDITS_KEY]
    else:
        ob[EDITS_KEY] = np.ascontiguousarray(off, dtype=np.float64).ravel()


def surface_of(ob, co):
    """The surface dict of the object's spline with control points co (n, 4)."""
    sp = ob.data.splines[0]
    return {"control_points": co, "nu": sp.point_count_u, "nv": sp.point_count_v,
            "order_u": sp.order_u, "order_v": sp.order_v, "endpoint_u": sp.use_endpoint_u,
            "endpoint_v": sp.use_endpoint_v}


# (object name, id of the cache array, cache index) -> (the cache array, frames): the handler asks
# for the frames of the written index and of the new one on every frame change. Holding the array
# keeps its id from being reused while the entry lives.
_frames = {}


def local_frames(ob, cps, index):
    """Rows (tangent, binormal, normal) float64 (n, 3, 3) at every control point of cache frame
    `index`; a control point without a frame there takes the nearest cached frame's (world axes
    if it has none on any frame)."""
    key = (ob.name, id(cps), int(index))
    hit = _frames.get(key)
    if hit is not None:
        return hit[1]
    axes, valid = _native.control_point_frames(surface_of(ob, cps[index]))
    axes = np.array(axes)
    missing = ~np.asarray(valid, dtype=bool)
    for step in range(1, len(cps)):
        if not missing.any():
            break
        for j in (index - step, index + step):
            if 0 <= j < len(cps) and missing.any():
                other, ok = _native.control_point_frames(surface_of(ob, cps[j]))
                fill = missing & np.asarray(ok, dtype=bool)
                axes[fill] = np.asarray(other)[fill]
                missing &= ~fill
    if len(_frames) > 64:
        _frames.clear()
    _frames[key] = (cps, axes)
    return axes


def world_offsets(ob, cps, index):
    """The edits in world space on cache frame `index`, float64 (n, 3), or None."""
    migrate(ob, cps)
    off = offsets(ob)
    if off is None:
        return None
    return np.einsum("nk,nkj->nj", off, local_frames(ob, cps, index))


def migrate(ob, cps):
    """World-space offsets of an older file -> (t, b, n) offsets in the frames of the cache
    frame they were last written for (so that frame is unchanged)."""
    old = ob.get(LEGACY_EDITS_KEY)
    if old is None:
        return
    world = np.asarray(old, dtype=np.float64)
    n = len(ob.data.splines[0].points)
    if EDITS_KEY in ob or world.size != n * 3:
        del ob[LEGACY_EDITS_KEY]  # newer edits win; a mismatched array fits no net
        return
    axes = local_frames(ob, cps, written_index(ob, cps, 0))
    set_offsets(ob, np.einsum("nkj,nj->nk", axes, world.reshape(n, 3)))


def edited_points(ob, cps, index):
    """cache(index) + the edits turned into that frame's local frames, float32 (n, 4)."""
    co = np.array(cps[index], dtype=np.float32)
    off = world_offsets(ob, cps, index)
    if off is not None:
        co[:, :3] += off.astype(np.float32)
    return co


def current_points(ob):
    points = ob.data.splines[0].points
    co = np.empty(len(points) * 4, dtype=np.float32)
    points.foreach_get("co", co)
    return co.reshape(-1, 4)


def blended_points(ob, cps, index, t):
    """edited_points between cache frames `index` and `index` + 1, a share t of the way (the
    last frame stays put)."""
    co = edited_points(ob, cps, index)
    if t <= 0.0 or index + 1 >= len(cps):
        return co
    return (1.0 - t) * co + t * edited_points(ob, cps, index + 1)


def written_subframe(ob):
    return float(ob.get(SUBFRAME_KEY, 0.0))


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
    written = blended_points(ob, cps, i, written_subframe(ob))[:, :3]
    moved = np.abs(cur - written).max(axis=1) > TOLERANCE
    if not moved.any():
        return 0
    off = offsets(ob)
    off = np.zeros((len(cur), 3)) if off is None else off.copy()
    # An edit counts from the frame the points were written for, moved back to the frame itself
    # when they were written between frames (by motion blur's sub-frames).
    world = (cur[moved] - written[moved]).astype(np.float64) + (
        edited_points(ob, cps, i)[moved, :3] - cps[i][moved, :3])
    off[moved] = np.einsum("nkj,nj->nk", local_frames(ob, cps, i)[moved], world)
    set_offsets(ob, off)
    return int(moved.sum())


def write(ob, cps, index, t=0.0):
    """Writes cache(index) + offsets, blended a share t towards the next frame's, into the
    spline and remembers `index` and t."""
    ob.data.splines[0].points.foreach_set("co", blended_points(ob, cps, index, t).ravel())
    ob[FRAME_KEY] = int(index)
    if t > 0.0:
        ob[SUBFRAME_KEY] = float(t)
    elif SUBFRAME_KEY in ob:
        del ob[SUBFRAME_KEY]
    ob.data.update_tag()


def point_paths(n):
    return [f"splines[0].points[{k}].co" for k in range(n)]


def bake_keyframes(ob, cps, frame_start):
    """Plain F-curves (x, y, z of every control point, one key per cached frame, cache + the edits
    turned with the sheet) on the curve datablock, then detaches the surface from the handler.
    Returns the key count."""
    cu = ob.data
    frames, n = cps.shape[0], cps.shape[1]
    xyz = np.array(cps[:, :, :3], dtype=np.float32)
    for f in range(frames):
        off = world_offsets(ob, cps, f)
        if off is None:
            break
        xyz[f] += off.astype(np.float32)
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
