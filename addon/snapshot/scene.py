"""Scene reading that every pipeline's snapshot shares (bpy side, main thread): the active
domain, "//" paths and cache folders, evaluated mesh arrays, the Sources and Obstacles over a
frame range, and same-named properties copied into a settings dataclass."""

import dataclasses
import os

import bpy
import numpy as np
from mathutils import Vector

from .. import blender_compat as compat
from .. import cache
from ..settings import BakeError, EmitterSnapshot, SourceParams

NOT_A_DOMAIN = ("Plume: the active object is not a Plume domain: select the domain, or make "
                "a box one with Physics Properties › Plume › Domain")

#: Roles that take part in a grid bake (Flame Sources belong to flames_bake).
EMITTER_ROLES = {'SOURCE', 'OBSTACLE'}


def active_domain(context):
    """The active object if it is a Plume domain, else raises BakeError."""
    obj = getattr(context, "active_object", None)
    if obj is None or getattr(obj, "plume", None) is None or obj.plume.role != 'DOMAIN':
        raise BakeError(NOT_A_DOMAIN)
    if obj.type != 'MESH':
        raise BakeError(f"Plume: domain '{obj.name}' must be a mesh object (its type is "
                        f"{obj.type.title()}): make a box mesh the domain")
    return obj


def absolute_folder(path):
    """An absolute folder of a path setting: "//" is relative to the saved .blend; in an unsaved
    file it is relative to the working directory, as Blender does."""
    base = bpy.path.abspath(path)
    if base.startswith("//"):
        base = base[2:]
    return os.path.abspath(base or ".")


def blend_relative(path):
    """`path` as objects store it: "//"-relative when the .blend is saved (a render farm sees the
    same paths), else absolute."""
    if bpy.data.is_saved:
        try:
            return bpy.path.relpath(path)
        except ValueError:  # another drive
            return path
    return path


def cache_folder_of(domain):
    """Absolute cache folder of a domain: abspath(cache_directory)/<domain name>/."""
    base = absolute_folder(domain.plume.domain.cache_directory or "//plume_cache/")
    return cache.cache_folder(base, domain.name)


def flames_cache_folder(scene):
    """Absolute folder of the flames bake (scene.plume_flames.cache_directory)."""
    return absolute_folder(scene.plume_flames.cache_directory or "//plume_cache/flames/")


def domain_bbox(domain, depsgraph):
    """World-space bounding box of the evaluated domain mesh."""
    ob = domain.evaluated_get(depsgraph)
    corners = [ob.matrix_world @ Vector(c) for c in ob.bound_box]
    lo = tuple(min(c[a] for c in corners) for a in range(3))
    hi = tuple(max(c[a] for c in corners) for a in range(3))
    return lo, hi


def _is_animated(obj):
    """True when the object or a parent has animation, drivers or constraints."""
    while obj is not None:
        ad = obj.animation_data
        if ad is not None and (ad.action is not None or len(ad.drivers) or len(ad.nla_tracks)):
            return True
        if len(obj.constraints):
            return True
        obj = obj.parent
    return False


def _source_is_keyed(obj):
    """True when the object's Plume source settings are keyframed (action or NLA strips) or
    driven: F-curves or drivers whose data path starts with "plume.source"."""
    ad = obj.animation_data
    if ad is None:
        return False
    actions = [ad.action] + [strip.action for track in ad.nla_tracks for strip in track.strips]
    paths = [fc.data_path for a in actions if a is not None
             for fc in compat.action_fcurves(a)]
    paths += [d.data_path for d in ad.drivers]
    return any(p.startswith("plume.source") for p in paths)


def source_params(s):
    """A source's settings (obj.plume.source) now, as plain data."""
    return SourceParams(density=float(s.density), temperature=float(s.temperature),
                        fuel=float(s.fuel), velocity=tuple(float(v) for v in s.velocity),
                        motion_factor=float(s.motion_factor),
                        fuel_noise=float(s.fuel_noise),
                        fuel_noise_scale=float(s.fuel_noise_scale),
                        fuel_noise_rate=float(s.fuel_noise_rate),
                        smoke_noise=float(s.smoke_noise),
                        smoke_noise_scale=float(s.smoke_noise_scale),
                        smoke_noise_rate=float(s.smoke_noise_rate),
                        emit_particles=bool(s.emit_particles))


def mesh_arrays(obj, depsgraph):
    """Object-local vertices (float32 (N,3)) and triangles (int32 (M,3)) of the evaluated mesh."""
    ob = obj.evaluated_get(depsgraph)
    mesh = ob.to_mesh()
    try:
        mesh.calc_loop_triangles()
        verts = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", verts)
        tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", tris)
    finally:
        ob.to_mesh_clear()
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


def vertex_group_of_vertices(obj, depsgraph):
    """The vertex group each vertex of the evaluated mesh belongs to most (its index, -1 for
    none), int64 (N,), or None when the object has no vertex groups: hand-made candidate
    groups of point sources ([Smoke Surfaces] §3.3)."""
    if not obj.vertex_groups:
        return None
    ob = obj.evaluated_get(depsgraph)
    mesh = ob.to_mesh()
    try:
        return np.array([max(v.groups, key=lambda g: g.weight).group
                         if any(g.weight > 0.0 for g in v.groups) else -1
                         for v in mesh.vertices], dtype=np.int64)
    finally:
        ob.to_mesh_clear()


