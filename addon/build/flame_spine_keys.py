"""Bake Spines to Keyframes ([Structural Flames] §4.1: spines shown as curve objects the
artist can see and key): the cached spines of the baked frames become one plain curve object per
flame id, its points keyed on every frame the flame lives, so they exist without the add-on and
an artist can re-key them.

A flame's point count can change over its life (a separated flame is re-sampled but not refilled,
§4.3): its curve has the most points it ever had, and on a frame with fewer the extra points sit
on the tip (the same polyline). Before its birth and after its death the object is hidden:
hide_viewport and hide_render keyed on every baked frame (boolean keys hold, no blending).
"""

import bpy
import numpy as np

from .. import blender_compat as compat
from .. import flames
from .surface_edits import point_paths

COLLECTION_NAME = "Plume Flame Spine Keys"
#: Custom property on each object: the flame id it follows.
ID_KEY = "plume_flame_id"


def object_name(flame_id):
    return f"Plume Flame Spine {flame_id}"


def read_tracks(folder, first, last):
    """{flame id: {frame: (k, 3) float32 points}} over frames first..last; OSError/ValueError
    when a spines file is missing or damaged."""
    tracks = {}
    for frame in range(first, last + 1):
        sp = flames.read_spines(flames.spines_path(folder, frame))
        start = 0
        for fid, count in zip(sp["ids"], sp["counts"]):
            count = int(count)
            if count >= 2:
                tracks.setdefault(int(fid), {})[frame] = sp["points"][start:start + count]
            start += count
    return tracks


def padded(points, n):
    """points (k, 3) padded to (n, 3) by repeating the tip."""
    out = np.empty((n, 3), np.float32)
    out[:len(points)] = points
    out[len(points):] = points[-1]
    return out


def _collection(scene):
    """The (emptied) collection of the keyed spines, linked to the scene."""
    col = bpy.data.collections.get(COLLECTION_NAME)
    if col is None:
        col = bpy.data.collections.new(COLLECTION_NAME)
    if col.name not in scene.collection.children:
        scene.collection.children.link(col)
    for ob in list(col.objects):
        cu = ob.data
        bpy.data.objects.remove(ob, do_unlink=True)
        if cu is not None and cu.users == 0:
            bpy.data.curves.remove(cu)
    return col


def _key(id_data, path, index, frames, values, group):
    fc = compat.fcurve_new(id_data, path, index=index, group=group)
    fc.keyframe_points.add(len(frames))
    fc.keyframe_points.foreach_set(
        "co", np.column_stack([frames, values]).astype(np.float32).ravel())
    fc.update()
    return fc


def _curve_object(col, flame_id, n):
    cu = bpy.data.curves.new(object_name(flame_id), 'CURVE')
    cu.dimensions = '3D'
    sp = cu.splines.new('POLY')
    sp.points.add(n - 1)
    ob = bpy.data.objects.new(object_name(flame_id), cu)
    ob[ID_KEY] = int(flame_id)
    col.objects.link(ob)
    return ob


def bake(scene, folder, first, last):
    """Builds the keyed spine objects of frames first..last (replacing earlier ones). Returns
    (objects, keys). OSError/ValueError from an unreadable cache, before anything changes."""
    tracks = read_tracks(folder, first, last)
    col = _collection(scene)
    baked = np.arange(first, last + 1, dtype=np.float32)
    objects, keys = [], 0
    for fid, by_frame in sorted(tracks.items()):
        frames = np.array(sorted(by_frame), dtype=np.float32)
        n = max(len(p) for p in by_frame.values())
        xyz = np.stack([padded(by_frame[int(f)], n) for f in frames])  # (frames, n, 3)
        ob = _curve_object(col, fid, n)
        ob.data.splines[0].points.foreach_set(
            "co", np.column_stack([xyz[0], np.ones(n, np.float32)]).ravel())
        cu_action = bpy.data.actions.new(f"{ob.name} Points")
        ob.data.animation_data_create().action = cu_action
        for k, path in enumerate(point_paths(n)):
            for c in range(3):
                _key(ob.data, path, c, frames, xyz[:, k, c], "Plume Spine")
        hidden = ~np.isin(baked, frames)
        ob_action = bpy.data.actions.new(f"{ob.name} Visibility")
        ob.animation_data_create().action = ob_action
        for path in ("hide_viewport", "hide_render"):
            _key(ob, path, 0, baked, hidden.astype(np.float32), "Plume Spine")
        objects.append(ob)
        keys += len(frames) * n * 3 + 2 * len(baked)
    return objects, keys
