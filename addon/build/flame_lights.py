"""§5.2: "for global illumination purposes, an emitting sphere at the center of each flame
segment with a radius of h/3 gives reasonable looking lighting": a pool of point lights
"Plume Flame Light NNN", one per live flame of the frame (spines_####.npz), placed at the spine's
middle, radius h/3, power = eq. 5's E × Light Unit (Blender watts), coloured by the flame's
power-weighted mean emitted colour. Lights
beyond the frame's flame count are switched off (energy 0). Moved per frame by the flame
spines' frame handler (flame_spines.py)."""

import bpy
import numpy as np

PREFIX = "Plume Flame Light "
#: Custom property of a pool light: its index in the pool.
INDEX_KEY = "plume_flame_light"


def pool(scene):
    """The pool lights of the scene, by index."""
    out = {}
    for ob in scene.objects:
        if INDEX_KEY in ob and ob.type == 'LIGHT':
            out[int(ob[INDEX_KEY])] = ob
    return out


def ensure_pool(scene, count, collection=None):
    """Creates lights up to `count` (deleting extra ones). Returns them in order."""
    lights = pool(scene)
    for i in sorted(lights):
        if i >= count:
            remove_light(lights.pop(i))
    for i in range(count):
        if i not in lights:
            name = f"{PREFIX}{i:03d}"
            data = bpy.data.lights.new(name, 'POINT')
            ob = bpy.data.objects.new(name, data)
            ob[INDEX_KEY] = i
            # The lights stand for the flames' glow on the scene; lighting the flames' own
            # (scattering) volume from inside would wash it out to white.
            ob.visible_volume_scatter = False
            (collection or scene.collection).objects.link(ob)
            lights[i] = ob
    return [lights[i] for i in range(count)]


def light_color_energy(color, energy, light_unit):
    """Blender's (colour, power) of a flame light: the flame's mean colour (luminance 1) scaled
    to a maximum component of 1 (a light's colour), the power raised by as much, so the light
    emits E × Light Unit of luminance-weighted watts whatever its colour."""
    c = np.maximum(np.asarray(color, np.float64), 0.0)
    top = float(c.max())
    if top <= 0.0:
        return (1.0, 1.0, 1.0), float(energy) * light_unit
    return tuple(float(v) for v in c / top), float(energy) * light_unit * top


def update(scene, spines, light_unit):
    """Sets the pool from a spines file's light arrays (None: every light off)."""
    lights = pool(scene)
    m = 0 if spines is None else len(spines["light_ids"])
    for i, ob in lights.items():
        light = ob.data
        if i < m:
            ob.location = tuple(float(v) for v in spines["light_centres"][i])
            light.shadow_soft_size = float(spines["light_radii"][i])
            light.color, light.energy = light_color_energy(
                spines["light_colors"][i], spines["light_energy"][i], light_unit)
        else:
            light.energy = 0.0


def remove_light(ob):
    data = ob.data
    bpy.data.objects.remove(ob, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.lights.remove(data)


def remove_all(scene):
    for ob in list(pool(scene).values()):
        remove_light(ob)
