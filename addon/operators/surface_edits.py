"""Operators on built streak surfaces: store / clear hand edits ([Smoke Surfaces] §5, Figure 13),
bake to keyframes, export as an OpenSubdiv mesh. They act on the active Plume surface (plus the
selected ones), or, with the domain active (the panel's buttons), on all of its surfaces. Export
Mesh is a job (jobs/): the surfaces are read on the main thread, refined in the job's child process,
and the meshes are built only when every surface succeeded."""

import os

import bpy

from ..build import surface_edits as edits
from ..build import surface_mesh
from ..build.surfaces import CACHE_KEY, DOMAIN_KEY, cache_of
from ..jobs.operator import JobOperator
from ..jobs import JobRunner
from ..settings import BakeError


def surface_targets(context, allow_baked=False):
    """[(object, frame_start, control points)] to act on; BakeError saying what is wrong."""
    ob = context.active_object
    if ob is None:
        raise BakeError("Plume: no active object: select a Plume streak surface (made by "
                        "Build Surfaces) or its domain")
    if CACHE_KEY in ob:
        obs = [ob] + [o for o in context.selected_objects if o is not ob and CACHE_KEY in o]
    elif ob.type == 'MESH' and ob.plume.role == 'DOMAIN':
        obs = [o for o in bpy.data.objects if o.get(DOMAIN_KEY) == ob.name and CACHE_KEY in o]
        if not obs:
            raise BakeError(f"Plume: domain '{ob.name}' has no streak surfaces: build them first "
                            "(Physics Properties › Plume › Streak Surfaces › Build Surfaces)")
    else:
        raise BakeError(f"Plume: '{ob.name}' is not a Plume streak surface: select a surface made "
                        "by Build Surfaces, or its domain")
    out = []
    for o in obs:
        if o.get(edits.BAKED_KEY) and not allow_baked:
            raise BakeError(f"Plume: surface '{o.name}' is baked to keyframes already: edit its "
                            "keyframes, or build the surfaces again")
        hit = cache_of(o)
        if hit is None:
            raise BakeError(f"Plume: the control-point cache of surface '{o.name}' "
                            f"({o.get(CACHE_KEY)}) is missing or does not match its control net "
                            "(points added or deleted): build the surfaces again")
        out.append((o, hit[0], hit[1]))
    return out


def frame_index(context, frame_start, cps):
    return min(max(context.scene.frame_current - frame_start, 0), len(cps) - 1)


def load_edit_mode(ob):
    """Edit-mode moves live in the edit data until loaded into the curve."""
    if ob.mode == 'EDIT':
        ob.update_from_editmode()


class PlumeSurfaceOperator:
    allow_baked = False

    def execute(self, context):
        try:
            targets = surface_targets(context, self.allow_baked)
            msg = self.run(context, targets)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        self.report({'INFO'}, msg)
        return {'FINISHED'}


class PLUME_OT_surface_edits_store(PlumeSurfaceOperator, bpy.types.Operator):
    """Store the control points moved by hand as offsets that follow the surface on every frame"""

    bl_idname = "plume.surface_edits_store"
    bl_label = "Store Edits"
    bl_options = {'REGISTER', 'UNDO'}

    def run(self, context, targets):
        moved = 0
        for ob, frame_start, cps in targets:
            load_edit_mode(ob)
            i = frame_index(context, frame_start, cps)
            moved += edits.capture(ob, cps, i)
            if ob.mode != 'EDIT':
                edits.write(ob, cps, i)
        return f"Plume: stored edits of {moved} control points"


class PLUME_OT_surface_edits_clear(PlumeSurfaceOperator, bpy.types.Operator):
    """Remove the hand edits: the surfaces follow the simulation again"""

    bl_idname = "plume.surface_edits_clear"
    bl_label = "Clear Edits"
    bl_options = {'REGISTER', 'UNDO'}

    def run(self, context, targets):
        for ob, frame_start, cps in targets:
            if ob.mode == 'EDIT':
                raise BakeError(f"Plume: leave edit mode of '{ob.name}' before clearing its edits")
        for ob, frame_start, cps in targets:
            edits.set_offsets(ob, None)
            edits.write(ob, cps, frame_index(context, frame_start, cps))
        return f"Plume: cleared the edits of {len(targets)} surfaces"


class PLUME_OT_surfaces_bake_keyframes(PlumeSurfaceOperator, bpy.types.Operator):
    """Write the surfaces' control points (simulation + hand edits) as plain keyframes on every
    cached frame, so the file renders without the Plume add-on"""

    bl_idname = "plume.surfaces_bake_keyframes"
    bl_label = "Bake to Keyframes"
    bl_options = {'REGISTER', 'UNDO'}

    def run(self, context, targets):
        keys = 0
        for ob, frame_start, cps in targets:
            load_edit_mode(ob)
            edits.capture(ob, cps, frame_index(context, frame_start, cps))
        for ob, frame_start, cps in targets:
            keys += edits.bake_keyframes(ob, cps, frame_start)
        context.scene.frame_set(context.scene.frame_current)  # show the keyed points
        return f"Plume: baked {len(targets)} surfaces to {keys} keyframes"


class ExportMeshJob(JobRunner):
    """Export Mesh as a job: every target surface's control net and density map read by
    prepare(), refined (OpenSubdiv) one surface after the other by the child, the MESH objects
    made by finish()."""

    title = "Export Mesh"
    kind = "export_mesh"

    def __init__(self, level):
        super().__init__()
        self.level = level

    def prepare(self, context):
        targets = surface_targets(context, allow_baked=True)
        frame = context.scene.frame_current
        for ob, _frame_start, _cps in targets:
            load_edit_mode(ob)
            surface_mesh.sheet_file(ob, frame)  # every input checked before anything is made
        self.objects = tuple(ob.name for ob, _s, _c in targets)
        self.claim(*(("surface", name) for name in self.objects))
        self.inputs = [surface_mesh.inputs(ob, frame) for ob, _s, _c in targets]
        self.folder = os.path.dirname(surface_mesh.sheet_file(targets[0][0], frame))
        self.set_progress(0, len(self.inputs), "surface")

    def job_name(self):
        """Two exports of one domain's surfaces may run at once: a name of its own."""
        return f"export_mesh_{os.getpid()}_{id(self):x}"

    def job_spec(self):
        return {"inputs": self.inputs, "level": self.level}

    def finish(self, context):
        names = [surface_mesh.mesh_object(bpy.data.objects[name], *mesh).name
                 for name, mesh in zip(self.objects, self.result)]
        return 'INFO', f"Plume: exported {', '.join(names)}"

    def busy_text(self):
        return "Plume: these surfaces are being exported (Esc cancels): wait for it"


class PLUME_OT_surfaces_export_mesh(JobOperator, bpy.types.Operator):
    """Export the current frame's surfaces as smooth meshes (OpenSubdiv) with a "density"
    point attribute"""

    bl_idname = "plume.surfaces_export_mesh"
    bl_label = "Export Mesh"
    bl_options = {'REGISTER', 'UNDO'}

    level: bpy.props.IntProperty(
        name="Level", default=2, min=0, max=6,
        description="Catmull-Clark refinement levels of the control net (OpenSubdiv)")

    def make_runner(self, context):
        return ExportMeshJob(self.level)


classes = (PLUME_OT_surface_edits_store, PLUME_OT_surface_edits_clear,
           PLUME_OT_surfaces_bake_keyframes, PLUME_OT_surfaces_export_mesh)
