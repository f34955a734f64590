"""plume.bake and plume.cache_free on the active domain.

execute() bakes blocking (``blender -b``, scripts); invoke() (UI) runs the bake runner on a worker
thread with a modal timer for progress, and Esc cancels (BLENDER_NOTES §5)."""

import threading
import time

import bpy

from .. import bake_runner, cache
from .. import _native
from ..build import volume
from ..mantaflow_trace import MantaflowTraceRunner
from ..settings import BakeError
from ..snapshot import NOT_A_DOMAIN, active_domain, cache_folder_of, take_snapshot

#: Domains being baked in the background, by name (a second bake or a free must wait).
_running = {}


def _addon_version():
    from .. import VERSION
    return VERSION


def _prepare(context):
    """Snapshot + validation on the main thread; BakeError on bad input, nothing written."""
    snap = take_snapshot(context, addon_version=_addon_version())
    if snap.domain_name in _running:
        raise BakeError(f"Plume: domain '{snap.domain_name}' is already baking")
    # motion_source 'MANTAFLOW': trace the Mantaflow cache's velocity instead of simulating.
    runner_class = bake_runner.BakeRunner if snap.mantaflow is None else MantaflowTraceRunner
    runner = runner_class(snap, _native)
    runner.prepare()
    return runner


def _finish(context, runner, result):
    """Builds/updates the Volume object from what the cache holds."""
    snap = runner.snapshot
    domain = bpy.data.objects.get(snap.domain_name)
    if domain is None:
        return None
    return volume.build_volume(domain, snap.cache_folder, snap.frame_start, result.frames_done,
                               combustion=snap.solver.combustion,
                               max_temperature=snap.solver.max_temperature)


def _summary(runner, result):
    snap = runner.snapshot
    what = "cancelled" if result.cancelled else "baked"
    resumed = f", resumed at frame {result.resumed_from}" if result.resumed_from else ""
    return (f"Plume: '{snap.domain_name}' {what}: frames {snap.frame_start}-"
            f"{result.last_complete_frame} of {snap.frame_start}-{snap.frame_end} "
            f"({len(result.computed_frames)} computed{resumed}, {result.seconds:.1f} s)")


class _Progress:
    """Shared between the worker thread (writes) and the modal handler (reads)."""

    def __init__(self, total):
        self.total = total
        self.done = 0
        self.seconds_left = 0.0
        self.result = None
        self.error = None
        self.finished = False

    def __call__(self, p):
        self.done, self.seconds_left = p.frames_done, p.seconds_left


class PLUME_OT_bake(bpy.types.Operator):
    """Bake the smoke simulation of the active domain into its cache folder (Esc cancels;
    a later bake with the same settings resumes)"""

    bl_idname = "plume.bake"
    bl_label = "Bake"
    bl_options = {'REGISTER'}

    def execute(self, context):
        try:
            runner = _prepare(context)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        name = runner.snapshot.domain_name
        _running[name] = runner
        try:
            result = runner.run()
        except (BakeError, RuntimeError, ValueError, OSError) as e:
            self.report({'ERROR'}, f"Plume: bake of '{name}' failed: {e}")
            return {'CANCELLED'}
        finally:
            _running.pop(name, None)
        _finish(context, runner, result)
        self.report({'INFO'}, _summary(runner, result))
        return {'FINISHED'}

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        try:
            runner = _prepare(context)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        self._runner = runner
        self._progress = _Progress(runner.snapshot.frame_count)
        runner.progress = self._progress
        _running[runner.snapshot.domain_name] = runner
        self._thread = threading.Thread(target=self._work, daemon=True)
        self._t0 = time.perf_counter()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, max(1, runner.snapshot.frame_count))
        wm.modal_handler_add(self)
        self._thread.start()
        return {'RUNNING_MODAL'}

    def _work(self):
        try:
            self._progress.result = self._runner.run()
        except Exception as e:  # reported on the main thread
            self._progress.error = e
        self._progress.finished = True

    def modal(self, context, event):
        p = self._progress
        if event.type == 'ESC' and event.value == 'PRESS':
            self._runner.cancel()
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        wm = context.window_manager
        if not p.finished:
            wm.progress_update(p.done)
            if context.workspace is not None:
                context.workspace.status_text_set(
                    f"Plume: frame {p.done} of {p.total}, ~{p.seconds_left:.0f} s left (Esc cancels)")
            return {'PASS_THROUGH'}
        self._thread.join()
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        _running.pop(self._runner.snapshot.domain_name, None)
        if p.error is not None:
            self.report({'ERROR'}, f"Plume: bake of '{self._runner.snapshot.domain_name}' "
                                   f"failed: {p.error}")
            return {'CANCELLED'}
        _finish(context, self._runner, p.result)
        self.report({'WARNING'} if p.result.cancelled else {'INFO'}, _summary(self._runner, p.result))
        for area in context.screen.areas if context.screen else ():
            area.tag_redraw()
        return {'FINISHED'}


class PLUME_OT_cache_free(bpy.types.Operator):
    """Delete the bake files of the active domain and its Volume object"""

    bl_idname = "plume.cache_free"
    bl_label = "Free Bake"
    bl_options = {'REGISTER'}

    def execute(self, context):
        try:
            domain = active_domain(context)
        except BakeError:
            self.report({'ERROR'}, NOT_A_DOMAIN)
            return {'CANCELLED'}
        if domain.name in _running:
            self.report({'ERROR'}, f"Plume: domain '{domain.name}' is baking; cancel it first")
            return {'CANCELLED'}
        folder = cache_folder_of(domain)
        count = cache.delete_plume_files(folder)
        volume.remove_volume(domain)
        self.report({'INFO'}, f"Plume: freed '{domain.name}' ({count} files deleted)")
        return {'FINISHED'}


def cache_status(domain):
    """(frames done, frames total) of the domain's cache, read from its manifest."""
    d = domain.plume.domain
    total = max(0, d.frame_end - d.frame_start + 1)
    m = cache.read_manifest(cache_folder_of(domain))
    if m is None or m.get("frame_start") != d.frame_start:
        return 0, total
    done = min(m.get("last_complete_frame", 0), d.frame_end) - d.frame_start + 1
    return max(0, done), total


def is_baking(domain):
    return domain.name in _running


classes = (PLUME_OT_bake, PLUME_OT_cache_free)
