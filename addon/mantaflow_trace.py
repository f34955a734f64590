"""A streak bake driven by a Blender Mantaflow cache instead of the Plume solver
([Smoke Surfaces] §3.2: particles "advected by the velocity field"), no ``bpy``.

    runner = MantaflowTraceRunner(snapshot, _native)   # snapshot.mantaflow is set
    runner.prepare()   # raises BakeError on bad input; writes nothing, changes nothing
    result = runner.run()   # blocking; may run on a worker thread (native calls drop the GIL)

Same interface and cache files as bake_runner.BakeRunner, so Build Surfaces, the density maps
and Build Toon Smoke work unchanged: streaks_####.bin (world positions; with streak surfaces
on), volume_####.vdb (the Mantaflow density and cell-centred velocity, placed in world space) and
manifest.json with "motion_source": "mantaflow". Frame f of the cache = the tracers after the
frames frame_start..f, the particles born at the start of frame_start from still point sources in
the Plume Source objects' cells. The velocity between two cached frames is linear in time (see
native/tracers/mantaflow_driver.h). A trace is cheap, so it always starts over (no resume).
Emission pauses on the frames where no Source with point sources has emit_particles on (Figure 10),
as in a Plume bake; the Sources' smoke settings are unused (the Mantaflow density is traced).
"""

import dataclasses
import time

import numpy as np

from . import cache
from .bake_runner import BakeResult, BakeRunner
from .mantaflow_cache import TIME_UNITS_PER_SECOND, check_source
from .point_sources import domain_point_sources, emits_during
from .native_params import to_native_params
from .settings import BakeError, validate_python_side, validate_streaks


def voxel_settings(solver, plan):
    """Solver settings whose cubic grid voxelizes the Sources on the Mantaflow grid: cells of the
    Mantaflow cell size along its longest side, from its origin, as many as fit inside its box
    on each axis (Mantaflow's own cells are not cubic; the last partial cell of a shorter axis
    holds no point sources)."""
    size = np.asarray(plan.resolution, np.float64) * np.asarray(plan.cell_size, np.float64)
    h = float(plan.cell_size[int(np.argmax(size))])
    cells = tuple(max(2, int(np.floor(s / h + 1e-4))) for s in size)
    return dataclasses.replace(solver, resolution=cells, cell_size=h, origin=plan.origin,
                               combustion=False)


