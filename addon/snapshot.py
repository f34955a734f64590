"""Scene -> BakeSnapshot (bpy side). Runs on the main thread before a bake starts."""

import dataclasses
import os

import bpy
import numpy as np
from mathutils import Vector

from . import blender_compat as compat
from . import cache
from .mantaflow_cache import BORDER_SETTINGS, MantaflowSource
from .settings import (BOUNDARY_SIDES, BakeError, BakeSnapshot, EmitterSnapshot,
                       PathlineSettings, SolverSettings, SourceParams, StreakSettings, domain_grid)

NOT_A_DOMAIN = ("Plume: the active object is not a Plume domain "
                "(set one with plume.role_set(role='DOMAIN'))")

#: Roles that take part in a grid bake (Flame Sources belong to flames_bake).
EMITTER_ROLES = {'SOURCE', 'OBSTACLE'}


def active_domain(context):
    """The active object if it is a Plume domain, else raises BakeError."""
    obj = getattr(context, "active_object", None)
    if obj is None or getattr(obj, "plume", None) is None or obj.plume.role != 'DOMAIN':
        raise BakeError(NOT_A_DOMAIN)
    if obj.type != 'MESH':
        raise BakeError(f"Plume: domain '{obj.name}' must be a mesh object (got {obj.type})")
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


def solver_settings(domain, scene, cells, cell_size, origin):
    d = domain.plume.domain
    fps = scene.render.fps / scene.render.fps_base
    return SolverSettings(
        resolution=tuple(cells), cell_size=float(cell_size), origin=tuple(origin),
        boundaries=tuple(getattr(d, "boundary_" + side) for side in BOUNDARY_SIDES),
        frame_dt=float(d.time_scale) / fps, substeps=int(d.substeps), use_cfl=bool(d.use_cfl),
        cfl=float(d.cfl), advection=d.advection, interpolation=d.interpolation, trace=d.trace,
        conserve_mass=bool(d.conserve_mass),
        gravity=tuple(float(v) for v in d.gravity), alpha=float(d.alpha), beta=float(d.beta),
        ambient_temperature=float(d.ambient_temperature), wind=tuple(float(v) for v in d.wind),
        wind_strength=float(d.wind_strength), vorticity=float(d.vorticity),
        density_dissipation=float(d.density_dissipation),
        pressure_tolerance=float(d.pressure_tolerance),
        max_pressure_iterations=int(d.max_pressure_iterations), combustion=bool(d.combustion),
        burn_rate=float(d.burn_rate), soot_yield=float(d.soot_yield),
        heat_yield=float(d.heat_yield), conductivity=float(d.conductivity),
        cooling_rate=float(d.cooling_rate), max_temperature=float(d.max_temperature),
        expansion=float(d.expansion), seed=int(d.seed), threads=int(d.threads))


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
    groups of point sources (smoke_surfaces.txt §3.3)."""
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
    positions of the evaluated mesh's vertices at frame_start (smoke_surfaces.txt §3.2, one point
    source per vertex). The current frame is restored."""
    picked = [(o.plume.source.point_source_mesh, snap) for o, snap in zip(objs, snaps)
              if o.plume.role == 'SOURCE' and o.plume.source.point_source_mesh is not None]
    for mesh_obj, snap in picked:
        if mesh_obj.type != 'MESH':  # a script can bypass the property's poll
            raise BakeError(f"Plume: source '{snap.name}': point_source_mesh '{mesh_obj.name}' "
                            f"must be a mesh object (got {mesh_obj.type})")
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


def mantaflow_source(domain, scene):
    """The Mantaflow domain a streak bake traces (motion_source 'MANTAFLOW'), as plain data;
    mantaflow_cache.check_source() validates it."""
    ob = domain.plume.domain.mantaflow_domain
    source = MantaflowSource(domain_name=domain.name, object_name=ob.name if ob else "")
    mod = next((m for m in ob.modifiers if m.type == 'FLUID'), None) if ob else None
    ds = mod.domain_settings if mod is not None and mod.fluid_type == 'DOMAIN' else None
    if ds is None or ds.domain_type != 'GAS':
        return source
    return dataclasses.replace(
        source, is_gas_domain=True, cache_directory=absolute_folder(ds.cache_directory),
        cache_data_format=ds.cache_data_format, cache_frame_start=int(ds.cache_frame_start),
        cache_frame_end=int(ds.cache_frame_end), use_adaptive_domain=bool(ds.use_adaptive_domain),
        borders_closed=tuple(bool(getattr(ds, n)) for n in BORDER_SETTINGS),
        fps=scene.render.fps / scene.render.fps_base, time_scale=float(ds.time_scale))


def take_snapshot(context, addon_version="0.1.0"):
    """Everything the bake needs from the scene; BakeError for problems visible from here."""
    domain = active_domain(context)
    d = domain.plume.domain
    scene = context.scene
    from .settings import validate_python_side
    resolution = int(d.resolution)
    frame_start, frame_end = int(d.frame_start), int(d.frame_end)
    # Cheap checks first, before the grid size is derived from the resolution.
    validate_python_side(domain.name, resolution, frame_start, frame_end, SolverSettings())
    lo, hi = domain_bbox(domain, context.evaluated_depsgraph_get())
    try:
        cells, cell_size, origin = domain_grid(lo, hi, resolution)
    except BakeError as e:
        raise BakeError(f"{e} (domain '{domain.name}')") from None
    solver = solver_settings(domain, scene, cells, cell_size, origin)
    validate_python_side(domain.name, resolution, frame_start, frame_end, solver)
    smoke = flame_smoke_settings(domain, scene)
    return BakeSnapshot(
        domain_name=domain.name, resolution=resolution, frame_start=frame_start,
        frame_end=frame_end, cache_directory=d.cache_directory,
        cache_folder=cache_folder_of(domain), solver=solver,
        emitters=emitter_snapshots(context, domain, frame_start, frame_end),
        addon_version=addon_version,
        streaks=StreakSettings(enabled=bool(d.streaks), emission_period=int(d.emission_period),
                               max_streaklines=int(d.max_streaklines)),
        mantaflow=mantaflow_source(domain, scene) if d.motion_source == 'MANTAFLOW' else None,
        pathlines=PathlineSettings(enabled=bool(d.pathlines),
                                   nodes_per_frame=int(d.pathline_nodes_per_frame),
                                   lifetime=float(d.pathline_lifetime),
                                   float16=bool(d.pathline_float16)),
        flame_smoke=smoke, velocity_everywhere=bool(d.velocity_everywhere))


def flame_smoke_settings(domain, scene):
    """The domain's Flame Smoke settings (structural_flames.txt §6.3) and the scene's flames
    cache folder; None when off. The flames cache is read by BakeRunner.prepare()."""
    d = domain.plume.domain
    if not d.flame_smoke:
        return None
    if d.motion_source == 'MANTAFLOW':
        raise BakeError(f"Plume: domain '{domain.name}': Flame Smoke feeds the Plume solver: set "
                        "Motion to Plume Simulation or turn Flame Smoke off")
    from .flame_smoke import FlameSmokeSettings
    return FlameSmokeSettings(enabled=True, smoke_yield=float(d.flame_smoke_yield),
                              temperature=float(d.flame_smoke_temperature),
                              folder=flames_cache_folder(scene))
