"""Scene -> flames.FlameBakeSnapshot (bpy side, main thread): the Flame Sources with their flame
places and spread values, and every keyable value frame by frame (the current frame is
restored). BakeError on bad input, before anything is written."""

import math
import os

import bpy
import numpy as np

from .. import flame_placement as place
from .. import flames
from ..settings import BakeError
from .scene import cache_folder_of, flames_cache_folder, mesh_arrays
from ..ui_words import FLAME_SOURCE, ui


def source_at(name):
    """A Flame Source as a message names it: the object and the panel of its settings."""
    return f"Plume: Flame Source '{name}' ({FLAME_SOURCE})"


def flame_sources(scene):
    return [o for o in scene.objects if o.type == 'MESH' and o.plume.role == 'FLAME_SOURCE']


def settings_now(f):
    """scene.plume_flames at the current frame as flames.FlameSettings."""
    names = [fld for fld in flames.FlameSettings.__dataclass_fields__]
    return flames.FlameSettings(**{n: type(getattr(flames.FlameSettings, n))(getattr(f, n))
                                   for n in names})


def image_pixels(image, owner, setting):
    """(h, w, 4) float32 pixels of a Blender image (rows from the bottom); BakeError naming the
    setting when it has no data (a missing or unreadable file)."""
    if image.source == 'FILE' and image.packed_file is None:
        path = bpy.path.abspath(image.filepath)
        if not os.path.isfile(path):
            raise BakeError(f"{source_at(owner)}: {setting} '{image.name}' cannot be "
                            f"read: no file {path}")
    w, h = image.size
    if w == 0 or h == 0 or not image.has_data and not image.pixels:
        raise BakeError(f"{source_at(owner)}: {setting} '{image.name}' cannot be "
                        f"read ({bpy.path.abspath(image.filepath) or 'no file'})")
    px = np.empty(w * h * image.channels, np.float32)
    image.pixels.foreach_get(px)
    px = px.reshape(h, w, image.channels)
    if image.channels < 3:
        px = np.repeat(px[..., :1], 3, axis=2)
    return px


def color_image(image, owner):
    """§5.1: the Colour Image as (h, w, 3) scene-linear float32; BakeError naming the setting
    when it is empty, unreadable or not RGB."""
    if image is None:
        raise BakeError(f"{source_at(owner)}: Colour is Colour Image but Colour Image "
                        "is empty: pick an RGB image, or set Colour to Profile Colours")
    px = image_pixels(image, owner, "Colour Image")
    # Blender gives every image 4 channels in memory; the file's own are in its bit depth
    # (8 per channel, 32 for float): a greyscale file holds no colour.
    channels = image.depth // (32 if image.is_float else 8)
    if min(image.channels, channels) < 3:
        raise BakeError(f"{source_at(owner)}: Colour Image '{image.name}' must be RGB "
                        f"or RGBA (it has {min(image.channels, channels)} channel"
                        f"{'s' if min(image.channels, channels) != 1 else ''}: greyscale)")
    rgb = px[..., :3]
    if not image.is_float and image.colorspace_settings.name == 'sRGB':
        # byte images hold sRGB-encoded values: to scene-linear, as Blender's shaders read them
        rgb = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    return np.ascontiguousarray(rgb, np.float32)


def curve_profile(ob, owner):
    """(k, 2) (radius, height) of the first spline of a curve object, base first (§4.4): local X
    the radius, the longer of local Y and Z the height."""
    if ob is None:
        raise BakeError(f"{source_at(owner)}: Profile is Custom Curve but Profile "
                        "Curve is empty: pick a curve object drawn from the base to the tip")
    if not ob.data.splines or len(ob.data.splines[0].points) + len(
            ob.data.splines[0].bezier_points) < 2:
        raise BakeError(f"{source_at(owner)}: Profile Curve '{ob.name}' needs a "
                        "spline of at least 2 points")
    sp = ob.data.splines[0]
    pts = ([p.co[:3] for p in sp.bezier_points] if sp.type == 'BEZIER'
           else [p.co[:3] for p in sp.points])
    pts = np.asarray(pts, np.float64)
    span = pts.max(axis=0) - pts.min(axis=0)
    up = 2 if span[2] >= span[1] else 1
    out = np.stack([pts[:, 0], pts[:, up]], axis=1)
    if out[-1, 1] < out[0, 1]:
        out = out[::-1]
    return out


