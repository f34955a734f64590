"""What differs between the Blenders Plume supports (3.4.1, 4.5 LTS, 5.x), in one place.

Builders, operators, tests and examples call these instead of the version-specific API, so no
``bpy.app.version`` check sits anywhere else. Each difference is detected by the feature itself
(the attribute or node type existing), which also covers the versions between:

- node-group sockets: ``NodeTree.inputs/outputs`` until 3.6, ``NodeTree.interface`` from 4.0;
- the compositor: ``scene.node_tree`` with ``use_nodes`` and a Composite node until 4.5, a
  ``scene.compositing_node_group`` whose Group Output is the result from 5.0; its Math, Mix and
  Separate nodes are the shared shader nodes from 5.0;
- F-curves: ``Action.fcurves`` until 4.5, channel bags of the ID's action slot from 5.0 (4.4+
  layered actions; 4.4-4.5 still answer the legacy ``fcurves`` for the first slot);
- material transparency: ``blend_method`` / ``shadow_method`` (3.4) against EEVEE Next's
  ``surface_render_method`` (4.2+; ``shadow_method`` is gone in 4.5);
- the EEVEE engine's name: ``BLENDER_EEVEE`` (3.4, 5.0) or ``BLENDER_EEVEE_NEXT`` (4.2-4.5);
- the Principled BSDF's emission colour input: "Emission" (3.4) or "Emission Color" (4.0+)."""

import bpy

VERSION = tuple(bpy.app.version)


# --- node-group interface --------------------------------------------------------------------

def _legacy_sockets(ng):
    return hasattr(ng, "inputs") and not hasattr(ng, "interface")


def group_socket_new(ng, in_out, socket_type, name):
    """A new input ('INPUT') or output ('OUTPUT') socket of node group `ng`; the returned socket
    takes default_value, min_value, max_value and description in every version. Subtyped types
    ('NodeSocketFloatDistance', ...) become the base type with that subtype from 4.0."""
    if _legacy_sockets(ng):
        return (ng.inputs if in_out == 'INPUT' else ng.outputs).new(socket_type, name)
    subtype = next((s for s in _SUBTYPES if socket_type.endswith(s.title().replace("_", ""))
                    and socket_type != "NodeSocket" + s.title()), None)
    base = socket_type[:-len(subtype.title().replace("_", ""))] if subtype else socket_type
    socket = ng.interface.new_socket(name, in_out=in_out, socket_type=base)
    if subtype:
        socket.subtype = subtype
    return socket


#: Socket subtypes that 3.x spells as their own socket types (NodeSocketFloatDistance, ...).
_SUBTYPES = ("DISTANCE", "FACTOR", "ANGLE", "PERCENTAGE", "TIME", "UNSIGNED", "TRANSLATION",
             "DIRECTION", "VELOCITY", "ACCELERATION", "EULER", "XYZ")


def group_sockets(ng, in_out):
    """The group's input or output sockets (each with name and identifier), in order."""
    if _legacy_sockets(ng):
        return list(ng.inputs if in_out == 'INPUT' else ng.outputs)
    return [item for item in ng.interface.items_tree
            if item.item_type == 'SOCKET' and item.in_out == in_out]


def group_socket(ng, in_out, name):
    """The group's socket `name` (KeyError when missing)."""
    for s in group_sockets(ng, in_out):
        if s.name == name:
            return s
    raise KeyError(f"node group '{ng.name}' has no {in_out.lower()} socket '{name}'")


def group_input_ids(ng):
    """{input name: identifier}: the keys a Geometry Nodes modifier stores its inputs under."""
    return {s.name: s.identifier for s in group_sockets(ng, 'INPUT')}


def group_sockets_clear(ng):
    if _legacy_sockets(ng):
        ng.inputs.clear()
        ng.outputs.clear()
    else:
        ng.interface.clear()


# --- compositor -------------------------------------------------------------------------------

COMPOSITOR_GROUP = "Plume Compositing"


