"""What a job's child computes, one function per job kind, no ``bpy``.

Each takes the spec its operator wrote into the job file (jobs/jobfile.py) and the ChildJob
(child.py: progress, cancel, watched native objects), and returns plain data (the add-on's
result dataclasses, dicts, arrays) that the child writes back for the operator's finish().
New files go where the spec says: a bake writes its cache folder frame by frame (complete frames
stay and resume), every other job into the staging folder its operator made (moved into place
only when the job succeeded)."""

import os

import numpy as np

from ..settings import BakeError


def _native():
    from ..native import _native
    return _native


def bake(spec, job):
    """The smoke bake of one domain (or the trace of its Mantaflow cache)."""
    from .. import bake_runner
    from ..mantaflow_trace import MantaflowTraceRunner
    snap = spec["snapshot"]
    cls = bake_runner.BakeRunner if snap.mantaflow is None else MantaflowTraceRunner

    def frame_done(p):
        job.set_progress(p.frames_done, p.frames_total, "frame", seconds_left=p.seconds_left)

    runner = cls(snap, _native(), progress=frame_done)
    runner.prepare()
    job.on_cancel(runner.cancel)  # the solver, tracers and recorder stop within one step
    return runner.run()


def flames(spec, job):
    """The structural flames of the scene's Flame Sources."""
    from .. import flames as flame_bake
    runner = flame_bake.FlameBakeRunner(
        _native(), spec["snapshot"], progress=lambda done, total: job.set_progress(done, total),
        cancel=lambda: job.cancelled)
    return runner.run()


def toon(spec, job):
    """Toon particles over the bake's frames into the staging folder, and the stencil."""
    from .. import toon as toon_smoke
    from ..toon_sources import ToonSourceCells
    from ..toon_stencils import write_stencil
    native, manifest, settings = _native(), spec["manifest"], spec["settings"]
    sources = ToonSourceCells(native, toon_smoke.toon_grid(manifest), spec["emitters"],
                              int(manifest["frame_start"]))
    runner = toon_smoke.ToonRunner(native, spec["folder"], manifest, settings,
                                   spec["domain_name"], out_folder=spec["staging"],
                                   progress=lambda done, total: job.set_progress(done, total),
                                   cancel=lambda: job.cancelled, sources=sources)
    result = runner.run()
    stencil = None
    if not job.cancelled and settings.stencil != 'IMAGE':
        stencil = write_stencil(spec["staging"], settings.stencil)
    return {"result": result, "stencil": stencil}


def flowgraph(spec, job):
    """The cost matrix and the flow graph of the states, staged."""
    from .. import flowgraph as graph
    native = _native()
    job.set_progress(0, 0, "reading the pathlines")
    states = graph.open_states(native, spec["states"])

    def attach(cost_job):
        job.watch(cost_job)
        job.follow(lambda: (int(100 * cost_job.progress), 100, "cost matrix (%)"))

    built = graph.build_graph(native, states, spec["settings"], spec["staging"], on_job=attach)
    return {"summary": built["summary"]}


def synthesis(spec, job):
    """The random walk and the rasterized frames, staged: all of them; a farm chunk's frames
    with its chunk.json; or, gathering, every chunk's frames linked in (flowgraph_chunks.py)."""
    from .. import flowgraph as graph, flowgraph_chunks as chunks
    native, settings = _native(), spec["settings"]
    if spec["gather"]:
        job.set_progress(0, 0, "gathering the farm's chunks")
        return chunks.gather(spec["folder"], spec["staging"], settings, spec["key"],
                             spec["owner"])
    g, states = graph.load_graph(native, spec["folder"], spec["owner"])
    runner = graph.SynthesisRunner(native, g, states, settings, spec["staging"],
                                   progress=lambda done, total: job.set_progress(done, total),
                                   cancel=lambda: job.cancelled, owner=spec["owner"])
    result = runner.run(write=spec["chunk"])
    if spec["chunk"] is not None and not result.cancelled:
        chunks.write_record(spec["staging"], *spec["chunk"], spec["key"], result)
    return result


