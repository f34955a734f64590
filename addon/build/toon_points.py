"""Toon particles -> a point-cloud MESH object "<domain>_toon" (cartoon_smoke.txt §2.1-2.3):
its vertices and point attributes (size, velocity, colour, id) follow toon_####.bin on every
frame through a persistent frame_change_pre handler with bulk foreach_set updates. The
camera-dependent orientation and stretch (Figure 4) are computed by the billboard node group from
the velocity; the handler only keeps the group pointed at the scene camera."""

import os
import time

import bpy
import numpy as np

from . import frame_handlers
from .toon_nodes import (COLOR_ATTRIBUTE, VELOCITY_ATTRIBUTE, billboard_modifier,
                         set_camera)
from .surfaces import _file_path  # //-relative when the .blend is saved

#: Custom properties of a toon object: its cache folder, the domain and the bake's frame range.
FOLDER_KEY = "plume_toon_cache"
DOMAIN_KEY = "plume_toon_domain"
RANGE_KEY = "plume_toon_frames"

#: Point attributes written on every frame and their types.
ATTRIBUTES = {"size": 'FLOAT', VELOCITY_ATTRIBUTE: 'FLOAT_VECTOR', COLOR_ATTRIBUTE: 'FLOAT',
              "id": 'INT'}

# path -> (mtime, snapshot dict) of the last toon file read per object
_loaded = {}
#: Seconds the last handler call spent per toon object (printed by tests, never asserted).
last_update_seconds = []


def object_name(domain):
    return f"{domain.name}_toon"


def _native():
    from .. import _native
    return _native


def _toon_path(folder, frame):
    from ..toon import toon_path
    return toon_path(folder, frame)


def _read(path):
    try:
        mtime = os.path.getmtime(path)
    except OSError:
        return None
    hit = _loaded.get(path)
    if hit is not None and hit[0] == mtime:
        return hit[1]
    try:
        snap = _native().read_toon_file(path)
    except RuntimeError:
        return None
    _loaded.clear()  # one frame per path kept: frames are read in order, memory stays small
    _loaded[path] = (mtime, snap)
    return snap


def write_points(mesh, snap):
    """Replaces the mesh's vertices and point attributes with the particles' (bulk updates)."""
    n = len(snap["ids"])
    mesh.clear_geometry()
    mesh.vertices.add(n)
    mesh.vertices.foreach_set("co", np.ascontiguousarray(snap["positions"], np.float32).ravel())
    values = {"size": np.asarray(snap["size"], np.float32),
              VELOCITY_ATTRIBUTE: np.ascontiguousarray(snap["velocities"], np.float32).ravel(),
              COLOR_ATTRIBUTE: np.asarray(snap["color"], np.float32),
              # ids never repeat; int32 wraps only after 2^31 births (GN's stable "id")
              "id": (np.asarray(snap["ids"], np.uint64) & np.uint64(0x7FFFFFFF)).astype(np.int32)}
    for name, kind in ATTRIBUTES.items():
        attr = mesh.attributes.get(name)
        if attr is None or attr.data_type != kind or attr.domain != 'POINT':
            if attr is not None:
                mesh.attributes.remove(attr)
            attr = mesh.attributes.new(name, kind, 'POINT')
        if n:
            attr.data.foreach_set("vector" if kind == 'FLOAT_VECTOR' else "value", values[name])
    mesh.update()


def update_object(ob, scene, frame):
    """Sets the toon object's points of `frame` (clamped to the built range) and points its
    billboards at the scene camera (which markers may switch). True if set."""
    folder = ob.get(FOLDER_KEY)
    frames = ob.get(RANGE_KEY)
    if not folder or frames is None or ob.type != 'MESH':
        return False
    first, last = int(frames[0]), int(frames[1])
    snap = _read(_toon_path(bpy.path.abspath(folder), min(max(frame, first), last)))
    if snap is None:
        return False
    mod = billboard_modifier(ob)
    if mod is not None and scene.camera is not None:
        set_camera(mod, scene.camera)
    write_points(ob.data, snap)
    return True


def update_all(scene, frame):
    del last_update_seconds[:]
    for ob in scene.objects:
        if FOLDER_KEY in ob:
            t0 = time.perf_counter()
            if update_object(ob, scene, frame):
                last_update_seconds.append(time.perf_counter() - t0)


@bpy.app.handlers.persistent
def frame_change_pre(scene, *_args):
    update_all(scene, scene.frame_current)


def register():
    frame_handlers.add(frame_change_pre)


def unregister():
    frame_handlers.remove(frame_change_pre)
    _loaded.clear()


def build_object(scene, domain, folder, frame_start, last_frame):
    """Creates (or reuses) "<domain>_toon" linked to the scene, keyed to the cache folder, with
    the points of the current frame. The object stays at the world origin: points are in world
    space."""
    name = object_name(domain)
    ob = bpy.data.objects.get(name)
    if ob is not None and ob.type != 'MESH':
        bpy.data.objects.remove(ob, do_unlink=True)
        ob = None
    if ob is None:
        ob = bpy.data.objects.new(name, bpy.data.meshes.new(name))
    if scene.collection.objects.get(ob.name) is None and not ob.users_collection:
        scene.collection.objects.link(ob)
    ob.matrix_world.identity()
    ob[FOLDER_KEY] = _file_path(folder)
    ob[DOMAIN_KEY] = domain.name
    ob[RANGE_KEY] = [int(frame_start), int(last_frame)]
    _loaded.clear()
    update_object(ob, scene, scene.frame_current)
    return ob

