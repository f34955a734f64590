"""plume.toon_build on the active baked domain ([Cartoon Smoke] §2): toon particles from the
bake's volume frames -> toon_####.bin, a point object following them, billboards with a stencil
cut-out material, and the "Plume Depth Differences" compositor outlines. A job (jobs/): every
input is checked on the main thread before anything is written or created, the particles run in
the job's child process into a staging folder, and the files move into place and the objects
are built only when that succeeded, so bad input, a cancel or a crash changes nothing."""

import time

import bpy

from .. import toon
from ..native import _native
from ..build import toon_compositor, toon_nodes, toon_points
from ..jobs.operator import JobOperator
from ..jobs import JobRunner
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of, emitter_snapshots
from ..snapshot.toon import toon_settings
from ..toon_sources import ToonSourceCells
from ..ui_words import ADD_CAMERA
from .bake import cache_setting, domain_key


class ToonJob(JobRunner):
    """Build Toon Smoke as a job: toon.ToonRunner in the child writing toon_####.bin (and the
    generated stencil) into the staging folder; finish() commits and builds."""

    title = "Build Toon Smoke"
    kind = "toon"

    def prepare(self, context):
        self.t0 = time.perf_counter()
        scene = context.scene
        domain = active_domain(context)
        d = domain.plume.domain
        self.domain_name = domain.name
        settings = toon_settings(d)
        toon.validate(settings, domain.name)
        folder = cache_folder_of(domain)
        manifest = toon.toon_manifest(folder, domain.name)
        toon.check_bake(settings, manifest, domain.name)
        if scene.camera is None:
            raise BakeError(f"Plume: scene '{scene.name}' has no camera: the billboards face "
                            f"the scene camera and the outlines need its Depth pass: {ADD_CAMERA}")
        self.objects = (domain.name, scene.camera.name)  # the billboards face the camera
        self.claim(domain_key(domain.name))
        self.lock_folder(folder, cache_setting(domain))
        # The Sources over the bake's frames: their matrices per frame when they move, their
        # keyed Density / Emit Particles per frame (§2.1 emission follows both).
        frame_start, last = int(manifest["frame_start"]), int(manifest["last_complete_frame"])
        emitters = emitter_snapshots(context, domain, frame_start, last)
        ToonSourceCells(_native, toon.toon_grid(manifest), emitters, frame_start).check()
        toon.to_params(_native, settings, domain.name)  # BakeError now, not in the child
        self.emitters, self.manifest = emitters, manifest
        self.folder, self.settings = folder, settings
        self.set_progress(0, last - frame_start + 1, "frame")

    def job_spec(self):
        return {"folder": self.folder, "manifest": self.manifest, "settings": self.settings,
                "domain_name": self.domain_name, "emitters": self.emitters,
                "staging": self.stage(self.folder)}

    def take_result(self, value):
        self.result = value["result"]
        s = self.settings
        self.stencil = (s.stencil_image if s.stencil == 'IMAGE' or value["stencil"] is None
                        else self.staging.final_path(value["stencil"]))

    def finish(self, context):
        domain = bpy.data.objects[self.domain_name]
        folder, result = self.folder, self.result
        self.staging.commit(replaced=[toon.toon_path(folder, f) for f in toon.toon_frames(folder)])
        ob = self._build(context, domain, folder, result, self.stencil, self.settings)
        return 'INFO', (f"Plume: toon smoke '{ob.name}', frames {result.frame_start}-"
                        f"{result.last_frame}, {result.max_count_seen} particles at most "
                        f"({time.perf_counter() - self.t0:.1f} s)")

    def error_text(self, exc):
        if isinstance(exc, (BakeError, OSError)):
            return str(exc)
        return super().error_text(exc)

    def busy_text(self):
        return (f"Plume: domain '{self.domain_name}' is building its toon smoke (Esc cancels): "
                "wait for it")

    @staticmethod
    def _build(context, domain, folder, result, stencil, settings):
        scene, view_layer = context.scene, context.view_layer
        t = domain.plume.domain.toon
        ob = toon_points.build_object(scene, domain, folder, result.frame_start, result.last_frame)
        mat = toon_nodes.toon_material(toon_nodes.material_name(domain), stencil, t)
        toon_nodes.apply_billboards(ob, scene.camera, mat, settings.stretch_factor)
        # Depth only where the stencil is opaque (the material's cut-out is 0 or 1).
        view_layer.pass_alpha_threshold = toon_nodes.ALPHA_THRESHOLD
        # The handler rewrites the points while rendering frames: lock the interface.
        scene.render.use_lock_interface = True
        far = scene.camera.data.clip_end if scene.camera.type == 'CAMERA' else 1.0e9
        toon_compositor.wire_scene(scene, view_layer, t, far)
        toon_compositor.set_freestyle(scene, view_layer, t.use_freestyle, t.outline_color)
        t.object_name = ob.name
        return ob


class PLUME_OT_toon_build(JobOperator, bpy.types.Operator):
    """Build toon smoke (stencil billboards with depth-difference outlines) from the active
    domain's bake"""

    bl_idname = "plume.toon_build"
    bl_label = "Build Toon Smoke"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def make_runner(self, context):
        return ToonJob()


classes = (PLUME_OT_toon_build,)

