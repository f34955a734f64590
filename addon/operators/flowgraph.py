"""plume.flowgraph_build and plume.fire_synthesize (graph_fire_synthesis.txt §4.3-5): the
selected baked fire domains (Record Pathlines on) become the states of a flow graph stored with
the active domain; Synthesize walks it for any number of frames into a fire Volume. Every input
is checked before anything is written, so bad input changes nothing."""

import time

import bpy
import numpy as np

from .. import _native, cache, flowgraph
from ..build import fire_points, fire_volume
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of

#: Image datablock showing the cost matrix (Figure 4) in the panel.
IMAGE_PREFIX = "Plume Flow Graph "


def state_domains(context, active):
    """The selected Plume domains (the active one included), ordered by name: state 0, 1, ..."""
    chosen = {o.name: o for o in context.selected_objects
              if getattr(o, "plume", None) is not None and o.plume.role == 'DOMAIN'}
    chosen[active.name] = active
    return [chosen[name] for name in sorted(chosen)]


def graph_settings(g):
    return flowgraph.FlowGraphSettings(
        block_size=int(g.block_size), epsilon=float(g.epsilon), auto_weights=bool(g.auto_weights),
        alpha=float(g.alpha), beta=float(g.beta), min_node_gap=int(g.min_node_gap))


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


class PLUME_OT_flowgraph_build(bpy.types.Operator):
    """Build the flow graph of the selected fire domains (each baked with Record Pathlines is one
    state): transition costs over the pathlines' whole lifetime, transitions, dead ends pruned"""

    bl_idname = "plume.flowgraph_build"
    bl_label = "Build Flow Graph"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def execute(self, context):
        t0 = time.perf_counter()
        try:
            domain = active_domain(context)
            g = domain.plume.domain.flowgraph
            settings = graph_settings(g)
            flowgraph.validate_graph_settings(settings, f"domain '{domain.name}'")
            domains = state_domains(context, domain)
            states = flowgraph.open_states(
                _native, [(d.name, cache_folder_of(d)) for d in domains])
            folder = cache_folder_of(domain)
            error = cache.check_writable(folder)
            if error is not None:
                raise BakeError(f"Plume: cache folder {folder} is not writable ({error})")
            built = flowgraph.build_graph(_native, states, settings, folder)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        s = built["summary"]
        g.state_names = ", ".join(f"{i}: {st.name}" for i, st in enumerate(states))
        g.summary = (f"{sum(s['nodes'])} nodes, {s['kept']} of {s['candidates']} transitions "
                     f"(ε = {s['epsilon']:.3g} in [{s['a']:.3g}, {s['b']:.3g}]), pruned "
                     f"{sum(s['pruned'])}")
        show_cost_image(domain, folder)
        self.report({'INFO'}, f"Plume: flow graph of {len(states)} states: {g.summary} "
                              f"({time.perf_counter() - t0:.1f} s)")
        return {'FINISHED'}


def frame_inputs(context, domain, frame_start, frame_end):
    """(targets, winds, turbulence) per frame: the keyed target_state, the uniform wind plus the
    scene's Wind force fields (Strength m/s along their Z axis) and the Turbulence force fields
    as (strength, size, seed) (flowgraph.turbulence_velocity), evaluated frame by frame (the
    current frame is restored)."""
    scene = context.scene
    g = domain.plume.domain.flowgraph
    current, subframe = scene.frame_current, scene.frame_subframe
    targets, winds, turbulence = [], [], []
    try:
        for f in range(frame_start, frame_end + 1):
            scene.frame_set(f)
            wind = np.array(g.wind, dtype=np.float64)
            turb = []
            for ob in scene.objects if g.use_force_fields else ():
                fld = ob.field
                if fld is None or ob.hide_render:
                    continue
                if fld.type == 'WIND':
                    axis = np.array(ob.matrix_world.to_3x3().col[2], dtype=np.float64)
                    wind += fld.strength * axis / max(np.linalg.norm(axis), 1e-12)
                elif fld.type == 'TURBULENCE':
                    turb.append((float(fld.strength), float(fld.size), int(fld.seed)))
            targets.append(int(g.target_state))
            winds.append(tuple(float(v) for v in wind))
            turbulence.append(turb)
    finally:
        scene.frame_set(current, subframe=subframe)
    return targets, winds, turbulence


class PLUME_OT_fire_synthesize(bpy.types.Operator):
    """Synthesize fire of any length from the active domain's flow graph by a random walk
    (temporal bias γ, keyed target states, wind) into a fire Volume"""

    bl_idname = "plume.fire_synthesize"
    bl_label = "Synthesize Fire"
    bl_options = {'REGISTER'}

    def execute(self, context):
        t0 = time.perf_counter()
        try:
            domain = active_domain(context)
            g = domain.plume.domain.flowgraph
            owner = f"domain '{domain.name}'"
            folder = cache_folder_of(domain)
            graph, states = flowgraph.load_graph(_native, folder, owner)
            d = domain.plume.domain
            settings = flowgraph.SynthesisSettings(
                frame_start=int(g.frame_start), frame_end=int(g.frame_end), seed=int(g.seed),
                traversal=g.traversal, gamma=float(g.gamma), start_state=int(g.start_state),
                max_temperature=float(d.max_temperature),
                point_preview=bool(g.point_preview), preview_points=int(g.preview_points),
                group_cache_mb=int(g.group_cache))
            flowgraph.validate_synthesis(settings, graph.state_count, owner)
            settings.targets, settings.winds, settings.turbulence = frame_inputs(
                context, domain, settings.frame_start, settings.frame_end)
            flowgraph.validate_synthesis(settings, graph.state_count, owner)
            runner = flowgraph.SynthesisRunner(_native, graph, states, settings, folder)
        except (BakeError, ValueError) as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            result = runner.run()
        except (RuntimeError, OSError) as e:
            self.report({'ERROR'}, f"Plume: fire synthesis: {e}")
            return {'CANCELLED'}
        finally:
            wm.progress_end()
        frames = result.last_frame - result.frame_start + 1
        ob = fire_volume.build_fire_volume(domain, folder, result.frame_start, frames,
                                           settings.max_temperature)
        if settings.point_preview:
            fire_points.build_object(context.scene, domain, folder, result.frame_start,
                                     result.last_frame, states[0].file.cell_size,
                                     settings.max_temperature)
        else:
            fire_points.remove_object(domain)
        self.report({'INFO'}, f"Plume: synthesized {frames} frames of fire into '{ob.name}' "
                              f"({len(result.nodes_visited)} nodes, {result.transitions_taken} "
                              f"transitions, {time.perf_counter() - t0:.1f} s)")
        return {'FINISHED'}


classes = (PLUME_OT_flowgraph_build, PLUME_OT_fire_synthesize)