def compositor_tree(scene, create=False):
    """The scene's compositor node tree (None when it has none and `create` is False). Creating
    it switches the compositor on, with the Render Layers image as its result."""
    if hasattr(scene, "compositing_node_group"):  # 5.0+
        nt = scene.compositing_node_group
        if nt is None and create:
            nt = bpy.data.node_groups.new(COMPOSITOR_GROUP, 'CompositorNodeTree')
            scene.compositing_node_group = nt
            group_socket_new(nt, 'OUTPUT', 'NodeSocketColor', "Image")
            rl, out = nt.nodes.new('CompositorNodeRLayers'), nt.nodes.new('NodeGroupOutput')
            out.location = (rl.location.x + 600, rl.location.y)
            nt.links.new(rl.outputs["Image"], out.inputs[0])
        if nt is not None:
            scene.render.use_compositing = True
        return nt
    if not scene.use_nodes:
        if not create:
            return None
        scene.use_nodes = True  # 3.4-4.5 create the default Render Layers -> Composite tree
    scene.render.use_compositing = True
    return scene.node_tree


def compositor_full_precision(scene):
    """32-bit floats through the compositor (4.2+ may otherwise pick half floats)."""
    if hasattr(scene.render, "compositor_precision"):
        scene.render.compositor_precision = 'FULL'


def compositor_output(nt):
    """The input socket whose image is the compositor's result (Composite's Image before 5.0, the
    Group Output's first socket from 5.0), its node created when missing."""
    if hasattr(bpy.types, "CompositorNodeComposite"):
        node = next((n for n in nt.nodes if n.type == 'COMPOSITE'), None) or \
            nt.nodes.new('CompositorNodeComposite')
        return node.inputs["Image"]
    if not group_sockets(nt, 'OUTPUT'):
        group_socket_new(nt, 'OUTPUT', 'NodeSocketColor', "Image")
    node = next((n for n in nt.nodes if n.type == 'GROUP_OUTPUT'), None) or \
        nt.nodes.new('NodeGroupOutput')
    return node.inputs[0]


def compositor_output_node(nt):
    return compositor_output(nt).node


COMPOSITOR_MATH = 'CompositorNodeMath' if hasattr(bpy.types, "CompositorNodeMath") \
    else 'ShaderNodeMath'


def compositor_mix(nt):
    """A colour mix node of the compositor: (node, factor input, A input, B input, output)."""
    if hasattr(bpy.types, "CompositorNodeMixRGB"):
        m = nt.nodes.new('CompositorNodeMixRGB')
        return m, m.inputs["Fac"], m.inputs[1], m.inputs[2], m.outputs["Image"]
    m = nt.nodes.new('ShaderNodeMix')
    m.data_type = 'RGBA'
    return m, m.inputs["Factor"], m.inputs["A"], m.inputs["B"], m.outputs["Result"]


def compositor_translate(nt, dx, dy):
    """A node that shifts its Image input by (dx, dy) whole pixels, leaving what it uncovers
    empty (no wrapping, no filtering)."""
    t = nt.nodes.new('CompositorNodeTranslate')
    if "Interpolation" in t.inputs:  # 5.0+: options are inputs
        t.inputs["Interpolation"].default_value = 'Nearest'
        t.inputs["Extension X"].default_value = t.inputs["Extension Y"].default_value = 'Clip'
    else:
        t.wrap_axis, t.use_relative = 'NONE', False
    t.inputs["X"].default_value, t.inputs["Y"].default_value = float(dx), float(dy)
    return t


# --- animation --------------------------------------------------------------------------------

def _slot(id_data, action, create):
    ad = id_data.animation_data
    slot = ad.action_slot if ad is not None else None
    if slot is None and create:
        slot = action.slots.new(id_data.id_type, id_data.name)
        ad.action_slot = slot
    return slot


def _channelbag(id_data, action, create):
    """The channel bag of `id_data`'s slot in `action` (layered actions, 4.4+), or None."""
    slot = _slot(id_data, action, create)
    if slot is None:
        return None
    if not create:
        from bpy_extras import anim_utils
        return anim_utils.action_get_channelbag_for_slot(action, slot)
    layer = action.layers[0] if len(action.layers) else action.layers.new("Layer")
    strip = layer.strips[0] if len(layer.strips) else layer.strips.new(type='KEYFRAME')
    return strip.channelbag(slot, ensure=True)


def fcurve_new(id_data, path, index=0, group=""):
    """A new F-curve on the action assigned to `id_data` (which must have one), in the group
    `group` when given. From 4.4 it goes in the channel bag of the ID's slot (created and
    assigned when missing: the legacy Action.fcurves of 4.4-4.5 leave a new action's slot
    unassigned, so nothing would play)."""
    action = id_data.animation_data.action
    if not hasattr(action, "slots"):  # 3.4
        return action.fcurves.new(path, index=index, action_group=group)
    bag = _channelbag(id_data, action, True)
    fc = bag.fcurves.new(path, index=index)
    if group:
        fc.group = bag.groups.get(group) or bag.groups.new(group)
    return fc


