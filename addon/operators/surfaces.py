"""plume.surfaces_build on the active baked domain ([Smoke Surfaces] §3.3-3.4): streak files ->
h per candidate group -> clusters (h0) -> greedy order -> one SURFACE object per cluster with
per-frame control points and a density-map material. A job (jobs/): the settings are checked on
the main thread, everything is computed in the job's child process (no bpy) into a staging
folder, the density-map images are saved in short main-thread steps, and only then are the
files moved into place and the objects built, so bad input, a cancel or a crash changes
nothing."""

import time

import bpy
import numpy as np

from .. import cache
from ..native import _native
from .. import streak_surfaces as ss
from .. import sheet_render, surfaces_forecast
from ..build import surfaces as build
from ..jobs.operator import JobOperator
from ..jobs import Forecast, JobRunner
from .. import setting_paths
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of
from ..snapshot.streaks import sheet_settings
from .bake import cache_setting, domain_key

#: h per candidate group, cached in memory for the panel's live count (never computed in draw):
#: domain name -> (key of the cache state, {group: GroupDistances})
_distances = {}


def _cache_key(folder, manifest):
    run = manifest.get("last_run", {})
    return (folder, manifest.get("last_complete_frame"), manifest.get("frames_computed_total"),
            run.get("seconds"))


def cached_distances(domain, manifest=None):
    """The h matrices of the domain's last computation if they match its cache (its manifest:
    `manifest` when given, else read from the disk), else None."""
    hit = _distances.get(domain.name)
    if hit is None:
        return None
    folder = cache_folder_of(domain)
    m = manifest if manifest is not None else cache.read_manifest(folder)
    if m is None or _cache_key(folder, m) != hit[0]:
        return None
    return hit[1]


def live_summary(domain, manifest=None):
    """(surfaces, streaklines) for the domain's current h0 from cached h, or None (`manifest` as
    in cached_distances)."""
    groups = cached_distances(domain, manifest)
    h0 = domain.plume.domain.streak_threshold
    if groups is None or not np.isfinite(h0) or h0 < 0:
        return None
    try:
        return ss.summary(_native, groups, h0)
    except ValueError:
        return None


def compute_distances(domain):
    """Reads the streak files and computes h per group (BakeError on bad input); cached."""
    folder = cache_folder_of(domain)
    m = ss.streak_manifest(folder, domain.name)
    frame_start, last = int(m["frame_start"]), int(m["last_complete_frame"])
    frames = ss.load_frames(_native, folder, frame_start, last)
    groups = ss.group_distances(_native, frames)
    _distances[domain.name] = (_cache_key(folder, m), groups)
    return folder, m, frames, groups


