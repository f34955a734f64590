"""plume.toon_build on the active baked domain (cartoon_smoke.txt §2): toon particles from the
bake's volume frames -> toon_####.bin, a point object following them, billboards with a stencil
cut-out material, and the "Plume Depth Differences" compositor outlines. Every input is checked
before anything is written or created, so bad input changes nothing."""

import time

import bpy

from .. import _native, toon
from ..build import toon_compositor, toon_nodes, toon_points
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of, emitter_snapshots
from ..toon_stencils import write_stencil


def toon_settings(d):
    """toon.ToonSettings of a domain's obj.plume.domain.toon (image path made absolute)."""
    t = d.toon
    s = toon.ToonSettings()
    for name in toon.PARAM_FIELDS + ('depth_threshold', 'stencil', 'ignore_background'):
        if name != 'threads':
            setattr(s, name, type(getattr(s, name))(getattr(t, name)))
    s.threads = int(d.threads)  # the domain's worker threads (results do not depend on it)
    s.stencil_image = bpy.path.abspath(t.stencil_image) if t.stencil_image else ""
    return s


class PLUME_OT_toon_build(bpy.types.Operator):
    """Build toon smoke (stencil billboards with depth-difference outlines) from the active
    domain's bake"""

    bl_idname = "plume.toon_build"
    bl_label = "Build Toon Smoke"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def execute(self, context):
        t0 = time.perf_counter()
        scene = context.scene
        try:
            domain = active_domain(context)
            d = domain.plume.domain
            settings = toon_settings(d)
            toon.validate(settings, domain.name)
            folder = cache_folder_of(domain)
            manifest = toon.toon_manifest(folder, domain.name)
            toon.check_bake(settings, manifest, domain.name)
            if scene.camera is None:
                raise BakeError(f"Plume: scene '{scene.name}' has no camera: the billboards face "
                                "the scene camera and the outlines need its Depth pass; set "
                                "scene.camera")
            frame_start = int(manifest["frame_start"])
            emitters = emitter_snapshots(context, domain, frame_start, frame_start)
            runner = toon.ToonRunner(_native, folder, manifest, settings, domain.name,
                                     progress=self._progress(context),
                                     source_cells=toon.source_cells(
                                         _native, toon.toon_grid(manifest), emitters))
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        # Checked: now the files, then the scene.
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            result = runner.run()
            stencil = (settings.stencil_image if settings.stencil == 'IMAGE'
                       else write_stencil(folder, settings.stencil))
        except (BakeError, OSError) as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        finally:
            wm.progress_end()
        ob = self._build(context, domain, folder, result, stencil, settings)
        self.report({'INFO'}, f"Plume: toon smoke '{ob.name}', frames {result.frame_start}-"
                              f"{result.last_frame}, {result.max_count_seen} particles at most "
                              f"({time.perf_counter() - t0:.1f} s)")
        return {'FINISHED'}

    @staticmethod
    def _progress(context):
        wm = context.window_manager

        def progress(done, total):
            wm.progress_update(int(100 * done / max(total, 1)))
        return progress

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


classes = (PLUME_OT_toon_build,)