def scene_emitters(scene, domain):
    return [o for o in scene.objects
            if o is not domain and o.type == 'MESH' and o.plume.role in EMITTER_ROLES]


def emitter_snapshots(context, domain, frame_start, frame_end):
    """Meshes at the current frame, matrices at frame_start .. frame_end + 1 and source settings
    at frame_start .. frame_end (evaluated per frame only for objects that are animated or whose
    source settings are keyframed or driven, e.g. Figure 10's density and emit_particles; the
    current frame is restored)."""
    scene = context.scene
    depsgraph = context.evaluated_depsgraph_get()
    objs = scene_emitters(scene, domain)
    snaps = []
    for o in objs:
        verts, tris = mesh_arrays(o, depsgraph)
        s = o.plume.source
        snaps.append(EmitterSnapshot(
            name=o.name, role=o.plume.role, vertices=verts, triangles=tris,
            matrices=[np.array(o.matrix_world, dtype=np.float64)],
            source=source_params(s) if o.plume.role == 'SOURCE' else None,
            slip=o.plume.obstacle.slip,
            point_placement=s.point_placement, point_sources=int(s.point_sources),
            candidate_group=int(s.candidate_group),
            candidate_split=int(s.candidate_split)))
    animated = [i for i, o in enumerate(objs) if _is_animated(o)]
    keyed = [i for i, o in enumerate(objs) if o.plume.role == 'SOURCE' and _source_is_keyed(o)]
    if animated or keyed:
        current, subframe = scene.frame_current, scene.frame_subframe
        for i in animated:
            snaps[i].matrices = []
        try:
            for f in range(frame_start, frame_end + 2):
                scene.frame_set(f)
                for i in animated:
                    snaps[i].matrices.append(np.array(objs[i].matrix_world, dtype=np.float64))
                for i in keyed if f <= frame_end else ():
                    snaps[i].source_frames.append(source_params(objs[i].plume.source))
        finally:
            scene.frame_set(current, subframe=subframe)
        for i in animated:  # e.g. only its source settings are keyed: one matrix, no re-voxelizing
            if all(np.array_equal(m, snaps[i].matrices[0]) for m in snaps[i].matrices):
                snaps[i].matrices = snaps[i].matrices[:1]
        for i in keyed:  # keys that change nothing in the frame range give one value
            snaps[i].source = snaps[i].source_frames[0]
            if all(p == snaps[i].source for p in snaps[i].source_frames):
                snaps[i].source_frames = []
    point_source_vertices(context, objs, snaps, frame_start)
    return snaps


def point_source_vertices(context, objs, snaps, frame_start):
    """Fills the point_source_mesh of each Source snapshot whose source has one: the world
    positions of the evaluated mesh's vertices at frame_start ([Smoke Surfaces] §3.2, one point
    source per vertex). The current frame is restored."""
    picked = [(o.plume.source.point_source_mesh, snap) for o, snap in zip(objs, snaps)
              if o.plume.role == 'SOURCE' and o.plume.source.point_source_mesh is not None]
    for mesh_obj, snap in picked:
        if mesh_obj.type != 'MESH':  # a script can bypass the property's poll
            raise BakeError(f"Plume: source '{snap.name}': point_source_mesh '{mesh_obj.name}' "
                            f"must be a mesh object (its type is {mesh_obj.type.title()})")
    if not picked:
        return
    scene = context.scene
    current, subframe = scene.frame_current, scene.frame_subframe
    moved = (current, subframe) != (frame_start, 0.0)
    try:
        if moved:
            scene.frame_set(frame_start)
        depsgraph = context.evaluated_depsgraph_get()
        for mesh_obj, snap in picked:
            local, _ = mesh_arrays(mesh_obj, depsgraph)
            m = np.array(mesh_obj.evaluated_get(depsgraph).matrix_world, dtype=np.float64)
            world = local.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
            snap.point_source_mesh = mesh_obj.name
            snap.point_source_vertices = world.astype(np.float32)
            snap.point_source_groups = vertex_group_of_vertices(mesh_obj, depsgraph)
            snap.point_source_group_names = [g.name for g in mesh_obj.vertex_groups]
    finally:
        if moved:
            scene.frame_set(current, subframe=subframe)


def from_properties(cls, props, **values):
    """An instance of dataclass `cls`: the fields given in `values`, the others read from the
    same-named properties of `props` (a PropertyGroup), each converted to the type of the field's
    default (a vector property to a tuple of the default's element type)."""
    for f in dataclasses.fields(cls):
        if f.name in values:
            continue
        default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
        value = getattr(props, f.name)
        if isinstance(default, tuple):
            values[f.name] = tuple(type(d)(v) for d, v in zip(default, value))
        else:
            values[f.name] = type(default)(value)
    return cls(**values)
