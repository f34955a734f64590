"""Toon particles -> a point-cloud MESH object "<domain>_toon" ([Cartoon Smoke] §2.1-2.3):
its vertices and point attributes (size, velocity, colour, id) follow toon_####.bin on every
frame through a persistent frame_change_pre handler with bulk foreach_set updates. The
camera-dependent orientation and stretch (Figure 4) are computed by the billboard node group from
the velocity; the handler only keeps the group pointed at the scene camera."""

import time

import bpy
import numpy as np

from . import frame_handlers, point_frames
from ..native import _native
from .toon_nodes import (COLOR_ATTRIBUTE, VELOCITY_ATTRIBUTE, billboard_modifier,
                         set_camera)

#: Custom properties of a toon object: its cache folder, the domain and the bake's frame range.
FOLDER_KEY = "plume_toon_cache"
DOMAIN_KEY = "plume_toon_domain"
RANGE_KEY = "plume_toon_frames"

#: Point attributes written on every frame and their types.
ATTRIBUTES = {"size": 'FLOAT', VELOCITY_ATTRIBUTE: 'FLOAT_VECTOR', COLOR_ATTRIBUTE: 'FLOAT',
              "id": 'INT'}

#: Seconds the last handler call spent per toon object (printed by tests, never asserted).
last_update_seconds = []


def object_name(domain):
    return f"{domain.name}_toon"


def _toon_path(folder, frame):
    from ..toon import toon_path
    return toon_path(folder, frame)


#: The toon file of the last frame read (one kept: frames are read in order).
_files = point_frames.LastFile(lambda path: _native.read_toon_file(path), RuntimeError)


def write_points(mesh, snap):
    """Replaces the mesh's vertices and point attributes with the particles' (bulk updates)."""
    values = {"size": np.asarray(snap["size"], np.float32),
              VELOCITY_ATTRIBUTE: np.ascontiguousarray(snap["velocities"], np.float32),
              COLOR_ATTRIBUTE: np.asarray(snap["color"], np.float32),
              # ids never repeat; int32 wraps only after 2^31 births (GN's stable "id")
              "id": (np.asarray(snap["ids"], np.uint64) & np.uint64(0x7FFFFFFF)).astype(np.int32)}
    point_frames.set_points(mesh, snap["positions"],
                            {name: (kind, values[name]) for name, kind in ATTRIBUTES.items()})


def update_object(ob, scene, frame):
    """Sets the toon object's points of `frame` (clamped to the built range) and points its
    billboards at the scene camera (which markers may switch). True if set."""
    cached = point_frames.cached_frames(ob, FOLDER_KEY, RANGE_KEY)
    if cached is None:
        return False
    folder, first, last = cached
    snap = _files.read(_toon_path(folder, min(max(frame, first), last)))
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
    _files.clear()


def build_object(scene, domain, folder, frame_start, last_frame):
    """Creates (or reuses) "<domain>_toon" linked to the scene, keyed to the cache folder, with
    the points of the current frame. The object stays at the world origin: points are in world
    space."""
    ob = point_frames.point_object(scene, object_name(domain), {
        FOLDER_KEY: point_frames.stored_path(folder), DOMAIN_KEY: domain.name,
        RANGE_KEY: [int(frame_start), int(last_frame)]})
    _files.clear()
    update_object(ob, scene, scene.frame_current)
    return ob

