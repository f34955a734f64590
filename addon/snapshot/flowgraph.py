"""Scene -> flow-graph fire settings ([Graph Fire Synthesis]): the pathlines a fire bake
records, the states and settings of Build Flow Graph, and the settings and per-frame inputs
(target states, wind, turbulence force fields) of Synthesize Fire."""

import numpy as np

from .. import flowgraph
from ..settings import BakeError, PathlineSettings
from ..ui_words import ui
from .scene import from_properties


def pathline_settings(d):
    """PathlineSettings of a domain's obj.plume.domain (Record Pathlines of a fire bake)."""
    return PathlineSettings(enabled=bool(d.pathlines),
                            nodes_per_frame=int(d.pathline_nodes_per_frame),
                            lifetime=float(d.pathline_lifetime),
                            float16=bool(d.pathline_float16))


def state_domains(context, active):
    """The selected Plume domains (the active one included), ordered by name: state 0, 1, ..."""
    chosen = {o.name: o for o in context.selected_objects
              if getattr(o, "plume", None) is not None and o.plume.role == 'DOMAIN'}
    chosen[active.name] = active
    return [chosen[name] for name in sorted(chosen)]


def graph_settings(g):
    """flowgraph.FlowGraphSettings of a domain's obj.plume.domain.flowgraph."""
    return from_properties(flowgraph.FlowGraphSettings, g)


def synthesis_settings(domain):
    """flowgraph.SynthesisSettings of a domain (frame inputs not yet filled: frame_inputs)."""
    d = domain.plume.domain
    g = d.flowgraph
    return flowgraph.SynthesisSettings(
        frame_start=int(g.frame_start), frame_end=int(g.frame_end), seed=int(g.seed),
        traversal=g.traversal, gamma=float(g.gamma), start_state=int(g.start_state),
        transition_hold=g.transition_hold,
        transition_hold_frames=float(g.transition_hold_frames),
        max_temperature=float(d.max_temperature),
        point_preview=bool(g.point_preview), preview_points=int(g.preview_points),
        group_cache_mb=int(g.group_cache))


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


def fire_source(domain, owner):
    """The flow graph's Fire Source object (the paper's fire blade), or None. BakeError when it is
    not a mesh."""
    ob = domain.plume.domain.flowgraph.fire_source
    if ob is None:
        return None
    if ob.type != 'MESH':
        raise BakeError(f"Plume: {owner}: {ui('flowgraph', 'fire_source')} '{ob.name}' must be "
                        f"a mesh (its type is {ob.type.title()}): choose a mesh object, the "
                        "fire is attached to it, or clear the setting")
    return ob


def source_transforms(context, ob, frame_start, frame_end, steps_per_frame):
    """E of every node step of the synthesis, (K, 4, 4) row-major: the object's world matrix at
    the step's time relative to its pose at frame_start, M(t) M(frame_start)^-1. Frame f's S
    steps run from f - 1 + 1/S to f (the frame written after its last step), each evaluated at
    its subframe, so any animation (keys, constraints, parents) is followed. The current frame
    is restored."""
    scene = context.scene
    current, subframe = scene.frame_current, scene.frame_subframe
    s = int(steps_per_frame)
    out = np.empty(((frame_end - frame_start + 1) * s, 4, 4), np.float64)
    try:
        scene.frame_set(frame_start)
        rest = np.linalg.inv(np.array(ob.matrix_world, dtype=np.float64))
        for i, f in enumerate(range(frame_start, frame_end + 1)):
            for j in range(s):
                t = (j + 1) / s  # step j of frame f happens at f - 1 + t
                if t >= 1.0:
                    scene.frame_set(f)
                else:
                    scene.frame_set(f - 1, subframe=t)
                out[i * s + j] = np.array(ob.matrix_world, dtype=np.float64) @ rest
    finally:
        scene.frame_set(current, subframe=subframe)
    return out