def fcurves(id_data):
    """The F-curves animating `id_data` through its assigned action ([] without one); from 4.4
    the channel bag of its slot. The result supports iteration, find(path, index) and remove()."""
    ad = id_data.animation_data
    action = ad.action if ad is not None else None
    if action is None:
        return []
    if not hasattr(action, "slots"):
        return action.fcurves
    bag = _channelbag(id_data, action, False)
    return bag.fcurves if bag is not None else []


def action_fcurves(action):
    """Every F-curve of `action`, whatever slot it animates."""
    if not hasattr(action, "layers"):
        return list(action.fcurves)
    return [fc for layer in action.layers for strip in layer.strips
            for bag in strip.channelbags for fc in bag.fcurves]


# --- materials and render ---------------------------------------------------------------------

def set_transparency(mat, mode, alpha_threshold=0.5):
    """EEVEE transparency: 'CLIP' (cut out at alpha_threshold, shadows too), 'BLEND' (blended,
    hashed shadows). Cycles ignores these; they keep EEVEE previews right."""
    if hasattr(mat, "surface_render_method"):  # EEVEE Next (4.2+): the shader cuts at alpha
        mat.surface_render_method = 'DITHERED' if mode == 'CLIP' else 'BLENDED'
        mat.use_transparent_shadow = True
    else:  # 3.4
        mat.blend_method = mode
        mat.shadow_method = 'CLIP' if mode == 'CLIP' else 'HASHED'
    mat.alpha_threshold = alpha_threshold


def transparency(mat):
    """The mode set_transparency gave `mat` ('CLIP', 'BLEND' or 'OPAQUE')."""
    if hasattr(mat, "surface_render_method"):
        return {'DITHERED': 'CLIP', 'BLENDED': 'BLEND'}.get(mat.surface_render_method, 'OPAQUE')
    return mat.blend_method if mat.blend_method in ('CLIP', 'BLEND') else 'OPAQUE'


def eevee_engine():
    """The EEVEE render engine's identifier in this Blender."""
    items = bpy.types.RenderSettings.bl_rna.properties["engine"].enum_items.keys()
    return 'BLENDER_EEVEE_NEXT' if 'BLENDER_EEVEE_NEXT' in items else 'BLENDER_EEVEE'


def principled_emission_color(bsdf):
    """The Principled BSDF's emission colour input ("Emission" until 3.6)."""
    return bsdf.inputs["Emission Color"] if "Emission Color" in bsdf.inputs \
        else bsdf.inputs["Emission"]


def compositor_file_output(nt, directory, name, socket):
    """A File Output node writing `socket` as a 32-bit float EXR to
    <directory>/<name><frame:04d>.exr on every render."""
    fo = nt.nodes.new('CompositorNodeOutputFile')
    if hasattr(fo.format, "media_type"):  # 5.0+: a multilayer EXR unless told otherwise
        fo.format.media_type = 'IMAGE'
    fo.format.file_format = 'OPEN_EXR'
    fo.format.color_depth = '32'
    fo.format.exr_codec = 'ZIP'
    if hasattr(fo, "file_output_items"):  # 5.0+: file name + item name, '#' -> frame number
        fo.directory, fo.file_name = directory, ""
        fo.file_output_items.new('RGBA', name + "####")
        nt.links.new(socket, fo.inputs[name + "####"])
    else:
        fo.base_path = directory
        fo.file_slots[0].path = name
        nt.links.new(socket, fo.inputs[0])
    return fo


# --- Geometry Nodes modifier inputs ----------------------------------------------------------

def _modifier_input(mod, identifier):
    """5.1+: the input's own struct (mod.properties.inputs.<identifier>), else None."""
    inputs = getattr(getattr(mod, "properties", None), "inputs", None)
    return getattr(inputs, identifier, None) if inputs is not None else None


def modifier_input(mod, identifier):
    """The value of a Geometry Nodes modifier's input, by its socket identifier: an ID property
    of the modifier up to 5.0 (mod["Socket_2"]), mod.properties.inputs.Socket_2.value in 5.1+."""
    item = _modifier_input(mod, identifier)
    return item.value if item is not None else mod[identifier]


