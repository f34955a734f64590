"""plume.flowgraph_build and plume.fire_synthesize ([Graph Fire Synthesis] §4.3-5): the
selected baked fire domains (Record Pathlines on) become the states of a flow graph stored with
the active domain; Synthesize walks it for any number of frames into a fire Volume. Both are jobs
(jobs/): every input is checked on the main thread before anything is written, the work runs in
the job's child process into a staging folder, and the files move into place and the Blender
data is built only when it succeeded, so bad input, a cancel or a crash changes nothing."""

import os
import time

import bpy

from .. import cache, flowgraph, flowgraph_chunks
from ..native import _native
from ..build import fire_points, fire_volume
from ..jobs.operator import JobOperator
from ..jobs import JobRunner
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of
from ..snapshot.flowgraph import (fire_source, frame_inputs,  # noqa: F401  (scripts)
                                 graph_settings, source_transforms, state_domains,
                                 synthesis_settings)
from .bake import cache_setting, domain_key
from ..ui_words import FLOWGRAPH, in_ui_words, label

#: Image datablock showing the cost matrix (Figure 4) in the panel.
IMAGE_PREFIX = "Plume Flow Graph "


def show_cost_image(domain, folder):
    """(Re)loads flowgraph_cost.png as the image the panel shows."""
    name = IMAGE_PREFIX + domain.name
    img = bpy.data.images.get(name)
    if img is None:
        img = bpy.data.images.load(flowgraph.image_path(folder), check_existing=False)
        img.name = name
    else:
        img.filepath = flowgraph.image_path(folder)
        img.reload()
    img.preview_ensure()
    return img


class FlowGraphJob(JobRunner):
    """Build Flow Graph as a job: the native cost-matrix job in the child (progress from it;
    Esc kills the child when the job cannot stop inside), flowgraph.npz and the cost image
    staged; finish() commits them and fills the panel's summary."""

    title = "Build Flow Graph"
    kind = "flowgraph"

    def prepare(self, context):
        self.t0 = time.perf_counter()
        domain = active_domain(context)
        self.domain_name = domain.name
        g = domain.plume.domain.flowgraph
        self.settings = graph_settings(g)
        flowgraph.validate_graph_settings(self.settings, f"domain '{domain.name}'")
        domains = state_domains(context, domain)
        self.objects = tuple(d.name for d in domains)
        self.claim(*(domain_key(d.name) for d in domains))
        self.states = flowgraph.open_states(
            _native, [(d.name, cache_folder_of(d)) for d in domains])
        self.folder = cache_folder_of(domain)
        self.lock_folder(self.folder, cache_setting(domain))
        error = cache.check_writable(self.folder)
        if error is not None:
            raise BakeError(f"Plume: {cache_setting(domain)} is not writable ({self.folder}: "
                            f"{error})")
        self.set_progress(0, 0, "reading the pathlines")  # until the cost matrix reports

    def job_spec(self):
        return {"settings": self.settings, "states": [(st.name, st.folder) for st in self.states],
                "staging": self.stage(self.folder)}

    def finish(self, context):
        domain = bpy.data.objects[self.domain_name]
        g = domain.plume.domain.flowgraph
        self.staging.commit()
        s, states = self.result["summary"], self.states
        g.state_names = ", ".join(f"{i}: {st.name}" for i, st in enumerate(states))
        g.summary = (f"{sum(s['nodes'])} nodes ({max(s['startup'])} start-up groups per state "
                     f"left out), {s['kept']} of {s['candidates']} transitions "
                     f"(ε = {s['epsilon']:.3g} in [{s['a']:.3g}, {s['b']:.3g}]; "
                     f"{s['same_moment_kept']} of them between states at the same moment), "
                     f"pruned {sum(s['pruned'])}")
        show_cost_image(domain, self.folder)
        return 'INFO', (f"Plume: flow graph of {len(states)} states: {g.summary} "
                        f"({time.perf_counter() - self.t0:.1f} s)")

    def busy_text(self):
        return (f"Plume: domain '{self.domain_name}' is building a flow graph (Esc cancels): "
                "wait for it")


class PLUME_OT_flowgraph_build(JobOperator, bpy.types.Operator):
    """Build the flow graph of the selected fire domains (each baked with Record Pathlines is one
    state): transition costs over the pathlines' whole lifetime, transitions, dead ends pruned"""

    bl_idname = "plume.flowgraph_build"
    bl_label = "Build Flow Graph"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def make_runner(self, context):
        return FlowGraphJob()


#: The registry key of fire synthesis: one at a time (the session's prepared-group cache).
SYNTHESIS_KEY = ("fire synthesis",)


