"""Streak surfaces -> Blender data ([Smoke Surfaces] §3.3-3.4): one SURFACE (NURBS) object per
cluster with a fixed control net, its per-frame control points in a cache file read by a
persistent frame_change_pre handler, and the "Plume Smoke Sheet" material whose opacity is
p = d e^(-|n·v|) with d from a density-map image sequence."""

import math
import os
import time

import bpy
import numpy as np

from . import frame_handlers, sheet_detail, surface_edits
from .. import blender_compat as compat
from ..snapshot import blend_relative

#: Custom properties of a surface object: its control-point cache and the domain it came from.
CACHE_KEY = "plume_surface_cache"
DOMAIN_KEY = "plume_surface_domain"
MATERIAL = "Plume Smoke Sheet"
#: Samples per control point without a scene camera to size them by (sheet_detail.py).
RESOLUTION_U, RESOLUTION_V = 2, 4


def resolution_u(order_u):
    """Blender's samples per control point along the streaklines without a camera. An order-2 net
    (one control point per particle where the streaklines scatter too much for a smooth sheet:
    streak_surfaces.NEAR_TOLERANCE_CELLS) is straight between its control points, and with 1
    sample per point Blender samples exactly at them (step (n - 1) / (n - 1)): the drawn sheet is
    the fitted one, through every particle. With 2, the samples fall between the particles and
    cut the corners of every zig-zag, and the sheet renders as bright creased outlines instead of
    smoke."""
    return 1 if order_u <= 2 else RESOLUTION_U


def default_resolutions(order_u, order_v):
    """(resolution_u, resolution_v) without a camera."""
    return resolution_u(order_u), (1 if order_v <= 2 else RESOLUTION_V)

# path -> (mtime, frame_start, control points (frames, n, 4) float32)
_loaded = {}
#: Seconds the last handler call spent per surface (measured by tests).
last_update_seconds = []


def collection_name(domain):
    return f"{domain.name}_surfaces"


# --------------------------------------------------------------------------- frame handler
def _control_points(path):
    try:
        mtime = os.path.getmtime(path)
    except OSError:
        return None
    hit = _loaded.get(path)
    if hit is not None and hit[0] == mtime:
        return hit
    try:
        with np.load(path) as z:
            hit = (mtime, int(z["frame_start"]),
                   np.ascontiguousarray(z["control_points"], dtype=np.float32))
    except (OSError, ValueError, KeyError):
        return None
    _loaded[path] = hit
    return hit


def cache_of(ob):
    """(frame_start, control points (frames, n, 4) float32) of a Plume surface, or None."""
    path = ob.get(CACHE_KEY)
    if not path or ob.type != 'SURFACE' or not ob.data.splines:
        return None
    hit = _control_points(bpy.path.abspath(path))
    if hit is None or len(ob.data.splines[0].points) != hit[2].shape[1]:
        return None  # missing cache, or the artist changed the net's topology: leave it alone
    return hit[1], hit[2]


def update_object(ob, frame):
    """Sets the surface's control points of `frame` (clamped to the baked range) plus the hand
    edits (surface_edits.py), capturing first any edit made since the last update. True if set.
    A frame between two frames (motion blur's sub-frames) blends the two around it. Baked
    surfaces (keyframes) and surfaces in edit mode are left alone."""
    if ob.get(surface_edits.BAKED_KEY) or ob.mode == 'EDIT':
        return False
    hit = cache_of(ob)
    if hit is None:
        return False
    frame_start, cps = hit
    surface_edits.capture(ob, cps)
    at = min(max(frame - frame_start, 0.0), float(len(cps) - 1))
    i = int(math.floor(at))
    surface_edits.write(ob, cps, i, at - i)
    return True


def update_detail(ob, scene):
    """Sets the surface's tessellation from the scene's camera (sheet_detail.py), for the
    control points it has now; not in edit mode (the artist's own settings while editing)."""
    if ob.type != 'SURFACE' or not ob.data.splines or ob.mode == 'EDIT':
        return False
    return sheet_detail.update(ob, scene, default_resolutions)


