"""Datablocks the add-on builds and rebuilds in place: a node group emptied for rebuilding, and
an object of a given type reused by name (one of another type is replaced)."""

import bpy

from .. import blender_compat as compat


def empty_node_group(name, tree_type):
    """Node group `name` of `tree_type` ('GeometryNodeTree', 'CompositorNodeTree', ...) with no
    nodes and no sockets: created, or the existing one emptied so users keep pointing at it."""
    ng = bpy.data.node_groups.get(name)
    if ng is None or ng.bl_idname != tree_type:
        ng = bpy.data.node_groups.new(name, tree_type)
    ng.nodes.clear()
    compat.group_sockets_clear(ng)
    return ng


def typed_object(scene, name, ob_type, new_data, collections=()):
    """Object `name` of type `ob_type` ('MESH', 'VOLUME'), created with data new_data(name) when
    missing or of another type (that one is deleted), and linked to `collections` (else the
    scene's collection) when it is in none."""
    ob = bpy.data.objects.get(name)
    if ob is not None and ob.type != ob_type:
        bpy.data.objects.remove(ob, do_unlink=True)
        ob = None
    if ob is None:
        ob = bpy.data.objects.new(name, new_data(name))
    if not ob.users_collection:
        for coll in collections:
            coll.objects.link(ob)
        if not ob.users_collection:
            scene.collection.objects.link(ob)
    return ob


def node_material(name):
    """A new material `name` using nodes, its tree emptied but for a Material Output at (300, 0):
    (material, node tree, output node)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    return mat, nt, out
