"""Cache -> Blender data: the Volume object playing a domain's VDB sequence, and its material.
Renders without the add-on (Blender reads the VDB files itself)."""

import bpy

from . import datablocks
from .. import cache
from ..fire_colors import FIRE_RAMP
from ..snapshot import blend_relative

SMOKE_MATERIAL = "Plume Smoke"
FIRE_MATERIAL = "Plume Fire"
#: Principled Volume density multiplier of the smoke material (the solver's ρ is ~1 in sources).
SMOKE_DENSITY = 5.0
#: Fire material (a fire a compositor would take: bright orange-yellow flames, cooling to dark
#: red and soot at the top, on black): the emission colour is fire_colors.FIRE_RAMP of T / T_max
#: (a Color Ramp the artist can edit; measured to read orange-yellow under both AgX and Filmic,
#: where a blackbody reads salmon under AgX). The emission strength is FIRE_EMISSION · b², b =
#: clamp((flame - FIRE_FLAME_LOW) / (FIRE_FLAME_HIGH - FIRE_FLAME_LOW), 0, 1) (node "Burning"):
#: the solver's flame grid is the unburnt fuel (0..1), which decays as e^(-r t) and never reaches
#: 0, so emission proportional to it lit the whole rising column to the domain's top (a uniform
#: glowing tube); the threshold ends the flame where little fuel is left, earlier at its edges
#: (mixed with air) than on its axis, so it tapers, and b² keeps the base bright and the tips dim.
#: The soot density is the density grid times FIRE_DENSITY · clamp(1 - FIRE_SOOT_FADE b, 0, 1):
#: none where the flame burns (real flames are nearly transparent, so the hot core is not dimmed
#: by its own fuel), all of it where the flame has gone out, scattering little (FIRE_SOOT_COLOR)
#: and absorbing the rest, so cooled smoke above the flames reads dark. The Principled Volume's
#: own blackbody is off. Measured on the 1 m combustion scene of blender_tests/test_fire_look.py
#: (domain defaults): see that file for the hue, white and lit numbers per Blender. FIRE_EMISSION
#: was 10 until the Source's Flicker (which thins the fuel by about 40% on average) made the
#: default fire dimmer; at 16 its lit share in 4.5 is 4.0-4.1% (3.5-3.9% at 10), nothing white.
FIRE_EMISSION = 16.0
FIRE_FLAME_LOW = 0.1
FIRE_FLAME_HIGH = 0.8
FIRE_FLAME_POWER = 2.0
FIRE_DENSITY = 4.0
FIRE_SOOT_FADE = 4.0
FIRE_SOOT_COLOR = (0.05, 0.04, 0.035, 1.0)
#: Layout version of "Plume Fire" (custom property "plume_version"): a Plume Fire made by an
#: older Plume is rebuilt; a material the artist put in its place is left alone.
FIRE_MATERIAL_VERSION = 5


def volume_name(domain):
    return f"{domain.name}_smoke"


def _setup_material(nt, out, combustion, max_temperature):
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    pv.location = (0, 0)
    pv.inputs["Density"].default_value = SMOKE_DENSITY
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Temperature Attribute"].default_value = "temperature"
    pv.inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    pv.inputs["Blackbody Intensity"].default_value = 0.0
    if combustion:
        _setup_fire(nt, pv, max_temperature)
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])


def _setup_fire(nt, pv, max_temperature):
    """The fire's emission and soot on Principled Volume `pv` (see FIRE_EMISSION)."""
    pv.inputs["Color"].default_value = FIRE_SOOT_COLOR
    flame = nt.nodes.new("ShaderNodeAttribute")
    flame.location = (-800, 150)
    flame.attribute_name = "flame"
    # burning = clamp((flame - FIRE_FLAME_LOW) / (FIRE_FLAME_HIGH - FIRE_FLAME_LOW), 0, 1)
    span = max(FIRE_FLAME_HIGH - FIRE_FLAME_LOW, 1e-3)
    burning = nt.nodes.new("ShaderNodeMath")
    burning.location = (-600, 150)
    burning.label = "Burning"
    burning.operation = 'MULTIPLY_ADD'
    burning.use_clamp = True
    nt.links.new(flame.outputs["Fac"], burning.inputs[0])
    burning.inputs[1].default_value = 1.0 / span
    burning.inputs[2].default_value = -FIRE_FLAME_LOW / span
    shaped = nt.nodes.new("ShaderNodeMath")  # burning ** FIRE_FLAME_POWER
    shaped.location = (-400, 250)
    shaped.operation = 'POWER'
    nt.links.new(burning.outputs[0], shaped.inputs[0])
    shaped.inputs[1].default_value = FIRE_FLAME_POWER
    strength = nt.nodes.new("ShaderNodeMath")
    strength.location = (-200, 250)
    strength.operation = 'MULTIPLY'
    nt.links.new(shaped.outputs[0], strength.inputs[0])
    strength.inputs[1].default_value = FIRE_EMISSION
    nt.links.new(strength.outputs[0], pv.inputs["Emission Strength"])
    burnt = nt.nodes.new("ShaderNodeMath")  # 1 - FIRE_SOOT_FADE burning, clamped to [0, 1]
    burnt.location = (-400, 100)
    burnt.operation = 'MULTIPLY_ADD'
    burnt.use_clamp = True
    nt.links.new(burning.outputs[0], burnt.inputs[0])
    burnt.inputs[1].default_value = -FIRE_SOOT_FADE
    burnt.inputs[2].default_value = 1.0
    soot = nt.nodes.new("ShaderNodeMath")
    soot.location = (-200, 100)
    soot.operation = 'MULTIPLY'
    nt.links.new(burnt.outputs[0], soot.inputs[0])
    soot.inputs[1].default_value = FIRE_DENSITY
    nt.links.new(soot.outputs[0], pv.inputs["Density"])
    temperature = nt.nodes.new("ShaderNodeAttribute")
    temperature.location = (-800, -100)
    temperature.attribute_name = "temperature"
    heat = nt.nodes.new("ShaderNodeMath")  # T / T_max
    heat.location = (-600, -100)
    heat.operation = 'DIVIDE'
    nt.links.new(temperature.outputs["Fac"], heat.inputs[0])
    heat.inputs[1].default_value = max(max_temperature, 1e-3)
    ramp = fire_ramp_node(nt, (-400, -100))
    nt.links.new(heat.outputs[0], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], pv.inputs["Emission Color"])


