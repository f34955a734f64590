"""The smoke bake loop, no ``bpy``: validation, cache folder, manifest, resume, progress, cancel.

    runner = BakeRunner(snapshot, _native, progress=callback)
    runner.prepare()   # raises BakeError on bad input; writes nothing, changes nothing
    result = runner.run()   # blocking; may run on a worker thread (the native loop drops the GIL)

VDB of frame f = state after advancing (f - frame_start + 1) frames from an empty domain.
"""

import json
import math
import os
import threading
import time
from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

from . import cache, flame_smoke
from .point_sources import domain_point_sources, emits_during

#: A checkpoint of the solver state is written when the time since the last one is at least this
#: many times what writing the last one took (and after the last frame): about every frame on
#: small grids, every ~5 s at 128³ (75 MB in ~0.25 s), never more than ~5% of the bake time
#: (at 10, 128³ bakes spent 10-15% of their time in checkpoints).
CHECKPOINT_COST_RATIO = 20.0
from .native_params import to_native_params, to_native_source
from .settings import (BakeError, validate_pathlines, validate_python_side, validate_source,
                       validate_streaks)


@dataclass
class BakeProgress:
    """What a progress callback receives after each frame."""

    frame: int
    frames_done: int  # frames of the range available (including resumed ones)
    frames_total: int
    seconds_elapsed: float
    seconds_left: float


@dataclass
class BakeResult:
    frame_start: int
    last_complete_frame: int  # frame_start - 1 when nothing is available
    computed_frames: List[int] = field(default_factory=list)
    resumed_from: Optional[int] = None  # first frame computed when a bake was resumed
    cancelled: bool = False
    seconds: float = 0.0

    @property
    def frames_done(self):
        return self.last_complete_frame - self.frame_start + 1


def _normalized(data):
    """JSON round trip, so tuples/lists and ints/floats compare as they are stored."""
    return json.loads(json.dumps(data, sort_keys=True))


def check_input(snap, native):
    """The checks of a bake's input that need no solver (Blender runs them before it starts the
    bake's child); the validated native SmokeParams. BakeError naming the setting."""
    validate_python_side(snap.domain_name, snap.resolution, snap.frame_start,
                         snap.frame_end, snap.solver)
    try:
        params = to_native_params(snap.solver, native)
    except ValueError as e:
        raise BakeError(f"Plume: domain '{snap.domain_name}': {e}") from None
    for emitter in snap.emitters:
        if emitter.role == "SOURCE":
            validate_source(emitter, snap.frame_start)
    validate_streaks(snap.domain_name, snap.streaks, snap.emitters)
    validate_pathlines(snap.domain_name, snap.pathlines, snap.solver, snap.streaks,
                       snap.emitters, snap.frame_count)
    return params


