"""The structural flames ([Structural Flames] §5.3: "ideally, the deformed flames should be
volume rendered directly") as the Volume object "Plume Flames" over flames_####.vdb with an
emission material that renders without the add-on:
- emission: the `emission` grid (RGB W/m³ in Blender's units: each particle's share of eq. 5's
  E × Light Unit (eq. 6) in its §5.1 colour) × Flame Brightness / 4π. Cycles' volume emission strength is radiance per metre; a volume emitting
  ε W/m³ isotropically has radiance ε / 4π per metre: measured, a 10 cm cube of strength P / V
  lights a floor 13.0× as much as a P-watt point light (4π = 12.6), so the flame looks as bright
  as the light it casts;
- absorption: the `density` grid (§5.3's opacity, ∝ (d/I)²), a black scattering colour: real
  flames are "highly transparent", only bright things show through their core;
- both gated off for diffuse, glossy and shadow rays (Light Path), as the object's ray
  visibility already hides the volume from them (see build()): Cycles tests an object's ray
  visibility only where a ray enters its bounds, and a ray leaving a surface inside them (the
  ground under a campfire, inside the flames' padded voxel blocks) already carries the volume.
  Ungated, the ground inside the bounds took the volume's glow on top of the flames' lights: a
  lighter patch with straight edges (leaf blocks in 3.4, the bounding box in 5.x) on the ground.
"""

import math

import bpy

from . import datablocks, volume
from .. import flames
from ..snapshot import blend_relative

OBJECT_NAME = "Plume Flames"
MATERIAL = "Plume Flames"
#: The material's layout version (custom property): an older Plume Flames material is rebuilt.
MATERIAL_VERSION = 3
#: Volume emission strength per W/m³ (isotropic radiance per metre, see above).
EMISSION_PER_WATT = 1.0 / (4.0 * math.pi)


def _attribute(nt, name, y):
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.location = (-700, y)
    attr.attribute_name = name
    return attr


def _build_nodes(mat):
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    N, L = nt.nodes.new, nt.links.new
    pv = N("ShaderNodeVolumePrincipled")
    pv.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)  # absorbs, does not scatter
    pv.inputs["Density"].default_value = 1.0
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Blackbody Intensity"].default_value = 0.0
    L(_attribute(nt, "emission", -150).outputs["Vector"], pv.inputs["Emission Color"])
    strength = nt.nodes.new("ShaderNodeValue")
    strength.location = (-700, -400)
    strength.name = strength.label = "Plume Emission"
    # The gate 1 − max(diffuse, glossy, shadow): 1 on camera (and transmission) rays, else 0.
    path = N("ShaderNodeLightPath")
    path.location = (-1100, -550)
    hidden = N("ShaderNodeMath")
    hidden.operation = 'MAXIMUM'
    hidden.location = (-900, -500)
    L(path.outputs["Is Diffuse Ray"], hidden.inputs[0])
    L(path.outputs["Is Glossy Ray"], hidden.inputs[1])
    hidden2 = N("ShaderNodeMath")
    hidden2.operation = 'MAXIMUM'
    hidden2.location = (-700, -550)
    L(hidden.outputs[0], hidden2.inputs[0])
    L(path.outputs["Is Shadow Ray"], hidden2.inputs[1])
    gate = N("ShaderNodeMath")
    gate.operation = 'SUBTRACT'
    gate.name = gate.label = "Plume Ray Gate"
    gate.location = (-500, -550)
    gate.inputs[0].default_value = 1.0
    L(hidden2.outputs[0], gate.inputs[1])
    gated = N("ShaderNodeMath")
    gated.operation = 'MULTIPLY'
    gated.location = (-300, -400)
    L(strength.outputs[0], gated.inputs[0])
    L(gate.outputs[0], gated.inputs[1])
    L(gated.outputs[0], pv.inputs["Emission Strength"])
    L(gate.outputs[0], pv.inputs["Density"])
    L(pv.outputs["Volume"], out.inputs["Volume"])
    mat["plume_version"] = MATERIAL_VERSION


def flames_material(brightness):
    """The shared flames material (created once, then left to the artist; Flame Brightness
    updated; rebuilt when made by an older Plume)."""
    mat = bpy.data.materials.get(MATERIAL)
    if mat is None:
        mat = datablocks.node_material(MATERIAL)[0]
    if mat.get("plume_version") != MATERIAL_VERSION:
        mat.use_nodes = True
        _build_nodes(mat)
    node = mat.node_tree.nodes.get("Plume Emission")
    if node is not None:
        node.outputs[0].default_value = brightness * EMISSION_PER_WATT
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
        # Glossy rays finding the small, bright volume by chance are fireflies on every rough
        # surface; the lights give the glossy highlights instead.
        ob.visible_glossy = False
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