def fire_ramp_node(nt, location):
    """A Color Ramp node "Fire Colour" holding fire_colors.FIRE_RAMP (input: T / T_max)."""
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.location = location
    ramp.name = ramp.label = "Fire Colour"
    elements = ramp.color_ramp.elements
    while len(elements) > 1:
        elements.remove(elements[-1])
    for i, (position, rgb) in enumerate(FIRE_RAMP):
        element = elements[0] if i == 0 else elements.new(position)
        element.position = position
        element.color = (*rgb, 1.0)
    return ramp


def _scaled_attribute(nt, name, factor, y):
    """A Math node: the volume attribute `name` times `factor`."""
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.location = (-600, y)
    attr.attribute_name = name
    scale = nt.nodes.new("ShaderNodeMath")
    scale.location = (-400, y)
    scale.operation = 'MULTIPLY'
    nt.links.new(attr.outputs["Fac"], scale.inputs[0])
    scale.inputs[1].default_value = factor
    return scale


def material(combustion, max_temperature=4.0):
    """The shared smoke (or fire) material; created once, then left to the artist (a Plume Fire
    of an older FIRE_MATERIAL_VERSION is rebuilt)."""
    name = FIRE_MATERIAL if combustion else SMOKE_MATERIAL
    mat = bpy.data.materials.get(name)
    if mat is None:
        mat, nt, out = datablocks.node_material(name)
        _setup_material(nt, out, combustion, max_temperature)
    elif combustion and mat.get("plume_version") != FIRE_MATERIAL_VERSION:
        mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        out.location = (300, 0)
        _setup_material(nt, out, combustion, max_temperature)
    if combustion:
        mat["plume_version"] = FIRE_MATERIAL_VERSION
    return mat


def find_volume_object(domain):
    """The domain's Volume object, by the stored name, else by the default name."""
    for name in (domain.plume.domain.volume_object, volume_name(domain)):
        ob = bpy.data.objects.get(name) if name else None
        if ob is not None and ob.type == 'VOLUME':
            return ob
    return None


def build_volume(domain, folder, frame_start, frames_done, combustion=False, max_temperature=4.0):
    """Creates or updates the Volume object of a baked domain. Returns it (None if no frame)."""
    if frames_done < 1:
        remove_volume(domain)  # nothing baked (e.g. cancelled in frame 1): old frames are gone
        return None
    ob = find_volume_object(domain)
    path = blend_relative(cache.volume_path(folder, frame_start))
    if ob is None:
        ob = datablocks.typed_object(bpy.context.scene, volume_name(domain), 'VOLUME',
                                     bpy.data.volumes.new, domain.users_collection)
    play_sequence(ob, path, frame_start, frames_done, material(combustion, max_temperature))
    domain.plume.domain.volume_object = ob.name
    domain.plume.domain.frames_baked = frames_done
    domain.display_type = 'WIRE'
    domain.hide_render = True
    return ob


def play_sequence(ob, path, frame_start, frames, mat):
    """Points Volume object `ob` at the VDB sequence starting with `path` (world-space voxels)
    and gives it `mat` unless the artist replaced the Plume material."""
    vol = ob.data
    vol.grids.unload()  # a re-bake rewrote the files: do not keep the old grids in memory
    vol.filepath = path
    vol.is_sequence = True
    vol.frame_start = frame_start
    vol.frame_duration = frames
    vol.frame_offset = 0
    vol.sequence_mode = 'CLIP'
    set_motion_blur(vol)
    ob.matrix_world.identity()  # the VDB voxels are in world space
    if not vol.materials:
        vol.materials.append(mat)
    elif vol.materials[0] is None or vol.materials[0].name in (SMOKE_MATERIAL, FIRE_MATERIAL):
        vol.materials[0] = mat


def set_motion_blur(vol):
    """Cycles motion-blurs a Volume by its velocity grid when Render Properties > Motion Blur is
    on; Blender 3.4.1, 4.5 and 5.0 have the same three settings. The grid is in m/s: unit
    'SECOND' (the default 'FRAME' would read it as metres per frame, a blur fps times too long),
    scale 1. The grid's name is not set here: Blender names it itself from every frame it loads
    ("velocity" found: velocity_grid = "velocity", else ""), its setter refuses (and clears) a
    name the loaded frame lacks, and loading a frame from here, before the datablock's frame is
    evaluated, leaves Blender reading the wrong file afterwards. A new datablock already holds
    "velocity"; the tests check the evaluated one on a baked frame."""
    vol.velocity_unit = 'SECOND'
    vol.velocity_scale = 1.0


def remove_volume(domain):
    """Deletes the domain's Volume object and datablock; shows the domain again."""
    ob = find_volume_object(domain)
    if ob is not None:
        vol = ob.data
        bpy.data.objects.remove(ob, do_unlink=True)
        if vol is not None and vol.users == 0:
            bpy.data.volumes.remove(vol)
    domain.plume.domain.volume_object = ""
    domain.plume.domain.frames_baked = 0
    domain.display_type = 'TEXTURED'
    domain.hide_render = False

