"""The flame spines ([Structural Flames] §4.1, Figure 5's "structural curves") as the curve
object "Plume Flame Spines": one POLY spline per live flame through its n points (base to tip;
separated flames through their own), rebuilt from spines_####.npz by a persistent
frame_change_pre handler, which also moves the flame lights (flame_lights.py). Outside the baked
range the curve is empty and the lights are off, like the Volume's CLIP sequence."""

import bpy
import numpy as np

from . import flame_lights, frame_handlers, point_frames
from .. import flames

OBJECT_NAME = "Plume Flame Spines"
FOLDER_KEY = "plume_flames_cache"
RANGE_KEY = "plume_flames_frames"
UNIT_KEY = "plume_flames_light_unit"
LIGHTS_KEY = "plume_flames_lights"

_files = point_frames.LastFile(flames.read_spines, (OSError, ValueError))


def set_splines(curve, spines):
    """Replaces the curve's splines: one POLY spline per flame (none when spines is None)."""
    curve.splines.clear()
    if spines is None:
        return
    start = 0
    for count in spines["counts"]:
        count = int(count)
        pts = spines["points"][start:start + count]
        start += count
        if count < 2:
            continue
        sp = curve.splines.new('POLY')
        sp.points.add(count - 1)
        co = np.ones((count, 4), np.float32)
        co[:, :3] = pts
        sp.points.foreach_set("co", co.ravel())


def update_object(ob, scene, frame):
    """The spines and lights of `frame`. True when a file was read."""
    folder, first, last = bpy.path.abspath(ob[FOLDER_KEY]), *ob[RANGE_KEY]
    spines = _files.read(flames.spines_path(folder, frame)) if first <= frame <= last else None
    set_splines(ob.data, spines)
    flame_lights.update(scene, spines, float(ob.get(UNIT_KEY, 1.0)))
    return spines is not None


@bpy.app.handlers.persistent
def frame_change_pre(scene, *_args):
    for ob in scene.objects:
        if FOLDER_KEY in ob and ob.type == 'CURVE':
            update_object(ob, scene, scene.frame_current)


def register():
    frame_handlers.add(frame_change_pre)


def unregister():
    frame_handlers.remove(frame_change_pre)
    _files.clear()


def max_lights(folder, first, last):
    """The most lights of any baked frame (the size of the light pool)."""
    most = 0
    for frame in range(first, last + 1):
        try:
            most = max(most, len(flames.read_spines(flames.spines_path(folder, frame))["light_ids"]))
        except (OSError, ValueError):
            pass
    return most


def build(scene, folder, first, last, light_unit, lights=True):
    """Creates or updates "Plume Flame Spines" and the light pool for frames first..last, set to
    the current frame. Returns the curve object."""
    ob = bpy.data.objects.get(OBJECT_NAME)
    if ob is not None and ob.type != 'CURVE':
        bpy.data.objects.remove(ob, do_unlink=True)
        ob = None
    if ob is None:
        cu = bpy.data.curves.new(OBJECT_NAME, 'CURVE')
        cu.dimensions = '3D'
        ob = bpy.data.objects.new(OBJECT_NAME, cu)
        scene.collection.objects.link(ob)
        ob.hide_render = True  # a guide: the Volume and the lights are what renders
    ob.matrix_world.identity()  # the points are in world space
    ob[FOLDER_KEY] = point_frames.stored_path(folder)
    ob[RANGE_KEY] = [int(first), int(last)]
    ob[UNIT_KEY] = float(light_unit)
    count = max_lights(folder, first, last) if lights else 0
    flame_lights.ensure_pool(scene, count)
    scene.render.use_lock_interface = True  # the handler rewrites data while rendering
    _files.clear()
    update_object(ob, scene, scene.frame_current)
    return ob


def remove(scene):
    ob = bpy.data.objects.get(OBJECT_NAME)
    if ob is not None and ob.type == 'CURVE':
        cu = ob.data
        bpy.data.objects.remove(ob, do_unlink=True)
        if cu.users == 0:
            bpy.data.curves.remove(cu)
    flame_lights.remove_all(scene)
    _files.clear()
