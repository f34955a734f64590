"""plume.flames_bake and plume.flames_free ([Structural Flames]): bake the scene's Flame
Sources into flames_####.vdb + spines_####.npz, then the "Plume Flames" Volume, the "Plume Flame
Spines" curve and the flame lights; plume.flames_bake_spines_keyframes turns the cached spines
into keyed curve objects. plume.flames_bake is a job (jobs/): the frames are computed in a
child process, waited for in execute() (``blender -b``, scripts), in the background with
status-bar progress and Esc from a button. Every input is checked before anything is written,
so bad input changes nothing; a cancelled bake keeps and builds the frames it finished."""

import os
import time

import bpy

from .. import flames
from ..build import flame_spine_keys, flame_spines, flames_volume
from ..snapshot import flames_cache_folder
from ..snapshot.flames import flames_snapshot
from ..jobs.operator import JobOperator
from ..jobs import JobRunner, folder_lock, registry
from ..settings import BakeError
from ..ui_words import FLAMES, in_ui_words, ui

#: The registry key of the scene's flames bake (one at a time).
FLAMES_KEY = ("flames",)


class FlamesJob(JobRunner):
    """flames.FlameBakeRunner as a job (its child validates every keyed value before it writes
    anything); the Flame Sources are the objects it works on."""

    title = "Bake Flames"
    kind = "flames"
    keeps_partial = True
    kept_text = "the frames it finished are kept (the next Bake Flames starts over)"

    def prepare(self, context):
        self.t0 = time.perf_counter()
        self.claim(FLAMES_KEY)
        snap = flames_snapshot(context)
        flames.validate_snapshot(snap)
        self.lock_folder(snap.folder, "the flames' cache folder "
                                      f"'{context.scene.plume_flames.cache_directory}' "
                                      f"({ui('flames', 'cache_directory')})")
        self.objects = tuple(dict.fromkeys(src.name for src in snap.sources))
        self.snap, self.folder = snap, snap.folder
        self.set_progress(0, snap.frame_count, "frame")

    def job_spec(self):
        return {"snapshot": self.snap}

    def tidy_partial(self, folder):
        m = flames.read_manifest(folder)
        if m is not None and isinstance(m.get("last_complete_frame"), int):
            flames.remove_frames_above(folder, m["last_complete_frame"])

    def finish(self, context):
        """Builds the Blender objects over what was baked; the report."""
        scene, snap, result = context.scene, self.snap, self.result
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
            # The light unit the frames were baked with (the emission grids hold E x it), not
            # the panel's: a change during the bake applies to the next bake. Flame Brightness
            # and Flame Lights only shape the built objects: read now, as the panel shows them.
            spines = flame_spines.build(scene, snap.folder, snap.frame_start, result.last_frame,
                                        float(snap.settings[0].light_unit), bool(f.lights))
            f.volume_object, f.spines_object, f.frames_baked = vol.name, spines.name, frames
        seconds = time.perf_counter() - self.t0
        per_frame = seconds / max(frames, 1)
        f.summary = (f"{frames} frames, up to {max(result.flames, default=0)} flames, "
                     f"{max(result.particles, default=0):,} particles, {per_frame:.2f} s/frame")
        what = "cancelled" if result.cancelled else "baked"
        text = (f"Plume: flames {what}: frames {snap.frame_start}-{result.last_frame} "
                f"({f.summary}; steps {result.step_seconds:.2f} s, shape "
                f"{result.shape_seconds:.2f} s, raster+write {result.write_seconds:.2f} s)")
        return ('WARNING' if result.cancelled else 'INFO'), text

    def error_text(self, exc):
        if isinstance(exc, BakeError):  # names the setting and what to do already
            return str(exc)
        return f"Plume: flames bake failed: {in_ui_words('flames', str(exc))}"

    def busy_text(self):
        return "Plume: flames are already baking"


class PLUME_OT_flames_bake(JobOperator, bpy.types.Operator):
    """Bake the structural flames of the scene's Flame Sources (B-spline spines, flicker and
    breakaway, profiles and noise) into a Volume, spine curves and lights (Esc cancels)"""

    bl_idname = "plume.flames_bake"
    bl_label = "Bake Flames"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def make_runner(self, context):
        return FlamesJob()


class PLUME_OT_flames_free(bpy.types.Operator):
    """Delete the flames bake files, the flames Volume, the spine curves and the flame lights"""

    bl_idname = "plume.flames_free"
    bl_label = "Free Flames"
    bl_options = {'REGISTER'}

    def execute(self, context):
        if is_baking():
            self.report({'ERROR'}, "Plume: flames are baking; cancel the bake first")
            return {'CANCELLED'}
        scene = context.scene
        folder = flames_cache_folder(scene)
        count = 0
        if os.path.isdir(folder):
            try:
                with folder_lock.holding(folder, "Free Flames"):  # not while another Blender bakes
                    before = len(os.listdir(folder))
                    flames.clear_folder(folder)
                    count = before - len(os.listdir(folder))
            except BakeError as e:
                self.report({'ERROR'}, str(e))
                return {'CANCELLED'}
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
        if is_baking():
            self.report({'ERROR'}, "Plume: flames are baking; wait for the bake to finish")
            return {'CANCELLED'}
        if f.frames_baked < 1:
            self.report({'ERROR'}, "Plume: no flames are baked: press Bake Flames first "
                                   f"({FLAMES})")
            return {'CANCELLED'}
        first = int(f.frame_start)
        try:
            objects, keys = flame_spine_keys.bake(scene, flames_cache_folder(scene), first,
                                                  first + int(f.frames_baked) - 1)
        except (OSError, ValueError) as e:
            self.report({'ERROR'}, "Plume: the flames' cache folder "
                                   f"({ui('flames', 'cache_directory')}) cannot be read: {e}; "
                                   "bake the flames again")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Plume: {len(objects)} flame spines keyed ({keys:,} keys) in "
                              f"collection '{flame_spine_keys.COLLECTION_NAME}'")
        return {'FINISHED'}


def is_baking():
    """True while the flames bake runs in the background."""
    return registry.busy(FLAMES_KEY)


classes = (PLUME_OT_flames_bake, PLUME_OT_flames_free, PLUME_OT_flames_bake_spines_keyframes)
