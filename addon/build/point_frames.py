"""Point-cloud MESH objects that follow one cache file per frame (the toon particles, the fire
point preview): the last file read, the bulk update of a mesh's vertices and point attributes,
and the creation of the object. Each kind has its own persistent frame_change_pre handler
(frame_handlers) that finds its objects by a custom property and calls these."""

import os

import bpy
import numpy as np

from . import datablocks
from ..snapshot import blend_relative


class LastFile:
    """The last file read by `reader(path)`, kept while its modification time holds: frames are
    read in order, so one file in memory is enough. read() gives None when the file is missing
    or `reader` raises one of `errors` (a damaged or half-written file shows nothing new)."""

    def __init__(self, reader, errors):
        self.reader, self.errors = reader, errors
        self._hit = None  # (path, mtime, data)

    def read(self, path):
        try:
            mtime = os.path.getmtime(path)
        except OSError:
            return None
        hit = self._hit
        if hit is not None and hit[0] == path and hit[1] == mtime:
            return hit[2]
        try:
            data = self.reader(path)
        except self.errors:
            return None
        self._hit = (path, mtime, data)
        return data

    def clear(self):
        self._hit = None


def set_points(mesh, positions, attributes):
    """Replaces the mesh's vertices with `positions` (N, 3) and sets its point attributes from
    `attributes` {name: (data type 'FLOAT' | 'FLOAT_VECTOR' | 'INT', values)} with bulk
    foreach_set updates (an attribute of another type or domain is replaced)."""
    positions = np.ascontiguousarray(positions, np.float32).reshape(-1, 3)
    n = len(positions)
    mesh.clear_geometry()
    mesh.vertices.add(n)
    mesh.vertices.foreach_set("co", positions.ravel())
    for name, (kind, values) in attributes.items():
        attr = mesh.attributes.get(name)
        if attr is None or attr.data_type != kind or attr.domain != 'POINT':
            if attr is not None:
                mesh.attributes.remove(attr)
            attr = mesh.attributes.new(name, kind, 'POINT')
        if n:
            attr.data.foreach_set("vector" if kind == 'FLOAT_VECTOR' else "value",
                                  np.ascontiguousarray(values).ravel())
    mesh.update()


def point_object(scene, name, properties, collections=()):
    """Creates (or reuses) MESH object `name`, linked to `collections` (else the scene's
    collection) when it is in none, at the world origin (the points are in world space), with
    the custom `properties` (its cache folder is stored //-relative when the .blend is saved)."""
    ob = datablocks.typed_object(scene, name, 'MESH', bpy.data.meshes.new, collections)
    ob.matrix_world.identity()
    for key, value in properties.items():
        ob[key] = value
    return ob


def cached_frames(ob, folder_key, range_key):
    """(absolute cache folder, first frame, last frame) of a point object built from a cache,
    or None when `ob` is not one."""
    folder = ob.get(folder_key)
    frames = ob.get(range_key)
    if not folder or frames is None or ob.type != 'MESH':
        return None
    return bpy.path.abspath(folder), int(frames[0]), int(frames[1])


def stored_path(folder):
    return blend_relative(folder)


def remove_object(name):
    """Deletes object `name` and its mesh when nothing else uses it."""
    ob = bpy.data.objects.get(name)
    if ob is None:
        return
    data = ob.data
    bpy.data.objects.remove(ob, do_unlink=True)
    if isinstance(data, bpy.types.Mesh) and data.users == 0:
        bpy.data.meshes.remove(data)
