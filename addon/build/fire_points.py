"""Point preview of the synthesized fire ([Graph Fire Synthesis] §5.3, "optional point
preview"): a MESH object "<domain>_fire_points" whose vertices and point attributes (temperature,
density) follow fire/points_####.npz through a persistent frame_change_pre handler, drawn as
spheres of half a cell by a geometry-nodes "Mesh to Points" modifier with an emission material
coloured by the fire Volume's colour ramp of the temperature (fire_colors.FIRE_RAMP of T / T_max).
Like the fire Volume's sequence (CLIP), frames outside the synthesized range show no points."""

import bpy
import numpy as np

from . import datablocks, frame_handlers, point_frames
from .volume import _scaled_attribute, fire_ramp_node
from .. import blender_compat as compat
from .. import flowgraph

#: Custom properties of a fire points object: its cache folder and synthesized frame range.
FOLDER_KEY = "plume_fire_points_cache"
DOMAIN_KEY = "plume_fire_points_domain"
RANGE_KEY = "plume_fire_points_frames"
#: Point attributes. Not "temperature"/"density": Cycles maps those names to its standard
#: volume attributes, and point attributes of those names read as 0 in the shader.
TEMPERATURE_ATTRIBUTE = "plume_temperature"
DENSITY_ATTRIBUTE = "plume_density"
GROUP = "Plume Fire Points"
MATERIAL = "Plume Fire Points"
#: Surface emission strength of a point at T_max (a point is a small sphere, not a volume: its
#: own scale, independent of the Volume's FIRE_EMISSION).
POINT_EMISSION = 8.0

_EMPTY = {"positions": np.zeros((0, 3), np.float32), "temperature": np.zeros(0, np.float32),
          "density": np.zeros(0, np.float32)}
#: The points file of the last frame read.
_files = point_frames.LastFile(flowgraph.read_points, (OSError, ValueError))


def object_name(domain):
    return f"{domain.name}_fire_points"


def update_object(ob, frame):
    """Sets the points of `frame` (none outside the synthesized range). True if set."""
    cached = point_frames.cached_frames(ob, FOLDER_KEY, RANGE_KEY)
    if cached is None:
        return False
    folder, first, last = cached
    p = _files.read(flowgraph.points_path(folder, frame)) if first <= frame <= last else _EMPTY
    if p is None:
        return False
    point_frames.set_points(ob.data, p["positions"], {
        TEMPERATURE_ATTRIBUTE: ('FLOAT', p["temperature"]),
        DENSITY_ATTRIBUTE: ('FLOAT', p["density"])})
    return True


@bpy.app.handlers.persistent
def frame_change_pre(scene, *_args):
    for ob in scene.objects:
        if FOLDER_KEY in ob:
            update_object(ob, scene.frame_current)


@bpy.app.handlers.persistent
def load_post(*_args):
    """Another .blend: the prepared pathline groups of the last synthesis are freed."""
    flowgraph.clear_session_cache()


def register():
    frame_handlers.add(frame_change_pre)
    if load_post not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(load_post)


def unregister():
    frame_handlers.remove(frame_change_pre)
    while load_post in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(load_post)
    flowgraph.clear_session_cache()
    _files.clear()


def points_group():
    """The "Plume Fire Points" geometry-nodes group (rebuilt in place): Mesh to Points with
    the Radius input, then Set Material."""
    ng = datablocks.empty_node_group(GROUP, 'GeometryNodeTree')
    new = compat.group_socket_new
    new(ng, 'INPUT', 'NodeSocketGeometry', "Geometry")
    radius = new(ng, 'INPUT', 'NodeSocketFloatDistance', "Radius")
    radius.min_value, radius.default_value = 0.0, 0.01
    new(ng, 'INPUT', 'NodeSocketMaterial', "Material")
    new(ng, 'OUTPUT', 'NodeSocketGeometry', "Geometry")
    N, L = ng.nodes.new, ng.links.new
    gin, gout = N('NodeGroupInput'), N('NodeGroupOutput')
    gin.location, gout.location = (-400, 0), (400, 0)
    to_points = N('GeometryNodeMeshToPoints')
    set_mat = N('GeometryNodeSetMaterial')
    set_mat.location = (200, 0)
    L(gin.outputs["Geometry"], to_points.inputs["Mesh"])
    L(gin.outputs["Radius"], to_points.inputs["Radius"])
    L(to_points.outputs["Points"], set_mat.inputs["Geometry"])
    L(gin.outputs["Material"], set_mat.inputs["Material"])
    L(set_mat.outputs["Geometry"], gout.inputs["Geometry"])
    return ng


def points_material(max_temperature):
    """Emission coloured by the fire Volume's colour ramp of the point's T / T_max, of strength POINT_EMISSION · T / T_max; created once, then left to the
    artist."""
    mat = bpy.data.materials.get(MATERIAL)
    if mat is not None:
        return mat
    mat, nt, out = datablocks.node_material(MATERIAL)
    N, L = nt.nodes.new, nt.links.new
    emission = N("ShaderNodeEmission")
    ramp = fire_ramp_node(nt, (-200, 0))
    t_max = max(max_temperature, 1e-3)
    L(_scaled_attribute(nt, TEMPERATURE_ATTRIBUTE, 1.0 / t_max, 0).outputs[0], ramp.inputs["Fac"])
    L(ramp.outputs["Color"], emission.inputs["Color"])
    L(_scaled_attribute(nt, TEMPERATURE_ATTRIBUTE, POINT_EMISSION / t_max, -200).outputs[0],
      emission.inputs["Strength"])
    L(emission.outputs["Emission"], out.inputs["Surface"])
    return mat


def build_object(scene, domain, folder, frame_start, last_frame, cell_size, max_temperature):
    """Creates (or updates) "<domain>_fire_points" over fire/points_####.npz of frames
    frame_start..last_frame, with the points of the current frame, spheres of radius
    cell_size / 2. Returns the object."""
    ob = point_frames.point_object(scene, object_name(domain), {
        FOLDER_KEY: point_frames.stored_path(folder), DOMAIN_KEY: domain.name,
        RANGE_KEY: [int(frame_start), int(last_frame)]}, domain.users_collection)
    ng = points_group()
    mod = ob.modifiers.get(GROUP)
    if mod is None or mod.type != 'NODES':
        mod = ob.modifiers.new(GROUP, 'NODES')
    mod.node_group = ng
    ids = compat.group_input_ids(ng)
    compat.set_modifier_input(mod, ids["Radius"], 0.5 * float(cell_size))
    compat.set_modifier_input(mod, ids["Material"], points_material(max_temperature))
    # The handler rewrites the points while rendering frames: lock the interface.
    scene.render.use_lock_interface = True
    _files.clear()
    update_object(ob, scene.frame_current)
    domain.plume.domain.flowgraph.points_object = ob.name
    return ob


def remove_object(domain):
    """Deletes the domain's fire points object (point preview off)."""
    g = domain.plume.domain.flowgraph
    for name in {g.points_object, object_name(domain)} - {""}:
        ob = bpy.data.objects.get(name)
        if ob is not None and FOLDER_KEY in ob:
            point_frames.remove_object(name)
    g.points_object = ""
    _files.clear()