class MantaflowTraceRunner(BakeRunner):
    """One streak bake of a Plume domain through the frames of a Mantaflow cache. BakeRunner's
    interface, cancel, progress and manifest bookkeeping; its own prepare() and run()."""

    def __init__(self, snapshot, native, progress=None):
        # Nothing burns: the Volume object gets the smoke material whatever the domain says.
        super().__init__(dataclasses.replace(
            snapshot, solver=dataclasses.replace(snapshot.solver, combustion=False)),
            native, progress)
        self._frames = None  # mantaflow_cache.MantaflowPlan: the grid and files to read
        self._grid = None
        self._start = None  # fields at the start of frame_start
        self._first = None  # fields at the end of frame_start
        self._tracer = None  # native.MantaflowTracer; None with streak surfaces off

    # ---------------------------------------------------------------- validation
    def prepare(self):
        """Checks the settings, the Mantaflow domain and its cache, places the point sources and
        reads the first frames, so that bad input is reported before anything is written."""
        snap, native = self.snapshot, self._native
        owner = f"Plume: domain '{snap.domain_name}'"
        validate_python_side(snap.domain_name, snap.resolution, snap.frame_start, snap.frame_end,
                             snap.solver)
        validate_streaks(snap.domain_name, snap.streaks, snap.emitters)
        plan = check_source(snap.mantaflow, snap.frame_start, snap.frame_end)
        try:
            self._grid = native.MantaflowGrid(plan.resolution, plan.origin, plan.cell_size,
                                              TIME_UNITS_PER_SECOND)
        except ValueError as e:
            raise BakeError(f"{owner}: {e}") from None
        if snap.streaks.enabled:  # without streaks: the frames only, for the toon smoke
            self._prepare_tracer(plan, owner)
        self._frames = plan
        self._start = (self._read(plan.start_file) if plan.start_file
                       else native.MantaflowFrame.empty(plan.resolution))
        self._first = self._read(plan.files[0])
        error = cache.check_writable(snap.cache_folder)
        if error is not None:
            raise BakeError(f"Plume: the Cache Directory '{snap.cache_directory}' (Physics "
                            "Properties › Plume › Cache) is not writable "
                            f"({snap.cache_folder}: {error})")

    def _prepare_tracer(self, plan, owner):
        """The streak tracer on the Mantaflow grid with the Sources' point sources."""
        snap, native = self.snapshot, self._native
        closed = [native.Boundary.CLOSED if c else native.Boundary.OPEN
                  for c in snap.mantaflow.borders_closed]
        try:
            self._tracer = native.MantaflowTracer(
                self._grid, emission_period=snap.streaks.emission_period,
                interpolation=getattr(native.Interpolation, snap.solver.interpolation),
                boundaries=closed)
            params = to_native_params(voxel_settings(snap.solver, plan), native)
        except ValueError as e:
            raise BakeError(f"{owner}: {e}") from None
        points, groups, _velocities, self._emitting_sources = domain_point_sources(native, params,
                                                                                   snap)
        try:
            # Still sources: the Mantaflow flow, not the Plume source's velocity, moves them.
            self._tracer.add_point_sources(points, groups)
        except ValueError as e:
            raise BakeError(f"{owner}: point sources: {e}") from None

    def _read(self, path):
        try:
            return self._native.read_mantaflow_frame(path, self._grid)
        except RuntimeError as e:
            raise BakeError(f"Plume: {e}") from None

    # ---------------------------------------------------------------- the loop
    def run(self):
        if self._frames is None:
            self.prepare()
        snap, native, plan = self.snapshot, self._native, self._frames
        folder = snap.cache_folder
        t0 = time.perf_counter()
        result = BakeResult(frame_start=snap.frame_start, last_complete_frame=snap.frame_start - 1)
        cache.delete_plume_files(folder)
        cache.check_writable(folder)  # recreates the folder
        manifest = self._new_manifest()
        cache.write_manifest(folder, manifest)
        previous = self._start
        try:
            for n, frame in enumerate(range(snap.frame_start, snap.frame_end + 1)):
                if self._cancel.is_set():
                    result.cancelled = True
                    break
                fields = self._first if n == 0 else self._read(plan.files[n])
                if self._tracer is not None:
                    self._tracer.emitting = emits_during(self._emitting_sources, n)  # Figure 10
                    if self._tracer.advance_frame(previous, fields, plan.frame_dts[n]) == 0:
                        result.cancelled = True
                        break
                native.write_mantaflow_volume(cache.volume_path(folder, frame), fields,
                                              self._grid, frame)
                if self._tracer is not None:
                    self._tracer.write_snapshot(cache.streak_path(folder, frame))
                previous = fields
                self._frame_done(folder, manifest, result, frame, t0)
        finally:
            self._run_done(folder, manifest, result, t0)
        return result

    def _new_manifest(self):
        """BakeRunner's manifest on the Mantaflow grid: "cell_size" is the cell along the grid's
        longest side (density maps take one size), "cell_size_xyz" the exact cell per axis."""
        snap, plan = self.snapshot, self._frames
        m = super()._new_manifest()
        # Never equal to a Plume simulation's settings, so plume.bake with motion_source PLUME
        # does not take this cache for its own.
        m["settings"]["motion_source"] = {"mantaflow": snap.mantaflow.fingerprint()}
        longest = int(np.argmax(np.asarray(plan.resolution) * np.asarray(plan.cell_size)))
        m.update(motion_source="mantaflow", mantaflow_domain=snap.mantaflow.object_name,
                 resolution=list(plan.resolution), cell_size=float(plan.cell_size[longest]),
                 cell_size_xyz=list(plan.cell_size), origin=list(plan.origin),
                 streaks=snap.streaks.enabled,
                 last_run={"resumed": False, "computed_frames": [], "cancelled": False})
        return m