def update_all(frame, scene=None):
    """Every Plume surface to `frame`, then its tessellation to the camera of `scene` (the
    context's when None); last_update_seconds holds the time each surface took."""
    scene = scene if scene is not None else bpy.context.scene
    del last_update_seconds[:]
    for ob in bpy.data.objects:
        if CACHE_KEY in ob:
            t0 = time.perf_counter()
            moved = update_object(ob, frame)
            if moved or ob.get(surface_edits.BAKED_KEY):
                update_detail(ob, scene)
            if moved:
                last_update_seconds.append(time.perf_counter() - t0)


@bpy.app.handlers.persistent
def frame_change_pre(scene, *_args):
    # frame_current + frame_subframe: Cycles' motion blur sets the scene between frames. The
    # camera is where the last evaluation left it: a camera moving between frames sizes the
    # sheet's tessellation from its previous pose.
    update_all(scene.frame_current + scene.frame_subframe, scene)


def register():
    frame_handlers.add(frame_change_pre)


def unregister():
    frame_handlers.remove(frame_change_pre)
    _loaded.clear()
    surface_edits._frames.clear()


# --------------------------------------------------------------------------- objects
def surface_object(name, collection, nu, nv, view_layer):
    """SURFACE object with an nu x nv NURBS net built from 1-D NURBS rows. make_segment merges
    the 1-D rows and transposes them; with 2 rows it leaves them unmerged in 3.4.1, so one u row
    is extruded once instead (blender_tests/test_nurbs_tessellation.py)."""
    cu = bpy.data.curves.new(name, 'SURFACE')
    cu.dimensions = '3D'
    rows = nu if nv > 2 else 1
    for _ in range(rows):
        sp = cu.splines.new('NURBS')
        sp.points.add((nv if nv > 2 else nu) - 1)
        for p in sp.points:
            p.select = True
    ob = bpy.data.objects.new(name, cu)
    collection.objects.link(ob)
    for o in view_layer.objects:
        o.select_set(False)
    ob.select_set(True)
    view_layer.objects.active = ob
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.curve.select_all(action='SELECT')
    if nv > 2:
        bpy.ops.curve.make_segment()
    else:
        bpy.ops.curve.extrude_move(CURVE_OT_extrude={"mode": 'TRANSLATION'},
                                   TRANSFORM_OT_translate={"value": (0.0, 0.0, 1.0)})
    bpy.ops.object.mode_set(mode='OBJECT')
    sp = cu.splines[0]
    if len(cu.splines) != 1 or (sp.point_count_u, sp.point_count_v) != (nu, nv):
        raise RuntimeError(f"Plume: could not make a {nu} x {nv} NURBS net for '{name}' "
                           f"(got {len(cu.splines)} splines)")
    return ob


def remove_surfaces(domain):
    """Deletes the domain's surface objects, their curves, materials and images."""
    coll = bpy.data.collections.get(domain.plume.domain.surfaces_collection or
                                    collection_name(domain))
    obs = [o for o in bpy.data.objects if o.get(DOMAIN_KEY) == domain.name]
    for ob in obs:
        cu = ob.data
        mats = [m for m in cu.materials if m is not None] if cu is not None else []
        bpy.data.objects.remove(ob, do_unlink=True)
        if cu is not None and cu.users == 0:
            bpy.data.curves.remove(cu)
        for m in mats:
            if m.users == 0:
                imgs = [n.image for n in m.node_tree.nodes if n.type == 'TEX_IMAGE' and n.image]
                bpy.data.materials.remove(m)
                for img in imgs:
                    if img.users == 0:
                        bpy.data.images.remove(img)
    if coll is not None and not coll.objects:
        bpy.data.collections.remove(coll)
    domain.plume.domain.surfaces_collection = ""
    _loaded.clear()
    surface_edits._frames.clear()