def surfaces(spec, job):
    """h, the clusters, the NURBS animations and the density maps; the control points staged
    (the maps return to the operator, which saves them with Blender's image writer)."""
    from .. import cache, files
    from .. import streak_surfaces as ss
    native, folder, m = _native(), spec["folder"], spec["manifest"]
    frame_start, last = int(m["frame_start"]), int(m["last_complete_frame"])
    h0, settings, staged = spec["h0"], spec["settings"], spec["staging"]
    job.set_progress(0, 0, "reading the streak files")
    frames = ss.load_frames(native, folder, frame_start, last)
    job.check_cancel()
    job.set_progress(0, 0, "distances h between streaklines")
    groups = ss.group_distances(native, frames)
    job.check_cancel()
    plans = ss.plan_surfaces(native, groups, h0)
    if not plans:
        raise BakeError(f"Plume: Threshold (h0) {h0:g} joins no two streaklines: raise "
                        "Threshold (h0) in Physics Properties › Plume › Streak Surfaces (0 = the "
                        "default mean of h)")
    anims = []
    cell = float(m["cell_size"])
    lo = np.asarray(m["origin"], dtype=np.float64)
    box = (lo, lo + np.asarray(m["resolution"], dtype=np.float64) * cell)
    for i, plan in enumerate(plans):
        job.set_progress(i, len(plans), "surface")
        job.check_cancel()
        anims.append(ss.surface_animation(native, frames, plan, cell, box=box))
    maps = _density_maps(native, job, folder, m, anims, settings)
    for i, anim in enumerate(anims):
        job.check_cancel()
        files.save_npz(cache.surface_path(staged, i), control_points=anim.control_points,
                       frame_start=frame_start, nu=anim.nu, nv=anim.nv, order_u=anim.order_u,
                       order_v=anim.order_v)
        anim.surfaces = []  # per-frame fit data: the operator builds from the control points
    return {"frame_start": frame_start, "lines": sum(len(p.sources) for p in plans),
            "anims": anims, "maps": maps, "distances": ss.held_distances(groups)}


def _density_maps(native, job, folder, m, anims, settings):
    """§3.4 density map of every surface at every frame (from the VDB density grids)."""
    from .. import cache
    from .. import streak_surfaces as ss
    res = tuple(m["resolution"])
    origin, cell = tuple(m["origin"]), float(m["cell_size"])
    interp = getattr(native.Interpolation, m["settings"]["solver"]["interpolation"])
    frame_start = int(m["frame_start"])
    maps = [[] for _ in anims]
    count = len(anims[0].surfaces)
    for n in range(count):
        job.set_progress(n, count, "density map of frame")
        job.check_cancel()
        path = cache.volume_path(folder, frame_start + n)
        if not os.path.isfile(path):
            raise BakeError(f"Plume: volume file {path} is missing: bake the domain again")
        density = ss.dense_density(native, path, res)
        for i, anim in enumerate(anims):
            maps[i].append(ss.density_image(
                native, anim.surfaces[n], density, origin, cell, settings["k_u"],
                settings["k_v"], interp, anim.particles, anim.nv))
    return maps


def refine(name, points, nu, nv, density, level):
    """(vertices, quads, density per vertex in [0, 1]) of a surface's control net refined
    `level` times (OpenSubdiv); BakeError naming the surface on bad input."""
    try:
        verts, quads, dens = _native().subdivide_mesh(points, nu, nv, level, density, True)
    except ValueError as e:
        raise BakeError(f"Plume: mesh export of '{name}': {e}") from None
    return (np.asarray(verts, dtype=np.float32), np.asarray(quads, dtype=np.int32),
            np.clip(np.asarray(dens, dtype=np.float32), 0.0, 1.0))


def export_mesh(spec, job):
    """Every target surface refined, one after the other."""
    meshes, inputs = [], spec["inputs"]
    for i, args in enumerate(inputs):
        job.check_cancel()
        meshes.append(refine(*args, spec["level"]))
        job.set_progress(i + 1, len(inputs), "surface")
    return meshes


#: kind -> work function; the kind is written into the job file.
KINDS = {"bake": bake, "flames": flames, "toon": toon, "flowgraph": flowgraph,
         "synthesis": synthesis, "surfaces": surfaces, "export_mesh": export_mesh}