class SynthesisJob(JobRunner):
    """Synthesize Fire as a job: the random walk and the rasterized frames in the child into the
    staging folder's fire/; finish() commits them and builds the fire Volume (and the point
    preview).

    On the farm (flowgraph_chunks.py) the same job runs as many tasks: `chunk` = (first, last)
    writes only those frames into their chunk folder (no Volume: the chunk folder is the one
    folder it locks, so chunks run side by side), then `gather` takes every chunk's frames as
    the child's result and finishes as a local run does."""

    title = "Synthesize Fire"
    kind = "synthesis"
    prepare_errors = (BakeError, ValueError)

    def __init__(self, chunk=None, gather=False):
        super().__init__()
        self.chunk, self.gather = chunk, gather

    def prepare(self, context):
        self.t0 = time.perf_counter()
        domain = active_domain(context)
        self.domain_name = domain.name
        owner = f"domain '{domain.name}'"
        self.folder = folder = cache_folder_of(domain)
        self.objects = (domain.name,)
        self.claim(domain_key(domain.name), SYNTHESIS_KEY)
        self.out_folder = folder
        if self.chunk is not None:
            self.out_folder = flowgraph_chunks.chunk_folder(folder, *self.chunk)
        self.lock_folder(self.out_folder, cache_setting(domain))
        graph, states = flowgraph.load_graph(_native, folder, owner)
        settings = synthesis_settings(domain)
        flowgraph.validate_synthesis(settings, graph.state_count, owner)
        source = fire_source(domain, owner)
        steps_per_frame = int(states[0].file.nodes_per_frame)
        flowgraph.transition_hold_steps(settings, states[0].file.layout, steps_per_frame,
                                        [(st.name, st.node_count) for st in states], owner)
        settings.targets, settings.winds, settings.turbulence = frame_inputs(
            context, domain, settings.frame_start, settings.frame_end)
        if source is not None:
            settings.emitter_transforms = source_transforms(
                context, source, settings.frame_start, settings.frame_end, steps_per_frame)
        flowgraph.validate_synthesis(settings, graph.state_count, owner)
        flowgraph.SynthesisRunner(_native, graph, states, settings, folder, owner=owner)  # checks
        if self.chunk is not None:
            if not settings.frame_start <= self.chunk[0] <= self.chunk[1] <= settings.frame_end:
                raise BakeError(f"Plume: {owner}: synthesis chunk {self.chunk[0]}-"
                                f"{self.chunk[1]} is outside the synthesis range "
                                f"{settings.frame_start}-{settings.frame_end}")
        self.key = flowgraph_chunks.settings_key(settings, folder)
        self.settings, self.states, self.owner = settings, states, owner
        last = settings.frame_end if self.chunk is None else self.chunk[1]
        self.set_progress(0, last - settings.frame_start + 1, "frame")

    def job_folder(self):
        return self.out_folder  # a chunk's job file and log are its own

    def job_spec(self):
        return {"settings": self.settings, "folder": self.folder, "owner": self.owner,
                "staging": self.stage(self.out_folder), "chunk": self.chunk,
                "gather": self.gather, "key": self.key}

    def finish(self, context):
        folder, result, settings = self.out_folder, self.result, self.settings
        fire = os.path.join(folder, flowgraph.FIRE_FOLDER)
        old = [os.path.join(fire, n) for n in (os.listdir(fire) if os.path.isdir(fire) else ())
               if (n.startswith("fire_") and n.endswith(".vdb"))
               or (n.startswith("points_") and n.endswith(".npz"))
               or n == flowgraph.WALK_NAME]
        self.staging.commit(replaced=old)
        if self.chunk is not None:
            return 'INFO', (f"Plume: synthesized frames {self.chunk[0]}-{self.chunk[1]} of "
                            f"{settings.frame_start}-{settings.frame_end} for the farm "
                            f"({time.perf_counter() - self.t0:.1f} s)")
        if self.gather:
            flowgraph_chunks.remove(self.folder)
        domain = bpy.data.objects[self.domain_name]
        folder = self.folder
        frames = result.last_frame - result.frame_start + 1
        ob = fire_volume.build_fire_volume(domain, folder, result.frame_start, frames,
                                           settings.max_temperature)
        if settings.point_preview:
            fire_points.build_object(context.scene, domain, folder, result.frame_start,
                                     result.last_frame, self.states[0].file.cell_size,
                                     settings.max_temperature)
        else:
            fire_points.remove_object(domain)
        text = (f"Plume: synthesized {frames} frames of fire into '{ob.name}' "
                f"({len(result.nodes_visited)} nodes, {result.transitions_taken} transitions, "
                f"held {result.transition_hold} node steps after each, "
                f"{time.perf_counter() - self.t0:.1f} s)")
        if result.unreachable_target is not None:
            frame, state = result.unreachable_target
            return 'WARNING', (f"{text}; from frame {frame} the keyed Target State {state} "
                               "could not be reached: the flow graph does not lead back to it "
                               "from where the walk was. Build the graph with a smaller "
                               f"{label('flowgraph', 'block_size')} or a larger "
                               f"{label('flowgraph', 'epsilon')} ({FLOWGRAPH}), or bake longer "
                               "states")
        return 'INFO', text

    def error_text(self, exc):
        if isinstance(exc, BakeError):
            return str(exc)
        return f"Plume: fire synthesis: {in_ui_words('flowgraph', str(exc))}"

    def refusal_text(self, exc):  # a ValueError of the core names the setting by its name
        return self.error_text(exc)

    def busy_text(self):
        return f"Plume: fire synthesis of domain '{self.domain_name}' is running (Esc cancels it)"


class PLUME_OT_fire_synthesize(JobOperator, bpy.types.Operator):
    """Synthesize fire of any length from the active domain's flow graph by a random walk
    (temporal bias γ, keyed target states, wind) into a fire Volume"""

    bl_idname = "plume.fire_synthesize"
    bl_label = "Synthesize Fire"
    bl_options = {'REGISTER'}

    # A farm's tasks (farm/node_task.py), not the artist's button.
    farm_chunk: bpy.props.IntVectorProperty(
        name="Farm Chunk", size=2, default=(0, -1), options={'HIDDEN', 'SKIP_SAVE'},
        description="A farm task's frames: only these are written, into their own folder "
                    "(the whole range when the second is below the first)")
    farm_gather: bpy.props.BoolProperty(
        name="Gather Farm Chunks", default=False, options={'HIDDEN', 'SKIP_SAVE'},
        description="A farm's last synthesis task: the fire from every chunk's frames")

    def make_runner(self, context):
        first, last = self.farm_chunk
        return SynthesisJob(chunk=(first, last) if last >= first else None,
                            gather=self.farm_gather)


classes = (PLUME_OT_flowgraph_build, PLUME_OT_fire_synthesize)