def build_surfaces(context, domain, folder, frame_start, anims, sheets, settings):
    """Creates the collection and one SURFACE object per SurfaceAnimation (replacing the old ones);
    `sheets[i]` = (first image path, width, height, frames) of surface i's density map."""
    from .. import cache
    remove_surfaces(domain)
    scene, view_layer = context.scene, context.view_layer
    prev_active = view_layer.objects.active
    prev_selected = [o for o in view_layer.objects if o.select_get()]
    coll = bpy.data.collections.new(collection_name(domain))
    scene.collection.children.link(coll)
    objects = []
    try:
        for i, anim in enumerate(anims):
            name = f"{domain.name}_surface_{i}"
            ob = surface_object(name, coll, anim.nu, anim.nv, view_layer)
            sp = ob.data.splines[0]
            frame = min(max(scene.frame_current - frame_start, 0), len(anim.control_points) - 1)
            sp.points.foreach_set("co", anim.control_points[frame].ravel())
            ob[surface_edits.FRAME_KEY] = frame
            sp.order_u, sp.order_v = anim.order_u, anim.order_v
            sp.use_endpoint_u = sp.use_endpoint_v = True
            sp.resolution_u, sp.resolution_v = default_resolutions(anim.order_u, anim.order_v)
            update_detail(ob, scene)
            ob[CACHE_KEY] = blend_relative(cache.surface_path(folder, i))
            _control_points(cache.surface_path(folder, i))  # loaded now, not on the first frame
            ob[DOMAIN_KEY] = domain.name
            path, width, height, frames = sheets[i]
            ob.data.materials.append(sheet_material(f"{MATERIAL} {name}", path, width, height,
                                                    frame_start, frames, settings))
            ob.data.update_tag()
            objects.append(ob)
    finally:
        for o in view_layer.objects:
            o.select_set(o in prev_selected)
        view_layer.objects.active = prev_active
    domain.plume.domain.surfaces_collection = coll.name
    return objects


# --------------------------------------------------------------------------- density images
def write_sheet_images(folder, index, frame_start, images):
    """Saves one float OpenEXR per frame (§3.4 density map, rows = v); returns the first path."""
    from .. import cache
    h, w = images[0].shape
    img = bpy.data.images.new(f"plume_sheet_tmp_{index}", w, h, alpha=False, float_buffer=True)
    # Densities, not colours: a new float image is sRGB, and saving it would write the densities
    # sRGB-encoded (0.26 -> 0.55), which the material (reading Non-Color) took as they are.
    img.colorspace_settings.name = 'Non-Color'
    try:
        img.file_format = 'OPEN_EXR'
        rgba = np.ones((h, w, 4), dtype=np.float32)
        for n, d in enumerate(images):
            rgba[..., 0] = rgba[..., 1] = rgba[..., 2] = d
            img.pixels.foreach_set(rgba.ravel())
            img.filepath_raw = cache.sheet_path(folder, index, frame_start + n)
            img.save()
    finally:
        bpy.data.images.remove(img)
    return cache.sheet_path(folder, index, frame_start)


def lit_film(nt, color, location):
    """A thin film of smoke lit by the scene: half diffuse reflection (the side facing a lamp),
    half diffuse transmission (the light glowing through from behind). Returns its mix node."""
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.location = (location[0] - 200, location[1])
    translucent = nt.nodes.new("ShaderNodeBsdfTranslucent")
    translucent.location = (location[0] - 200, location[1] - 150)
    for node in (diffuse, translucent):
        node.inputs["Color"].default_value = color
    film = nt.nodes.new("ShaderNodeMixShader")
    film.label = "Lit Film"
    film.location = location
    film.inputs["Fac"].default_value = 0.5
    nt.links.new(diffuse.outputs[0], film.inputs[1])
    nt.links.new(translucent.outputs[0], film.inputs[2])
    return film


