"""Scene Properties › Plume Farm: the cluster, the shared folder and its path on the farm, what to
submit, Submit, and the last job's tasks (queued / running / done / failed, a failed task's last
log lines), polled in the background (operators/farm.py's LAST, never the disk)."""

import bpy

from .. import manual
from ..farm import status
from ..operators import farm as farm_ops
from ..operators.manual_open import draw_help

ICONS = {status.QUEUED: 'SORTTIME', status.RUNNING: 'PLAY', status.DONE: 'CHECKMARK',
         status.FAILED: 'ERROR', status.MISSING: 'CANCEL', status.UNKNOWN: 'QUESTION'}


class SCENE_PT_plume_farm(bpy.types.Panel):
    bl_label = "Plume Farm"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "scene"
    bl_options = {'DEFAULT_CLOSED'}

    def draw_header_preset(self, context):
        draw_help(self.layout, manual.FARM)

    def draw(self, context):
        farm = context.scene.plume_farm
        layout = self.layout
        layout.use_property_split = True
        col = layout.column()
        col.prop(farm, "folder")
        col.prop(farm, "path_here")
        col.prop(farm, "path_farm")
        col = layout.column(heading="Slurm")
        col.prop(farm, "partition")
        col.prop(farm, "account")
        col.prop(farm, "time_limit")
        col.prop(farm, "cpus")
        layout.prop(farm, "job")
        if farm.job == 'FLOWGRAPH':
            layout.prop(farm, "flowgraph_domain")
        elif farm.job == 'WEDGE':
            layout.prop(farm, "wedge_domain")
            layout.prop(farm, "wedge_settings")
            layout.prop(farm, "wedge_frame")
        if farm.job != 'WEDGE':
            layout.prop(farm, "chunk")
        layout.operator("plume.farm_submit", icon='EXPORT')
        if farm.last_job:
            draw_job(layout, farm.last_job)


def draw_job(layout, folder):
    box = layout.box()
    box.label(text=f"Job: {folder}", icon='FILE_FOLDER')
    states = farm_ops.LAST["states"] if farm_ops.LAST["folder"] == folder else None
    if states is None:
        box.label(text="Press Refresh to read its state", icon='INFO')
    for ts in states or ():
        counts = {}
        for s in ts.states.values():
            counts[s] = counts.get(s, 0) + 1
        text = ", ".join(f"{n} {s.lower()}" for s, n in sorted(counts.items()))
        box.label(text=f"{ts.label}: {text}", icon=ICONS[ts.summary])
        if ts.summary == status.UNKNOWN:
            box.label(text="  Slurm did not answer (a busy controller?); asked again soon")
        for i, lines in sorted(ts.failures.items()):
            col = box.column(align=True)
            col.label(text=f"Task {i} failed; its log ends:")
            for line in lines[-3:]:
                col.label(text="  " + line[:120])
    row = box.row(align=True)
    row.operator("plume.farm_refresh", icon='FILE_REFRESH')
    row.operator("plume.farm_resubmit", icon='RECOVER_LAST')
    row.operator("plume.farm_cancel", icon='CANCEL')


classes = (SCENE_PT_plume_farm,)
