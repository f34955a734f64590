"""Scene -> BakeSnapshot of a domain's grid bake (smoke, fire, streak tracers, pathlines): the
solver settings, the emitters, a traced Mantaflow cache and Flame Smoke. Runs on the main thread
before a bake starts."""

import dataclasses

from ..mantaflow_cache import BORDER_SETTINGS, MantaflowSource
from ..settings import (BOUNDARY_SIDES, BakeError, BakeSnapshot, SolverSettings, domain_grid,
                        physical_buoyancy, validate_python_side)
from .flowgraph import pathline_settings
from .scene import (absolute_folder, active_domain, cache_folder_of, domain_bbox,
                    emitter_snapshots, flames_cache_folder, from_properties)
from .streaks import streak_settings


def solver_settings(domain, scene, cells, cell_size, origin):
    """The domain's SolverSettings: the grid derived from its box, the frame time step, and every
    other field copied from the same-named domain property."""
    d = domain.plume.domain
    fps = scene.render.fps / scene.render.fps_base
    alpha, beta = physical_buoyancy(d.alpha, d.beta, d.buoyancy_units,
                                    max(cells) * float(cell_size))
    return from_properties(
        SolverSettings, d, resolution=tuple(cells), cell_size=float(cell_size),
        origin=tuple(origin),
        boundaries=tuple(getattr(d, "boundary_" + side) for side in BOUNDARY_SIDES),
        frame_dt=float(d.time_scale) / fps, alpha=alpha, beta=beta)


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
        streaks=streak_settings(d),
        mantaflow=mantaflow_source(domain, scene) if d.motion_source == 'MANTAFLOW' else None,
        pathlines=pathline_settings(d),
        flame_smoke=smoke, velocity_everywhere=bool(d.velocity_everywhere))


def flame_smoke_settings(domain, scene):
    """The domain's Flame Smoke settings ([Structural Flames] §6.3) and the scene's flames
    cache folder; None when off. The flames cache is read by BakeRunner.prepare()."""
    d = domain.plume.domain
    if not d.flame_smoke:
        return None
    if d.motion_source == 'MANTAFLOW':
        raise BakeError(f"Plume: domain '{domain.name}': Flame Smoke feeds the Plume solver: set "
                        "Motion to Plume Simulation or turn Flame Smoke off")
    from ..flame_smoke import FlameSmokeSettings
    return FlameSmokeSettings(enabled=True, smoke_yield=float(d.flame_smoke_yield),
                              temperature=float(d.flame_smoke_temperature),
                              smoke_point=float(d.flame_smoke_point),
                              folder=flames_cache_folder(scene))
