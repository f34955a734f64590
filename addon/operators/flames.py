"""plume.flames_bake and plume.flames_free (structural_flames.txt): bake the scene's Flame
Sources into flames_####.vdb + spines_####.npz, then the "Plume Flames" Volume, the "Plume Flame
Spines" curve and the flame lights; plume.flames_bake_spines_keyframes turns the cached spines
into keyed curve objects. execute() bakes blocking (``blender -b``, scripts); invoke()
(UI) runs the bake on a worker thread with a modal timer for progress, Esc cancels (BLENDER_NOTES
§5). Every input is checked before anything is written, so bad input changes nothing."""

import os
import threading
import time

import bpy

from .. import _native, flames
from ..build import flame_spine_keys, flame_spines, flames_volume
from ..flame_snapshot import cache_folder, flames_snapshot
from ..settings import BakeError

#: The bake running in the background (a second one, or a free, must wait).
_running = {}


def _prepare(context, progress=None, cancel=None):
    if _running:
        raise BakeError("Plume: flames are already baking")
    snap = flames_snapshot(context)
    return flames.FlameBakeRunner(_native, snap, progress=progress, cancel=cancel)


def _finish(context, runner, result, t0):
    """Builds the Blender objects over what was baked; the report's text."""
    scene, snap = context.scene, runner.snap
    f = scene.plume_flames
    frames = result.frames
    if frames < 1:
        flames_volume.remove()
        flame_spines.remove(scene)
        f.volume_object = f.spines_object = ""
        f.frames_baked = 0
    else:
        vol = flames_volume.build(scene, snap.folder, snap.frame_start, frames,
                                  float(scene.plume_flames.emission))
        spines = flame_spines.build(scene, snap.folder, snap.frame_start, result.last_frame,
                                    float(f.light_watts))
        f.volume_object, f.spines_object, f.frames_baked = vol.name, spines.name, frames
    seconds = time.perf_counter() - t0
    per_frame = seconds / max(frames, 1)
    f.summary = (f"{frames} frames, up to {max(result.flames, default=0)} flames, "
                 f"{max(result.particles, default=0):,} particles, {per_frame:.2f} s/frame")
    what = "cancelled" if result.cancelled else "baked"
    return (f"Plume: flames {what}: frames {snap.frame_start}-{result.last_frame} "
            f"({f.summary}; steps {result.step_seconds:.2f} s, shape {result.shape_seconds:.2f} s, "
            f"raster+write {result.write_seconds:.2f} s)")


class PLUME_OT_flames_bake(bpy.types.Operator):
    """Bake the structural flames of the scene's Flame Sources (B-spline spines, flicker and
    breakaway, profiles and noise) into a Volume, spine curves and lights (Esc cancels)"""

    bl_idname = "plume.flames_bake"
    bl_label = "Bake Flames"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def execute(self, context):
        t0 = time.perf_counter()
        try:
            runner = _prepare(context)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0, runner.snap.frame_count)
        runner.progress = lambda done, _total: wm.progress_update(done)
        _running["flames"] = runner
        try:
            result = runner.run()
        except (RuntimeError, ValueError, OSError) as e:
            self.report({'ERROR'}, f"Plume: flames bake failed: {e}")
            return {'CANCELLED'}
        finally:
            _running.pop("flames", None)
            wm.progress_end()
        self.report({'INFO'}, _finish(context, runner, result, t0))
        return {'FINISHED'}

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        self._t0 = time.perf_counter()
        self._done, self._cancel = [0], threading.Event()
        self._result, self._error = None, None
        try:
            runner = _prepare(context, progress=lambda done, _t: self._done.__setitem__(0, done),
                              cancel=self._cancel.is_set)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        self._runner = runner
        _running["flames"] = runner
        self._thread = threading.Thread(target=self._work, daemon=True)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, max(1, runner.snap.frame_count))
        wm.modal_handler_add(self)
        self._thread.start()
        return {'RUNNING_MODAL'}

    def _work(self):
        try:
            self._result = self._runner.run()
        except Exception as e:  # reported on the main thread
            self._error = e

    def modal(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            self._cancel.set()
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        wm = context.window_manager
        if self._thread.is_alive():
            wm.progress_update(self._done[0])
            if context.workspace is not None:
                context.workspace.status_text_set(
                    f"Plume: flames frame {self._done[0]} of {self._runner.snap.frame_count} "
                    "(Esc cancels)")
            return {'PASS_THROUGH'}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        _running.pop("flames", None)
        if self._error is not None:
            self.report({'ERROR'}, f"Plume: flames bake failed: {self._error}")
            return {'CANCELLED'}
        text = _finish(context, self._runner, self._result, self._t0)
        self.report({'WARNING'} if self._result.cancelled else {'INFO'}, text)
        return {'FINISHED'}


class PLUME_OT_flames_free(bpy.types.Operator):
    """Delete the flames bake files, the flames Volume, the spine curves and the flame lights"""

    bl_idname = "plume.flames_free"
    bl_label = "Free Flames"
    bl_options = {'REGISTER'}

    def execute(self, context):
        if _running:
            self.report({'ERROR'}, "Plume: flames are baking; cancel the bake first")
            return {'CANCELLED'}
        scene = context.scene
        folder = cache_folder(scene)
        count = 0
        if os.path.isdir(folder):
            before = len(os.listdir(folder))
            flames.clear_folder(folder)
            count = before - len(os.listdir(folder))
        flames_volume.remove()
        flame_spines.remove(scene)
        f = scene.plume_flames
        f.volume_object = f.spines_object = f.summary = ""
        f.frames_baked = 0
        self.report({'INFO'}, f"Plume: flames freed ({count} files deleted)")
        return {'FINISHED'}


class PLUME_OT_flames_bake_spines_keyframes(bpy.types.Operator):
    """Convert the cached spines of the baked frames into one curve object per flame with its
    points keyframed (hidden while the flame does not live): they work without Plume and can be
    re-keyed by hand"""

    bl_idname = "plume.flames_bake_spines_keyframes"
    bl_label = "Bake Spines to Keyframes"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        scene = context.scene
        f = scene.plume_flames
        if _running:
            self.report({'ERROR'}, "Plume: flames are baking; wait for the bake to finish")
            return {'CANCELLED'}
        if f.frames_baked < 1:
            self.report({'ERROR'}, "Plume: no flames are baked (press Bake Flames first)")
            return {'CANCELLED'}
        first = int(f.frame_start)
        try:
            objects, keys = flame_spine_keys.bake(scene, cache_folder(scene), first,
                                                  first + int(f.frames_baked) - 1)
        except (OSError, ValueError) as e:
            self.report({'ERROR'}, f"Plume: the flames cache cannot be read: {e}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Plume: {len(objects)} flame spines keyed ({keys:,} keys) in "
                              f"collection '{flame_spine_keys.COLLECTION_NAME}'")
        return {'FINISHED'}


def is_baking():
    return bool(_running)


classes = (PLUME_OT_flames_bake, PLUME_OT_flames_free, PLUME_OT_flames_bake_spines_keyframes)