def _corner_uvs(ob, depsgraph):
    """(M, 3, 2) UVs of the evaluated mesh's loop triangles, or None without a UV map."""
    me = ob.evaluated_get(depsgraph).to_mesh()
    try:
        if not me.uv_layers:
            return None
        me.calc_loop_triangles()
        loops = np.empty(len(me.loop_triangles) * 3, np.int64)
        me.loop_triangles.foreach_get("loops", loops)
        uv = np.empty(len(me.loops) * 2, np.float32)
        me.uv_layers.active.data.foreach_get("uv", uv)
        return uv.reshape(-1, 2)[loops].reshape(-1, 3, 2)
    finally:
        ob.evaluated_get(depsgraph).to_mesh_clear()


def source_input(ob, depsgraph, seed, settings, fps):
    """The fixed part of a Flame Source (its flame places, spread values, profile, image)."""
    fl = ob.plume.flame
    lo, hi = flames.FLAMES_PER_SOURCE_RANGE
    if not lo <= fl.flames <= hi:
        raise BakeError(f"{source_at(ob.name)}: Flames must be in [{lo}, {hi}] "
                        f"(got {fl.flames})")
    src = flames.FlameSourceInput(name=ob.name, profile=fl.profile)
    if fl.profile == 'CUSTOM':
        src.profile_points = curve_profile(fl.profile_curve, ob.name)
    src.color_source = fl.color_source
    if fl.color_source == 'IMAGE':
        src.color_image = color_image(fl.color_image, ob.name)
    verts, tris = mesh_arrays(ob, depsgraph)
    order = place.canonical_order(tris)
    tris = tris[order]
    if len(tris) == 0:
        raise BakeError(f"Plume: Flame Source '{ob.name}' has no faces to burn on: make a mesh "
                        "with faces the Flame Source")
    m = np.array(ob.matrix_world, np.float64)
    world = verts.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
    faces, bary = place.place_flames(world, tris, int(fl.flames), seed)
    corners = verts.astype(np.float64)[tris]
    src.local_points = place.interpolate(corners, faces, bary)
    _areas, normals = place.face_data(verts.astype(np.float64), tris.astype(np.int64))
    src.local_normals = normals[faces]
    k = len(faces)
    src.start_times, src.end_times = np.zeros(k), np.full(k, math.inf)
    src.intensity_scale, src.diameter_scale, src.height_scale = (np.ones(k) for _ in range(3))
    if fl.spread == 'MAPS':
        _maps(ob, fl, depsgraph, faces, bary, src, order)
    elif fl.spread == 'MODEL':
        _spread_model(ob, fl, settings, world[tris], faces, bary, src)
    return src


def _maps(ob, fl, depsgraph, faces, bary, src, order):
    """§6.2: activation, duration, intensity, diameter and height maps on the UVs."""
    if fl.activation_map is None:
        raise BakeError(f"{source_at(ob.name)}: Spread is Maps but Activation Map "
                        "is empty: pick the image whose brightness gives each point's ignition time")
    corner_uvs = _corner_uvs(ob, depsgraph)
    if corner_uvs is None:
        raise BakeError(f"Plume: Flame Source '{ob.name}' has no UV map for its spread maps: "
                        "add one (Object Data Properties › UV Maps › +), or set Spread to "
                        f"Always Burning ({FLAME_SOURCE})")
    uvs = place.interpolate(corner_uvs[order], faces, bary)

    def sample(image, setting):
        return place.sample_map(image_pixels(image, ob.name, setting), uvs)
    src.start_times = sample(fl.activation_map, "Activation Map") * float(fl.time_scale)
    if fl.duration_map is not None:
        src.end_times = src.start_times + sample(fl.duration_map, "Duration Map") * float(
            fl.duration_scale)
    for image, setting, attr in ((fl.intensity_map, "Intensity Map", "intensity_scale"),
                                 (fl.diameter_map, "Diameter Map", "diameter_scale"),
                                 (fl.height_map, "Height Map", "height_scale")):
        if image is not None:
            # A black texel would give a zero diameter or height: keep a small floor.
            setattr(src, attr, np.maximum(sample(image, setting),
                                          0.0 if attr == "intensity_scale" else 0.01))