class SurfacesJob(JobRunner):
    """Build Surfaces as a job: prepare() checks the settings and the bake's manifest, the
    child computes h, the clusters, the NURBS animations and the density maps and stages the
    control-point files (jobs/kinds.py), main_steps() saves the density maps (bpy images) into
    the staging folder, finish() commits and builds the objects."""

    title = "Build Surfaces"
    kind = "surfaces"
    prepare_errors = (BakeError, ValueError, RuntimeError)

    def forecast(self, context):
        domain = active_domain(context)
        folder = cache_folder_of(domain)
        m = cache.read_manifest(folder)
        if m is None or not m.get("streaks"):
            return None
        size = surfaces_forecast.shot_size(_native, folder, m)
        if size is None:
            return None
        lines, particles, frames = size
        return Forecast(surfaces_forecast.seconds(lines, particles, frames),
                        f"{lines:,} streaklines x {frames} frames")

    def shorter_hint(self):
        return ("Fewer streaklines (Max Streaklines, then bake again) or a lower",
                "Threshold (h0) make it shorter.")

    def prepare(self, context):
        self.t0 = time.perf_counter()
        domain = active_domain(context)
        d = domain.plume.domain
        self.domain_name = domain.name
        self.settings = sheet_settings(d)
        ss.check_threshold(d.streak_threshold, domain.name)
        self.h0 = d.streak_threshold
        self.folder = cache_folder_of(domain)
        self.objects = (domain.name,)
        self.claim(domain_key(domain.name))
        self.lock_folder(self.folder, cache_setting(domain))
        self.manifest = ss.streak_manifest(self.folder, domain.name)
        size = surfaces_forecast.shot_size(_native, self.folder, self.manifest)
        if size is not None:
            surfaces_forecast.check_memory(domain.name, *size)
        self.set_progress(0, 0, "reading the streak files")

    def job_spec(self):
        return {"folder": self.folder, "manifest": self.manifest, "h0": self.h0,
                "settings": self.settings, "staging": self.stage(self.folder)}

    def take_result(self, value):
        self.result = value
        self.frame_start, self.lines = value["frame_start"], value["lines"]
        self.anims, self.maps = value["anims"], value["maps"]
        # The panel's live count as h0 changes (never computed in draw()).
        _distances[self.domain_name] = (_cache_key(self.folder, self.manifest), value["distances"])

    def main_steps(self, context):
        """Saves the density maps as EXR files into the staging folder with Blender's image
        writer (so on the main thread), one image per step."""
        self.sheets = []
        total = sum(len(images) for images in self.maps)
        done = 0
        for i, images in enumerate(self.maps):
            for n, image in enumerate(images):
                self.set_progress(done, total, "density map image")
                yield
                build.write_sheet_images(self.staging.path, i, self.frame_start + n, [image])
                done += 1
            self.sheets.append((cache.sheet_path(self.folder, i, self.frame_start),
                                images[0].shape[1], images[0].shape[0], len(images)))

    def finish(self, context):
        domain = bpy.data.objects[self.domain_name]
        self.staging.commit(replaced=cache.surface_files(self.folder))
        objs = build.build_surfaces(context, domain, self.folder, self.frame_start, self.anims,
                                    self.sheets, self.settings)
        return 'INFO', (f"Plume: {len(objs)} surfaces from {self.lines} streaklines "
                        f"({time.perf_counter() - self.t0:.1f} s)")

    def refusal_text(self, exc):
        return self.error_text(exc)

    def error_text(self, exc):  # the settings named as their panel shows them
        if isinstance(exc, BakeError):
            return setting_paths.in_ui_words(str(exc))
        return f"Plume: surfaces of '{self.domain_name}': {exc}"

    def busy_text(self):
        return (f"Plume: domain '{self.domain_name}' is building its surfaces (Esc cancels): "
                "wait for it")


class PLUME_OT_surfaces_build(JobOperator, bpy.types.Operator):
    """Build streak surfaces (NURBS smoke sheets) from the active domain's streak bake"""

    bl_idname = "plume.surfaces_build"
    bl_label = "Build Surfaces"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def make_runner(self, context):
        return SurfacesJob()


class PLUME_OT_surfaces_pick_threshold(bpy.types.Operator):
    """Set h0 to the threshold giving the most surfaces (the peak of the paper's Figure 4 curve)"""

    bl_idname = "plume.surfaces_pick_threshold"
    bl_label = "Most Surfaces"
    bl_options = {'REGISTER', 'UNDO'}  # changes one property, nothing on disk

    def execute(self, context):
        try:
            domain = active_domain(context)
            _folder, _m, _frames, groups = compute_distances(domain)
            h0 = ss.most_surfaces_threshold(_native, groups)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        domain.plume.domain.streak_threshold = h0
        h0 = domain.plume.domain.streak_threshold  # as stored (float32; the pick is one)
        surfaces, lines = ss.summary(_native, groups, h0)
        self.report({'INFO'}, f"Plume: Threshold (h0) {h0:.4g} gives {surfaces} surfaces from "
                              f"{lines} streaklines")
        return {'FINISHED'}


class PLUME_OT_surfaces_fast_render(bpy.types.Operator):
    """Set the scene to a fast Cycles set-up for streak sheets: their material shades itself
    (emission and transparency by p, §3.4), so 16 samples and no light bounces, only transparent
    ones, give the same picture (other objects lose indirect light)"""

    bl_idname = "plume.surfaces_fast_render"
    bl_label = "Fast Sheet Render"
    bl_options = {'REGISTER', 'UNDO'}  # render settings only

    samples: bpy.props.IntProperty(
        name="Samples", default=sheet_render.FAST_SAMPLES, min=1, soft_max=256,
        description="Samples per pixel: the sheets need a few for their edges; lit objects seen "
                    "through them (a collider) need more against light-sampling noise")

    def execute(self, context):
        sheet_render.apply_fast_cycles(context.scene, samples=self.samples)
        self.report({'INFO'}, "Plume: " + sheet_render.describe(context.scene))
        return {'FINISHED'}


classes = (PLUME_OT_surfaces_build, PLUME_OT_surfaces_pick_threshold,
           PLUME_OT_surfaces_fast_render)
