"""Scene › Plume Farm's buttons: plume.farm_submit (the scene's job to Slurm, after every check),
plume.farm_refresh (the job's state, squeue asked in the background), plume.farm_resubmit (what
is missing or failed) and plume.farm_cancel. The panel draws `LAST` (never the disk)."""

import bpy

from ..farm import slurm, status
from ..farm.graph import FarmError
from ..snapshot import farm as farm_snapshot

#: The panel's view of the last job: {"folder": str, "states": [TaskState] or None}.
LAST = {"folder": "", "states": None, "poll": None}
#: Seconds between two polls of a job, and between two looks at a poll's answer (squeue answers
#: in tens of ms; the first state shows a moment after Submit, not a poll later).
POLL_S, ANSWER_S = 3.0, 0.2


def cluster_of(farm):
    return slurm.Cluster(partition=farm.partition.strip(), account=farm.account.strip(),
                         time_minutes=int(farm.time_limit), cpus=int(farm.cpus))


def _poll_timer():
    """While a job is shown and has not ended: starts squeue in the background, looks for its
    answer every ANSWER_S, shows it, and starts the next POLL_S later. Once every task is done,
    failed or missing it stops (Refresh, Resubmit Missing and Cancel Job start it again)."""
    poll = LAST.get("poll")
    if poll is not None:
        states = poll.result()
        if states is None:
            return ANSWER_S
        LAST["states"], LAST["poll"] = states, None
        for window in bpy.context.window_manager.windows:
            for area in window.screen.areas:
                if area.type == 'PROPERTIES':
                    area.tag_redraw()
        return None if {ts.summary for ts in states} <= status.ENDED else POLL_S
    if not LAST["folder"]:
        return None
    try:
        LAST["poll"] = status.Poll(LAST["folder"])
    except FarmError:
        return None
    return ANSWER_S


def show(folder, wait=False):
    """Shows the job in `folder` in the panel, followed by the background poll; `wait` reads
    its state now (scripts, tests, Refresh)."""
    if LAST["folder"] != folder:  # another job's states and poll are not this one's
        LAST["states"] = LAST["poll"] = None
    LAST["folder"] = folder
    if wait or bpy.app.background:
        LAST["states"] = status.read(folder)
        if bpy.app.background:
            return
    if not bpy.app.timers.is_registered(_poll_timer):
        bpy.app.timers.register(_poll_timer, first_interval=0.1)


class PLUME_OT_farm_submit(bpy.types.Operator):
    """Check the scene, copy it into a new job folder on the shared storage and submit the job
    (Scene › Plume Farm › Submit) to the Slurm cluster"""

    bl_idname = "plume.farm_submit"
    bl_label = "Submit to Farm"
    bl_options = {'REGISTER'}

    def execute(self, context):
        farm = context.scene.plume_farm
        try:
            job = farm_snapshot.plan(context)
            farm_snapshot.write(job, context.scene)
            submitted = slurm.submit(job.graph, job.folder, cluster_of(farm),
                                     farm_root=job.farm_folder)
        except (FarmError, OSError) as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        farm.last_job = job.folder
        show(job.folder)
        self.report({'INFO'}, f"Plume farm: submitted {len(submitted)} tasks "
                              f"({', '.join(t.name for t in job.graph.tasks)}) from {job.folder}; "
                              "their state is in Scene Properties › Plume Farm")
        return {'FINISHED'}


class FarmJobOperator:
    @classmethod
    def poll(cls, context):
        return bool(context.scene.plume_farm.last_job)


class PLUME_OT_farm_refresh(FarmJobOperator, bpy.types.Operator):
    """Read the state of the last farm job now"""

    bl_idname = "plume.farm_refresh"
    bl_label = "Refresh"

    def execute(self, context):
        try:
            show(context.scene.plume_farm.last_job, wait=True)
        except FarmError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        return {'FINISHED'}


class PLUME_OT_farm_resubmit(FarmJobOperator, bpy.types.Operator):
    """Submit again what of the last farm job is missing or failed (what is done is kept, what
    is queued or running is waited for)"""

    bl_idname = "plume.farm_resubmit"
    bl_label = "Resubmit Missing"

    def execute(self, context):
        folder = context.scene.plume_farm.last_job
        try:
            submitted = slurm.resubmit(folder, status.pending(status.read(folder)))
        except FarmError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        show(folder)
        self.report({'INFO'}, f"Plume farm: resubmitted {', '.join(submitted) or 'nothing'}")
        return {'FINISHED'}


class PLUME_OT_farm_cancel(FarmJobOperator, bpy.types.Operator):
    """Cancel every queued or running task of the last farm job (what is done is kept)"""

    bl_idname = "plume.farm_cancel"
    bl_label = "Cancel Job"

    def execute(self, context):
        try:
            slurm.cancel(context.scene.plume_farm.last_job)
        except FarmError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        show(context.scene.plume_farm.last_job)
        return {'FINISHED'}


classes = (PLUME_OT_farm_submit, PLUME_OT_farm_refresh, PLUME_OT_farm_resubmit,
           PLUME_OT_farm_cancel)