def _spread_model(ob, fl, settings, world_corners, faces, bary, src):
    """§6.2 eq. 7 from the Ignition object (or the source's origin)."""
    if not (fl.spread_temperature > 0.0 and fl.spread_thickness > 0.0):
        raise BakeError(f"{source_at(ob.name)}: Flame Temperature (T_f) and Thermal "
                        "Thickness (L) of eq. 7 must be > 0")
    origin = (fl.ignition or ob).matrix_world.translation
    points = place.interpolate(world_corners, faces, bary)
    src.start_times = place.spread_times(points, tuple(origin), float(fl.spread_temperature),
                                         float(fl.spread_thickness),
                                         float(settings.height_intermittent))


def _winds(scene, f):
    out = [flames.WindInput('UNIFORM', vector=tuple(float(v) for v in f.wind))]
    for ob in scene.objects if f.use_force_fields else ():
        fld = ob.field
        if fld is None or ob.hide_render or fld.type not in {'WIND', 'VORTEX', 'TURBULENCE'}:
            continue
        axis = np.array(ob.matrix_world.to_3x3().col[2], np.float64)
        axis /= max(float(np.linalg.norm(axis)), 1e-12)
        loc = tuple(ob.matrix_world.translation)
        if fld.type == 'WIND':
            out.append(flames.WindInput('UNIFORM', vector=tuple(fld.strength * axis)))
        elif fld.type == 'VORTEX':
            out.append(flames.WindInput('VORTEX', vector=tuple(axis), centre=loc,
                                        strength=float(fld.strength), size=1.0))
        else:
            out.append(flames.WindInput('TURBULENCE', strength=float(fld.strength),
                                        size=max(float(fld.size), 1e-3),
                                        flow=float(fld.flow), seed=int(fld.seed)))
    return out


def _camera(scene):
    cam = scene.camera
    if cam is None or cam.type != 'CAMERA':
        return None
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return flames.CameraInput(position=tuple(cam.matrix_world.translation),
                              focal_length=float(cam.data.lens),
                              sensor_width=float(cam.data.sensor_width),
                              width=max(1, int(r.resolution_x * scale)),
                              height=max(1, int(r.resolution_y * scale)))


def flames_snapshot(context):
    """The whole bake's input; BakeError on bad input (nothing is written here)."""
    scene = context.scene
    f = scene.plume_flames
    objs = flame_sources(scene)
    if not objs:
        raise BakeError(flames.NO_SOURCE)
    if f.frame_end < f.frame_start:
        raise BakeError(f"Plume: Flames: {ui('flames', 'frame_end')} must be >= Start (got "
                        f"{f.frame_start} to {f.frame_end})")
    fps = scene.render.fps / scene.render.fps_base
    wind_domain = None
    if f.wind_domain is not None:
        wind_domain = (f.wind_domain.name, cache_folder_of(f.wind_domain))
    current, subframe = scene.frame_current, scene.frame_subframe
    try:
        scene.frame_set(f.frame_start)
        depsgraph = context.evaluated_depsgraph_get()
        first = settings_now(f)
        flames.validate_settings(first, f.frame_start)
        sources = [source_input(o, depsgraph, int(f.seed), first, fps) for o in objs]
        obstacles = []
        if f.use_obstacles:
            for o in scene.objects:
                if o.type == 'MESH' and o.plume.role == 'OBSTACLE':
                    v, t = mesh_arrays(o, depsgraph)
                    m = np.array(o.matrix_world, np.float64)
                    obstacles.append(flames.ObstacleInput(
                        o.name, (v.astype(np.float64) @ m[:3, :3].T + m[:3, 3]).astype(
                            np.float32), t))
        settings, winds, cameras = [], [], []
        for frame in range(f.frame_start - 1, f.frame_end + 1):
            scene.frame_set(frame)
            for ob, src in zip(objs, sources):
                src.matrices.append(np.array(ob.matrix_world, np.float64))
                fl = ob.plume.flame
                if frame >= f.frame_start:
                    src.values.append((float(fl.radius), float(fl.intensity),
                                       float(fl.temperature), float(fl.stops)))
            if frame >= f.frame_start:
                settings.append(settings_now(f))
                winds.append(_winds(scene, f))
                cameras.append(_camera(scene))
    finally:
        scene.frame_set(current, subframe=subframe)
    return flames.FlameBakeSnapshot(
        folder=flames_cache_folder(scene), frame_start=int(f.frame_start),
        frame_end=int(f.frame_end),
        fps=float(fps), seed=int(f.seed), substeps=int(f.substeps), sources=sources,
        settings=settings, winds=winds, cameras=cameras, obstacles=obstacles,
        wind_domain=wind_domain)
