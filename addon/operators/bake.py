"""plume.bake and plume.cache_free on the active domain.

plume.bake is a job (jobs/): its frames are computed in a child process (a crash there costs
the bake, never Blender), waited for in execute() (``blender -b``, scripts), in the background
with status-bar progress and Esc from a button. A cancelled or crashed bake keeps its complete
frames (a later bake with the same settings resumes from them); a cancelled one builds the
Volume over them."""

import os

import bpy

from .. import bake_runner, cache, cache_state, fuel_warning
from ..native import _native
from ..build import volume
from ..jobs.operator import JobOperator
from ..jobs import JobRunner, folder_lock, registry
from ..settings import BakeError
from ..version import VERSION
from ..snapshot import NOT_A_DOMAIN, active_domain, cache_folder_of, take_snapshot
from .. import setting_paths


def cache_setting(domain_or_directory):
    """A domain's cache folder as a message names it: its Cache Directory setting, where."""
    directory = (domain_or_directory if isinstance(domain_or_directory, str)
                 else domain_or_directory.plume.domain.cache_directory)
    return f"the Cache Directory '{directory}' ({setting_paths.TAB} › Cache)"


def domain_key(name):
    """The registry key of a domain: one job (bake, surfaces, toon, graph, synthesis) at a time."""
    return ("domain", name)


class BakeJob(JobRunner):
    """The smoke bake of one domain as a job: the child runs bake_runner.BakeRunner (or
    MantaflowTraceRunner when the domain traces a Mantaflow cache, jobs/kinds.py)."""

    title = "Bake"
    kind = "bake"
    keeps_partial = True  # complete frames stay and resume
    #: fuel_warning.unburnt_fuel() of the snapshot: Fuel with Combustion off, said in the report
    unburnt_fuel = ()

    def prepare(self, context):
        """Snapshot + the checks that need no solver; BakeError on bad input, nothing written
        (the child checks the rest, the emitters' voxels, before it writes anything)."""
        try:
            snap = take_snapshot(context, addon_version=VERSION)
            if snap.mantaflow is None:
                bake_runner.check_input(snap, _native)
        except BakeError as e:  # the setting named as its panel shows it
            raise BakeError(setting_paths.in_ui_words(str(e))) from None
        self.domain_name = snap.domain_name
        self.objects = (snap.domain_name,)
        self.unburnt_fuel = fuel_warning.unburnt_fuel(snap)  # a warning: the bake runs
        self.claim(domain_key(snap.domain_name))
        self.lock_folder(snap.cache_folder, cache_setting(snap.cache_directory))
        self.snapshot, self.folder = snap, snap.cache_folder
        self.set_progress(0, snap.frame_count, "frame")

    def job_spec(self):
        return {"snapshot": self.snapshot}

    def tidy_partial(self, folder):
        m = cache.read_manifest(folder)
        if m is not None and isinstance(m.get("last_complete_frame"), int):
            cache.delete_plume_files(folder, frames_above=m["last_complete_frame"])

    def finish(self, context):
        """Builds/updates the Volume object from what the cache holds."""
        snap, result = self.snapshot, self.result
        domain = bpy.data.objects.get(snap.domain_name)
        if domain is not None:
            volume.build_volume(domain, snap.cache_folder, snap.frame_start, result.frames_done,
                                combustion=snap.solver.combustion,
                                max_temperature=snap.solver.max_temperature)
        what = "cancelled" if result.cancelled else "baked"
        resumed = f", resumed at frame {result.resumed_from}" if result.resumed_from else ""
        text = (f"Plume: '{snap.domain_name}' {what}: frames {snap.frame_start}-"
                f"{result.last_complete_frame} of {snap.frame_start}-{snap.frame_end} "
                f"({len(result.computed_frames)} computed{resumed}, {result.seconds:.1f} s)")
        if self.unburnt_fuel:
            return 'WARNING', f"{text}; {' '.join(self.unburnt_fuel)}"
        return ('WARNING' if result.cancelled else 'INFO'), text

    def error_text(self, exc):
        return setting_paths.in_ui_words(f"Plume: bake of '{self.domain_name}' failed: {exc}")

    def busy_text(self):
        return f"Plume: domain '{self.domain_name}' is already baking"


class PLUME_OT_bake(JobOperator, bpy.types.Operator):
    """Bake the smoke simulation of the active domain into its cache folder (Esc cancels;
    a later bake with the same settings resumes)"""

    bl_idname = "plume.bake"
    bl_label = "Bake"
    bl_options = {'REGISTER'}

    def make_runner(self, context):
        return BakeJob()


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
        job = registry.holder(domain_key(domain.name))
        if job is not None:
            self.report({'ERROR'}, f"Plume: domain '{domain.name}' is busy ({job.title}); cancel "
                                   "it first")
            return {'CANCELLED'}
        folder = cache_folder_of(domain)
        count = 0
        try:
            if os.path.isdir(folder):
                with folder_lock.holding(folder, "Free Bake"):  # not while another Blender bakes
                    count = cache.delete_plume_files(folder)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        cache_state.refresh(domain)
        volume.remove_volume(domain)
        self.report({'INFO'}, f"Plume: freed '{domain.name}' ({count} files deleted)")
        return {'FINISHED'}


def is_baking(domain):
    """True while a bake of the domain runs in the background."""
    return isinstance(registry.holder(domain_key(domain.name)), BakeJob)


def is_busy(domain):
    """True while any job (bake, surfaces, toon, graph, synthesis) works on the domain."""
    return registry.busy(domain_key(domain.name))


classes = (PLUME_OT_bake, PLUME_OT_cache_free)