class BakeRunner:
    """One bake of one domain from a BakeSnapshot."""

    def __init__(self, snapshot, native, progress=None):
        self.snapshot = snapshot
        self._native = native
        self.progress = progress
        self._solver = None
        self._cancel = threading.Event()
        self._result = None  # BakeResult of the running run()
        #: frames computed when cancel() was first called (the frame in flight is then dropped)
        self.frames_done_at_cancel = None
        self._mode = None  # 'fresh', 'resume' or 'complete'
        self._resume_last = None
        self._resume_state = None
        self._manifest = None
        self._emitter_inputs = None  # EmitterSnapshot.solver_inputs of the loaded emitters
        self._tracer = None  # StreakTracer when streak surfaces are on
        self._recorder = None  # PathlineRecorder while a bake with pathlines runs
        self._fuel_cells = None  # linear cells of the fuel Sources (pathline seeds, §4.2)
        self._emitting_sources = []  # Sources with point sources (their emit_particles count)
        self._params = None  # the validated native SmokeParams

    # ---------------------------------------------------------------- validation
    def prepare(self):
        """Checks everything that can be wrong with the input and decides between a fresh bake
        and a resume. Raises BakeError; nothing is written."""
        snap = self.snapshot
        params = self._params = check_input(snap, self._native)
        try:
            self._solver = self._native.SmokeSolver(params)
        except ValueError as e:
            raise BakeError(f"Plume: domain '{snap.domain_name}': {e}") from None
        except MemoryError:
            raise BakeError(f"Plume: domain '{snap.domain_name}': resolution "
                            f"{tuple(snap.solver.resolution)} does not fit in memory") from None
        # Voxelize every emitter of the first frame now, so a bad obstacle is reported before
        # any file is written.
        self._load_emitters(0)
        self._load_flame_smoke()
        if snap.streaks.enabled:
            self._tracer = self._make_tracer(params)
        if snap.pathlines.enabled:
            self._fuel_cells = self._fuel_cells_of(params)
        error = cache.check_writable(snap.cache_folder)
        if error is not None:
            raise BakeError(f"Plume: the Cache Directory '{snap.cache_directory}' (Physics "
                            "Properties › Plume › Cache) is not writable "
                            f"({snap.cache_folder}: {error})")
        self._plan()

    def _load_emitters(self, index):
        """Voxelizes the emitters for frame frame_start + index (matrices at index, index+1, source
        settings at index) unless the solver already holds exactly those."""
        inputs = [e.solver_inputs(index) for e in self.snapshot.emitters]
        if inputs == self._emitter_inputs:
            return
        solver, native = self._solver, self._native
        solver.clear_emitters()
        for e in self.snapshot.emitters:
            m0, m1 = e.matrix_at(index), e.matrix_at(index + 1)
            try:
                if e.role == "SOURCE":
                    solver.add_source(e.vertices, e.triangles, m0, m1,
                                      to_native_source(e.source_at(index), native), name=e.name)
                else:
                    slip = getattr(native.Slip, e.slip)
                    solver.add_obstacle(e.vertices, e.triangles, m0, m1, slip, name=e.name)
            except ValueError as err:
                text = str(err)
                if e.name not in text:
                    text = f"{e.role.lower()} '{e.name}': {text}"
                raise BakeError(f"Plume: {text}") from None
        self._emitter_inputs = inputs

    def _load_flame_smoke(self):
        """Flame Smoke ([Structural Flames] §6.3): reads the flames cache over the bake's frames
        and passes every frame's emitters through the solver's validation, so that a missing
        or bad flames bake is reported before any file is written."""
        snap = self.snapshot
        smoke = snap.flame_smoke
        if smoke is None or not smoke.enabled:
            return
        flame_smoke.load_frames(smoke, snap.frame_start, snap.frame_end, snap.solver,
                                snap.domain_name)
        for index in range(snap.frame_count):
            try:
                flame_smoke.set_frame(self._solver, smoke, index)
            except ValueError as e:
                raise BakeError(f"Plume: domain '{snap.domain_name}': {flame_smoke.SETTING} "
                                f"(frame {snap.frame_start + index}): {e}") from None

    def _make_tracer(self, params):
        """StreakTracer with the point sources of every Source ([Smoke Surfaces] §3.2):
        `point_sources` random points per source cell, seeded by the domain seed and the source's
        index, or the vertices of its point_source_mesh; candidate group = the source's
        candidate_group (-1: a group of its own), or candidate_split groups of its own (§3.3)."""
        snap, native = self.snapshot, self._native
        try:
            tracer = native.StreakTracer(params, emission_period=snap.streaks.emission_period)
        except ValueError as e:
            raise BakeError(f"Plume: domain '{snap.domain_name}': {e}") from None
        points, groups, velocities, self._emitting_sources = domain_point_sources(native, params,
                                                                                  snap)
        try:
            tracer.add_point_sources(points, groups, velocities)
        except ValueError as e:
            raise BakeError(f"Plume: domain '{snap.domain_name}': point sources: {e}") from None
        return tracer

    def _fuel_cells_of(self, params):
        """Linear indices of the cells where the Sources with fuel inject it at the first frame:
        the fuel-injection region Ω where pathlines are seeded ([Graph Fire Synthesis] §4.2)."""
        snap, native = self.snapshot, self._native
        cells = []
        for e in snap.emitters:
            if e.role != "SOURCE" or e.source_at(0).fuel <= 0.0:
                continue
            try:
                linear, _motion = native.source_cells(e.vertices, e.triangles, e.matrix_at(0),
                                                      e.matrix_at(1), params, e.name)
            except ValueError as err:
                raise BakeError(f"Plume: source '{e.name}': {err}") from None
            cells.append(np.asarray(linear, dtype=np.uint32))
        merged = np.unique(np.concatenate(cells)) if cells else np.empty(0, np.uint32)
        if len(merged) == 0:
            raise BakeError(f"Plume: domain '{snap.domain_name}': the fuel Sources cover no cell "
                            "of the grid, so no pathline can be seeded: enlarge them or raise "
                            "the resolution")
        return merged

    def _pathline_recorder(self, folder):
        """A PathlineRecorder writing <folder>/pathlines.bin(.partial) for this bake."""
        snap, native = self.snapshot, self._native
        p = snap.pathlines
        try:
            return native.PathlineRecorder(
                native.PathlineParams(nodes_per_frame=p.nodes_per_frame, lifetime=p.lifetime),
                self._params, self._fuel_cells, cache.pathlines_path(folder), float16=p.float16)
        except (ValueError, RuntimeError) as e:
            raise BakeError(f"Plume: domain '{snap.domain_name}': pathlines: {e}") from None

    def _plan(self):
        """Fresh bake, resume from the checkpoint, or nothing to compute (already complete)."""
        snap = self.snapshot
        self._mode = "fresh"
        m = cache.read_manifest(snap.cache_folder)
        if m is None or m.get("frame_start") != snap.frame_start:
            return
        if m.get("addon_version") != snap.addon_version:
            return  # another solver version may not continue this state bit for bit
        if m.get("settings") != _normalized(snap.settings_dict()):
            return
        last = m.get("last_complete_frame")
        if not isinstance(last, int) or last < snap.frame_start:
            return
        upto = min(last, snap.frame_end)
        inputs = m.get("frame_inputs", [])
        expected = [snap.frame_input_hash(f) for f in range(snap.frame_start, upto + 1)]
        if inputs[:len(expected)] != expected:
            return  # emitters moved differently: the stored frames are stale
        present = set(cache.volume_frames(snap.cache_folder))
        if any(f not in present for f in range(snap.frame_start, upto + 1)):
            return
        if snap.streaks.enabled:
            streaks = set(cache.streak_frames(snap.cache_folder))
            if any(f not in streaks for f in range(snap.frame_start, upto + 1)):
                return
        if snap.pathlines.enabled and (last < snap.frame_end or m.get("frame_end") !=
                                       snap.frame_end or not os.path.isfile(
                                           cache.pathlines_path(snap.cache_folder))):
            return  # the recorder's pathlines in flight are not checkpointed: start over
        self._manifest = m
        if last >= snap.frame_end:
            self._mode = "complete"
        else:
            # Checkpoints are written every few seconds, so the state may be some frames behind
            # the last complete frame: resume from it and recompute (bit for bit) what follows.
            # A traced bake needs the tracers' checkpoint of the same frame too.
            state = m.get("state_frame")
            if (isinstance(state, int) and snap.frame_start <= state <= last
                    and any(map(os.path.isfile, cache.state_paths(snap.cache_folder)))
                    and (not snap.streaks.enabled
                         or any(map(os.path.isfile, cache.tracer_state_paths(snap.cache_folder))))):
                self._mode = "resume"
                self._resume_last = last
                self._resume_state = state

    # ---------------------------------------------------------------- the loop
    def cancel(self):
        """Thread-safe: the running frame stops within one step; completed frames stay."""
        if self.frames_done_at_cancel is None and self._result is not None:
            self.frames_done_at_cancel = len(self._result.computed_frames)
        self._cancel.set()
        if self._solver is not None:
            self._solver.cancel()
        if self._tracer is not None:
            self._tracer.cancel()
        if self._recorder is not None:
            self._recorder.cancel()

    @property
    def cancelled(self):
        return self._cancel.is_set()

    def run(self):
        if self._mode is None:
            self.prepare()
        snap = self.snapshot
        folder = snap.cache_folder
        t0 = time.perf_counter()
        result = BakeResult(frame_start=snap.frame_start, last_complete_frame=snap.frame_start - 1)
        self._result = result

        if self._mode == "complete":
            cache.delete_plume_files(folder, frames_above=snap.frame_end)
            m = self._manifest
            m["frame_end"] = snap.frame_end
            m["last_complete_frame"] = snap.frame_end
            m["frame_inputs"] = m.get("frame_inputs", [])[:snap.frame_count]
            m["last_run"] = {"resumed": True, "computed_frames": [], "cancelled": False}
            cache.write_manifest(folder, m)
            result.last_complete_frame = snap.frame_end
            return result

        first = snap.frame_start
        manifest = self._new_manifest()
        if self._mode == "resume" and not self._load_checkpoints(folder):
            self._mode = "fresh"
        if self._mode == "resume":
            first = self._resume_state + 1
            result.resumed_from = first
            result.last_complete_frame = self._resume_last
            manifest.update(last_complete_frame=self._resume_last, state_frame=self._resume_state,
                            frame_inputs=self._manifest.get("frame_inputs", [])[
                                :self._resume_last - snap.frame_start + 1],
                            frames_computed_total=self._manifest.get("frames_computed_total", 0))
        else:
            cache.delete_plume_files(folder)
            cache.check_writable(folder)  # recreates the folder
        manifest["last_run"] = {"resumed": self._mode == "resume", "computed_frames": [],
                                "cancelled": False}
        cache.write_manifest(folder, manifest)

        last_checkpoint, checkpoint_cost = time.perf_counter(), 0.0
        if snap.pathlines.enabled:
            self._recorder = self._pathline_recorder(folder)
        try:
            for frame in range(first, snap.frame_end + 1):
                if self._cancel.is_set():
                    result.cancelled = True
                    break
                self._load_emitters(frame - snap.frame_start)
                flame_smoke.set_frame(self._solver, snap.flame_smoke, frame - snap.frame_start)
                tracer = self._tracer
                if self._recorder is not None:
                    ok = self._recorder.advance_frame(self._solver)
                elif tracer is None:
                    ok = self._solver.advance_frame()
                else:
                    tracer.emitting = emits_during(self._emitting_sources,
                                                   frame - snap.frame_start)
                    ok = self._native.advance_frame_with_tracers(self._solver, tracer)
                if not ok:
                    result.cancelled = True
                    break
                self._solver.write_vdb(cache.volume_path(folder, frame),
                                       velocity_everywhere=snap.velocity_everywhere)
                if tracer is not None:  # atomic (tmp + rename) like the VDB
                    self._native.write_streak_file(cache.streak_path(folder, frame),
                                                   tracer.snapshot())
                # The checkpoint holds every grid (75 MB at 128³), so it is not written every frame.
                # The tracers' checkpoint goes with it, for the same frame: both or neither.
                now = time.perf_counter()
                if (frame == snap.frame_end
                        or now - last_checkpoint >= CHECKPOINT_COST_RATIO * checkpoint_cost):
                    cache.keep_previous_checkpoint(folder)
                    self._solver.save_state(cache.state_path(folder))
                    if tracer is not None:
                        tracer.save_state(cache.tracer_state_path(folder), frame)
                    manifest["state_frame"] = frame
                    last_checkpoint = time.perf_counter()
                    checkpoint_cost = last_checkpoint - now
                if frame - snap.frame_start >= len(manifest["frame_inputs"]):
                    manifest["frame_inputs"].append(snap.frame_input_hash(frame))
                # The manifest is fsynced with each checkpoint (and at the end), not after every
                # frame: two fsyncs a frame were 13 ms of a 64³ frame's ~50.
                self._frame_done(folder, manifest, result, frame, t0,
                                 durable=manifest["state_frame"] == frame)
            if self._recorder is not None and not result.cancelled:
                self._recorder.finish()  # pathlines.bin appears complete, with the last frame
        finally:
            if self._recorder is not None and not os.path.isfile(cache.pathlines_path(folder)):
                self._recorder.discard()  # cancelled or failed: no partial pathline file
            if self.frames_done_at_cancel is not None:
                manifest["last_run"]["frames_done_at_cancel"] = self.frames_done_at_cancel
            self._run_done(folder, manifest, result, t0)
        return result

    def _frame_done(self, folder, manifest, result, frame, t0, durable=True):
        """Frame `frame` is in the cache: the result, the manifest (written; fsynced when
        `durable`) and progress say so."""
        result.last_complete_frame = max(result.last_complete_frame, frame)
        result.computed_frames.append(frame)
        manifest["last_complete_frame"] = result.last_complete_frame
        manifest["frames_computed_total"] += 1
        manifest["last_run"]["computed_frames"].append(frame)
        cache.write_manifest(folder, manifest, durable)
        self._report(result, t0)

    @staticmethod
    def _run_done(folder, manifest, result, t0):
        """End of a run, a failed one too: the manifest says how it ended."""
        manifest["last_run"]["cancelled"] = result.cancelled
        manifest["last_run"]["seconds"] = time.perf_counter() - t0
        try:
            cache.write_manifest(folder, manifest)
        except OSError:
            pass
        result.seconds = time.perf_counter() - t0

    def _load_checkpoints(self, folder):
        """Loads the checkpoints of frame state_frame (the solver's, and the tracers' in a traced
        bake), each from state.bin or, when a bake was killed between writing a checkpoint and
        the manifest naming it, from the previous one (state.prev.bin), which then becomes the
        current one again. False when none is of that frame (missing or corrupt); the solver and
        tracer are then rebuilt as prepare() made them, so that the bake can start over."""
        expected = self._resume_state - self.snapshot.frame_start + 1  # frames advanced
        ok = self._load_one(cache.state_paths(folder),
                            lambda path: self._solver.load_state(path) is None
                            and self._solver.frame == expected)
        if ok and self._tracer is not None:
            ok = self._load_one(cache.tracer_state_paths(folder),
                                lambda path: self._tracer.load_state(path) == self._resume_state)
        if not ok:
            self._solver = self._native.SmokeSolver(self._params)
            self._emitter_inputs = None
            self._load_emitters(0)
            if self._tracer is not None:
                self._tracer = self._make_tracer(self._params)
        return ok

    @staticmethod
    def _load_one(paths, load):
        """The first of `paths` (newest first) that `load` accepts; an older one accepted is renamed
        to the newest's name (the newer is of a frame the manifest never named)."""
        for path in paths:
            try:
                if os.path.isfile(path) and load(path):
                    if path != paths[0]:
                        os.replace(path, paths[0])
                    return True
            except RuntimeError:
                continue
        return False

    def _new_manifest(self):
        snap = self.snapshot
        s = snap.solver
        return {
            "format_version": cache.FORMAT_VERSION,
            "addon_version": snap.addon_version,
            "kind": cache.KIND,
            "domain": snap.domain_name,
            "settings": _normalized(snap.settings_dict()),
            "frame_start": snap.frame_start,
            "frame_end": snap.frame_end,
            "resolution": list(s.resolution),
            "cell_size": s.cell_size,
            "origin": list(s.origin),
            "combustion": s.combustion,
            "streaks": snap.streaks.enabled,
            "emission_period": snap.streaks.emission_period,
            "last_complete_frame": snap.frame_start - 1,
            "state_frame": None,
            "frame_inputs": [],
            "frames_computed_total": 0,
        }

    def _report(self, result, t0):
        if self.progress is None:
            return
        snap = self.snapshot
        elapsed = time.perf_counter() - t0
        computed = len(result.computed_frames)
        left_frames = snap.frame_end - result.last_complete_frame
        per_frame = elapsed / computed if computed else 0.0
        self.progress(BakeProgress(
            frame=result.last_complete_frame,
            frames_done=result.frames_done,
            frames_total=snap.frame_count,
            seconds_elapsed=elapsed,
            seconds_left=per_frame * left_frames if math.isfinite(per_frame) else 0.0))