def sheet_material(name, image_path, width, height, frame_start, frames, settings):
    """p = d × e^(−|n·v|) (or 1 − |n·v|), Transparent mixed by p with Emission (§3.4), or with
    Lit shading with a thin lit film (lit_film)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    compat.set_transparency(mat, 'BLEND')
    mat.use_backface_culling = False
    nt = mat.node_tree
    nt.nodes.clear()
    N, L = nt.nodes.new, nt.links.new

    def math_node(op, a=None, b=None, x=0, y=0, clamp=False):
        m = N("ShaderNodeMath")
        m.operation, m.use_clamp, m.location = op, clamp, (x, y)
        for k, v in ((0, a), (1, b)):
            if isinstance(v, (int, float)):
                m.inputs[k].default_value = v
            elif v is not None:
                L(v, m.inputs[k])
        return m.outputs[0]

    # Density d from the per-surface image sequence on the surface's generated UVs.
    tc = N("ShaderNodeTexCoord")
    tc.location = (-1200, 200)
    mp = N("ShaderNodeMapping")
    mp.location = (-1000, 200)
    # Pixel i holds the density at UV i/(w-1): map UVs onto pixel centres.
    mp.inputs["Scale"].default_value = ((width - 1) / width, (height - 1) / height, 1.0)
    mp.inputs["Location"].default_value = (0.5 / width, 0.5 / height, 0.0)
    L(tc.outputs["UV"], mp.inputs["Vector"])
    tex = N("ShaderNodeTexImage")
    tex.location = (-800, 200)
    tex.interpolation = 'Linear'
    tex.extension = 'EXTEND'
    img = bpy.data.images.load(image_path, check_existing=False)
    img.source = 'SEQUENCE'
    img.colorspace_settings.name = 'Non-Color'
    tex.image = img
    iu = tex.image_user
    iu.frame_duration = frames
    iu.frame_start = frame_start
    iu.frame_offset = frame_start - 1  # files are numbered by scene frame
    iu.use_auto_refresh = True
    iu.use_cyclic = False
    L(mp.outputs["Vector"], tex.inputs["Vector"])
    sep = N("ShaderNodeSeparateColor")
    sep.location = (-550, 200)
    L(tex.outputs["Color"], sep.inputs["Color"])
    d = math_node('MULTIPLY', sep.outputs[0], float(settings["opacity"]), -350, 200)

    # |n·v| from the shading normal and the direction towards the viewer.
    geo = N("ShaderNodeNewGeometry")
    geo.location = (-1200, -200)
    dot = N("ShaderNodeVectorMath")
    dot.operation, dot.location = 'DOT_PRODUCT', (-1000, -200)
    L(geo.outputs["Normal"], dot.inputs[0])
    L(geo.outputs["Incoming"], dot.inputs[1])
    ndv = math_node('ABSOLUTE', dot.outputs["Value"], None, -800, -200)
    exp_term = math_node('POWER', math.e, math_node('MULTIPLY', ndv, -1.0, -650, -150), -500, -150)
    lin_term = math_node('SUBTRACT', 1.0, ndv, -650, -350)
    # Contour variant switch (0: e^(-|n·v|), 1: 1 - |n·v|), editable in the material.
    flag = N("ShaderNodeValue")
    flag.label = "Linear Contour (1 - |n·v|)"
    flag.location = (-650, -500)
    flag.outputs[0].default_value = 1.0 if settings["falloff"] == 'LINEAR' else 0.0
    term = math_node('ADD', exp_term, math_node(
        'MULTIPLY', math_node('SUBTRACT', lin_term, exp_term, -500, -350), flag.outputs[0],
        -350, -350), -200, -200)
    p = math_node('MULTIPLY', d, term, -50, 0, clamp=True)

    tr = N("ShaderNodeBsdfTransparent")
    tr.location = (100, 150)
    if settings.get("shading") == 'LIT':
        em = lit_film(nt, tuple(settings["color"]), (100, -50))
    else:
        em = N("ShaderNodeEmission")
        em.location = (100, -50)
        em.inputs["Color"].default_value = tuple(settings["color"])
        em.inputs["Strength"].default_value = float(settings["brightness"])
    mix = N("ShaderNodeMixShader")
    mix.location = (300, 50)
    L(p, mix.inputs["Fac"])
    L(tr.outputs[0], mix.inputs[1])
    L(em.outputs[0], mix.inputs[2])
    out = N("ShaderNodeOutputMaterial")
    out.location = (500, 50)
    L(mix.outputs[0], out.inputs["Surface"])
    return mat
