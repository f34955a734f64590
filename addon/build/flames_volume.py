"""The structural flames (structural_flames.txt §5.3: "ideally, the deformed flames should be
volume rendered directly") as the Volume object "Plume Flames" over flames_####.vdb with an
emission material: emission colour = blackbody of the `temperature` grid (K) × the base colour
grid `color` (§5.1), emission strength = the `flame` grid × Emission, a light `density` (real
flames are highly transparent, §5.3). Renders without the add-on."""

import bpy

from . import datablocks, volume
from .. import flames
from ..snapshot import blend_relative

OBJECT_NAME = "Plume Flames"
MATERIAL = "Plume Flames"
#: Principled Volume density: flames absorb little (§5.3, "real flames are highly transparent").
FLAME_DENSITY = 0.5


def _attribute(nt, name, y):
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.location = (-700, y)
    attr.attribute_name = name
    return attr


def flames_material(emission):
    """The shared flames material (created once, then left to the artist; Emission updated)."""
    mat = bpy.data.materials.get(MATERIAL)
    if mat is None:
        mat, nt, out = datablocks.node_material(MATERIAL)
        N, L = nt.nodes.new, nt.links.new
        pv = N("ShaderNodeVolumePrincipled")
        pv.inputs["Density"].default_value = FLAME_DENSITY
        pv.inputs["Density Attribute"].default_value = "density"
        pv.inputs["Blackbody Intensity"].default_value = 0.0
        blackbody = N("ShaderNodeBlackbody")
        blackbody.location = (-450, -150)
        L(_attribute(nt, "temperature", -150).outputs["Fac"], blackbody.inputs["Temperature"])
        # blackbody x colour, component-wise (a Vector Math node: Cycles 5.0 crashes optimizing
        # a volume shader holding the legacy MixRGB node)
        tint = N("ShaderNodeVectorMath")
        tint.location, tint.operation = (-250, -150), 'MULTIPLY'
        L(blackbody.outputs["Color"], tint.inputs[0])
        L(_attribute(nt, "color", -350).outputs["Vector"], tint.inputs[1])
        L(tint.outputs["Vector"], pv.inputs["Emission Color"])
        L(_attribute(nt, "color", 150).outputs["Vector"], pv.inputs["Color"])
        strength = volume._scaled_attribute(nt, "flame", emission, -500)
        strength.name = "Plume Emission"
        L(strength.outputs[0], pv.inputs["Emission Strength"])
        L(pv.outputs["Volume"], out.inputs["Volume"])
    node = mat.node_tree.nodes.get("Plume Emission")
    if node is not None:
        node.inputs[1].default_value = emission
    return mat


def build(scene, folder, frame_start, frames, emission):
    """Creates or updates "Plume Flames" over the baked frames. Returns the object."""
    ob = bpy.data.objects.get(OBJECT_NAME)
    if ob is not None and ob.type != 'VOLUME':
        bpy.data.objects.remove(ob, do_unlink=True)
        ob = None
    if ob is None:
        ob = bpy.data.objects.new(OBJECT_NAME, bpy.data.volumes.new(OBJECT_NAME))
        scene.collection.objects.link(ob)
        # §5.2: the flames light the scene through their point lights (flame_lights.py), which
        # sit inside them. Diffuse rays reaching the small, bright emitting volume by chance
        # would count that light twice and show as fireflies, and shadow rays marching through
        # the (nearly transparent, §5.3) volume to its own lights cost most of the render time.
        ob.visible_diffuse = False
        ob.visible_shadow = False
    volume.play_sequence(ob, blend_relative(flames.volume_path(folder, frame_start)),
                         frame_start, frames, flames_material(emission))
    if ob.data.materials[0] is None:
        ob.data.materials[0] = flames_material(emission)
    return ob


def remove():
    ob = bpy.data.objects.get(OBJECT_NAME)
    if ob is not None and ob.type == 'VOLUME':
        vol = ob.data
        bpy.data.objects.remove(ob, do_unlink=True)
        if vol.users == 0:
            bpy.data.volumes.remove(vol)