def set_modifier_input(mod, identifier, value):
    """Sets a Geometry Nodes modifier's input (see modifier_input)."""
    item = _modifier_input(mod, identifier)
    if item is not None:
        item.value = value
    else:
        mod[identifier] = value


# --- Blender's Mantaflow in the bpy wheels ----------------------------------------------------

#: Mantaflow's Python class hierarchy (its `PYTHON() class X : public Y` declarations), by the
#: names the `manta` module gives its classes.
_MANTA_BASES = {
    "FluidSolver": "PbClass", "GridBase": "PbClass", "Grid4dBase": "PbClass", "Mesh": "PbClass",
    "MeshDataBase": "PbClass", "Shape": "PbClass", "ParticleBase": "PbClass",
    "ParticleDataBase": "PbClass", "MovingObstacle": "PbClass", "WaveletNoiseField": "PbClass",
    "Timings": "PbClass",
    "Grid_Real": "GridBase", "Grid_Vec3": "GridBase", "Grid_int": "GridBase",
    "LevelsetGrid": "Grid_Real", "MACGrid": "Grid_Vec3", "FlagGrid": "Grid_int",
    "Grid4d_Real": "Grid4dBase", "Grid4d_Vec3": "Grid4dBase", "Grid4d_Vec4": "Grid4dBase",
    "Grid4d_int": "Grid4dBase",
    "VortexSheetMesh": "Mesh",
    "MeshDataImpl_Real": "MeshDataBase", "MeshDataImpl_Vec3": "MeshDataBase",
    "MeshDataImpl_int": "MeshDataBase",
    "NullShape": "Shape", "Box": "Shape", "Sphere": "Shape", "Cylinder": "Shape", "Slope": "Shape",
    "ParticleSystem_BasicParticleData": "ParticleBase",
    "ParticleSystem_ParticleIndexData": "ParticleBase",
    "ParticleSystem_TurbulenceParticleData": "ParticleBase",
    "ParticleSystem_VortexParticleData": "ParticleBase",
    "BasicParticleSystem": "ParticleSystem_BasicParticleData",
    "ParticleIndexSystem": "ParticleSystem_ParticleIndexData",
    "TurbulenceParticleSystem": "ParticleSystem_TurbulenceParticleData",
    "VortexParticleSystem": "ParticleSystem_VortexParticleData",
    "ParticleDataImpl_Real": "ParticleDataBase", "ParticleDataImpl_Vec3": "ParticleDataBase",
    "ParticleDataImpl_int": "ParticleDataBase",
}
#: Index of PyTypeObject.tp_mro among its pointer-sized fields (CPython 3.11 to 3.13, 64-bit;
#: the relinking checks the slot holds the MRO before it writes).
_TP_MRO_FIELD = 43


def repair_mantaflow_bindings():
    """Makes Blender's own Mantaflow bake in the `bpy` wheels (4.2+ on Linux), whose `manta`
    classes come unlinked from their bases (every class's MRO is (class, object)): Blender's
    4.x smoke scripts then stop at `phiObs.setConst(9999)` ("'LevelsetGrid' object has no
    attribute 'setConst'") and the bake aborts the process. This sets each class's MRO to the
    declared hierarchy, so base methods resolve and type checks pass. A no-op where the
    hierarchy is linked (Blender's own executables) or when `manta` is missing; returns the
    number of classes relinked. Only Mantaflow's bakes need it; Plume's own bakes do not."""
    try:
        import manta
    except ImportError:
        return 0
    if issubclass(manta.LevelsetGrid, manta.Grid_Real):
        return 0
    import ctypes

    def chain(name):
        out = [getattr(manta, name)]
        while name in _MANTA_BASES:
            name = _MANTA_BASES[name]
            out.append(getattr(manta, name))
        return tuple(out) + (object,)

    relinked = 0
    for name in _MANTA_BASES:
        cls = getattr(manta, name, None)
        if cls is None or len(cls.__mro__) > 2:
            continue
        slot = ctypes.c_void_p.from_address(id(cls) + ctypes.sizeof(ctypes.c_void_p)
                                            * _TP_MRO_FIELD)
        if slot.value != id(cls.__mro__):
            return relinked  # another type layout: leave the classes alone
        mro = chain(name)
        ctypes.pythonapi.Py_IncRef(ctypes.py_object(mro))  # owned by the type from now on
        slot.value = id(mro)
        ctypes.pythonapi.PyType_Modified(ctypes.py_object(cls))
        relinked += 1
    return relinked
