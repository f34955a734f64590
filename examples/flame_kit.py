"""Shared pieces of the structural-flames examples (structural_flames.txt), run inside
Blender: a Flame Source made through the operators an artist clicks, simple solid materials,
the bake (plume.flames_bake) with its per-frame figures, and the render of a few frames into a
strip. Builds on scene_kit. Imported by the examples in examples/flames/::

    HERE = os.path.dirname(os.path.abspath(__file__))
    sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/
    import flame_kit
"""

import json
import math
import os
import time

import bpy
import numpy as np

import scene_kit


def flame_source(name, add_primitive, location, profile, flames, source_radius, **primitive):
    """A mesh primitive (e.g. bpy.ops.mesh.primitive_cylinder_add with its keywords) at
    `location` made a Flame Source (plume.role_set) with `profile`, `flames` flames of source
    radius r = `source_radius` (m); the mesh itself is left visible (it is the wick, torch or log)."""
    add_primitive(location=location, **primitive)
    ob = bpy.context.active_object
    ob.name = name
    bpy.ops.plume.role_set(role='FLAME_SOURCE')
    fl = ob.plume.flame
    fl.profile, fl.flames, fl.radius = profile, flames, source_radius
    return ob


def solid(ob, color, roughness=0.6, emission=None, name=None):
    """Gives `ob` a Principled BSDF material of base `color` (an optional emission colour, e.g. a
    glowing ember); returns the material."""
    mat = bpy.data.materials.new(name or ob.name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    if emission is not None:
        scene_kit.compat().principled_emission_color(bsdf).default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = 1.0
    ob.data.materials.clear()
    ob.data.materials.append(mat)
    return mat


def wax(ob, color=(0.9, 0.82, 0.68), depth=0.01, name="Wax"):
    """A candle-wax material on `ob`: Principled BSDF with subsurface scattering `depth` metres
    deep (warm), so the wax glows under its flame as real wax does instead of reading black."""
    mat = solid(ob, color, roughness=0.35, name=name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    radius = (1.0, 0.45, 0.2)
    if "Subsurface Weight" in bsdf.inputs:  # 4.0+: weight, radius x scale
        bsdf.inputs["Subsurface Weight"].default_value = 1.0
        bsdf.inputs["Subsurface Scale"].default_value = depth
    else:  # 3.x: the mix, and the radius in metres
        bsdf.inputs["Subsurface"].default_value = 1.0
        radius = tuple(depth * r for r in radius)
    bsdf.inputs["Subsurface Radius"].default_value = radius
    if "Subsurface Color" in bsdf.inputs:  # 3.x: the colour scattered below the surface
        bsdf.inputs["Subsurface Color"].default_value = (*color, 1.0)
    return mat


def floor(size, z=0.0, color=(0.05, 0.04, 0.035), name="Floor"):
    """A square plane of `size` (m) at height `z`, a dull dark material."""
    bpy.ops.mesh.primitive_plane_add(size=size, location=(0.0, 0.0, z))
    ob = bpy.context.active_object
    ob.name = name
    solid(ob, color, roughness=0.8)
    return ob


def flames_settings(scene, frames, **values):
    """scene.plume_flames for frames 1..frames, its cache next to the .blend, then `values`
    (e.g. height_persistent=0.03, merging=False)."""
    f = scene.plume_flames
    f.frame_start, f.frame_end = 1, frames
    f.cache_directory = "//plume_cache/flames/"
    for name, value in values.items():
        setattr(f, name, value)
    return f


def manifest(scene):
    """The bake's manifest (flames_manifest.json): per-frame "flames" and "particles"."""
    folder = scene_kit.addon_module("snapshot").flames_cache_folder(scene)
    with open(os.path.join(folder, "flames_manifest.json"), encoding="utf-8") as fh:
        return json.load(fh)


def bake_flames(scene, tag):
    """Bake Flames (plume.flames_bake); prints its time per frame and the live flames and
    particles per frame. Returns (seconds per frame, flames per frame, particles per frame)."""
    seconds = scene_kit.run_op(bpy.ops.plume.flames_bake, tag, "Bake Flames")
    m = manifest(scene)
    frames = len(m["flames"])
    flames, particles = m["flames"], m["particles"]
    per = seconds / max(frames, 1)
    print(f"{tag}: Bake Flames {frames} frames in {seconds:.1f} s ({per:.3f} s/frame); "
          f"{scene.plume_flames.summary}", flush=True)
    print(f"{tag}: flames per frame {flames}", flush=True)
    print(f"{tag}: particles per frame min {min(particles):,} mean "
          f"{sum(particles) // max(frames, 1):,} max {max(particles):,}", flush=True)
    return per, flames, particles


def _has_denoiser():
    """Whether this Blender's Cycles has OpenImageDenoise (the bpy 4.5 / 5.x wheels do)."""
    try:
        import _cycles
        return bool(getattr(_cycles, "with_openimagedenoise", False))
    except ImportError:
        return False


#: The metering of the examples: the candle example's light (its flame and the short pieces of its
#: tip: 0.025 W over a fire 3.9 cm across) exposed +2 stops.
#: Every flame's light is physical (Light Unit's default), and eq. 5 grows as r^7: a torch is
#: ~10^4 candles, a dragon's breath ~10^10. A photographer exposes for the light falling on
#: what the flames light, ~P / D² at the fire's size D from them; so do the examples.
METER_IRRADIANCE, METER_EXPOSURE = 0.025 / 0.039 ** 2, 2.0


def metered_exposure(scene, frames, offset=0.0):
    """The exposure (stops) metering the flames' light over `frames`: P the mean total power
    of the flame lights (E × Light Unit), D the fire's size — the mean flame length (3 × light
    radius), or for many flames twice the RMS distance of their lights from their centroid if
    larger — so that P / D² reads as the candle's, plus `offset` stops of taste. Prints it."""
    folder = scene_kit.addon_module("snapshot").flames_cache_folder(scene)
    unit = scene.plume_flames.light_unit
    powers, sizes = [], []
    for frame in frames:
        d = np.load(os.path.join(folder, f"spines_{frame:04d}.npz"))
        if len(d["light_energy"]) == 0:
            continue
        powers.append(float(np.sum(d["light_energy"])) * unit)
        centres = np.asarray(d["light_centres"], np.float64)
        spread = 2.0 * math.sqrt(float(np.mean(np.sum((centres - centres.mean(axis=0)) ** 2,
                                                       axis=1))))
        sizes.append(max(3.0 * float(np.mean(d["light_radii"])), spread))
    p, size = (float(np.mean(powers)), float(np.mean(sizes))) if powers else (0.0, 1.0)
    stops = METER_EXPOSURE + math.log2(METER_IRRADIANCE / max(p / size ** 2, 1e-30)) + offset
    print(f"light: {p:.4g} W ({p * 683 / (4 * math.pi):.4g} cd), fire {size * 100:.1f} cm "
          f"across: exposure {stops:+.1f} stops", flush=True)
    return stops


def flame_look(scene, tag, out_dir, width=640, height=360, samples=64,
               world=(0.0015, 0.0015, 0.002), exposure=0.0):
    """Cycles on a near-black world (the flames and their lights light the scene), Filmic so
    bright flame cores keep their colour, `exposure` stops (flame_example meters it), the
    denoiser where the Blender has one (Debian's 3.4.1 has none)."""
    scene_kit.cycles(scene, width, height, samples, os.path.join(out_dir, tag + "_"))
    if _has_denoiser():
        scene.cycles.use_denoising = True
        scene.cycles.denoiser = 'OPENIMAGEDENOISE'
    scene_kit.plain_world(scene, world)
    scene.view_settings.view_transform = 'Filmic'
    scene.cycles.film_exposure = 2.0 ** exposure
    scene.cycles.volume_bounces = 0  # the flames emit; scattering in them is not worth its cost
    # no fireflies from the bright, small flames (the clamp scaled with the exposure)
    scene.cycles.sample_clamp_indirect = 1.0 / 2.0 ** max(exposure, 0.0)
    scene.cycles.volume_step_rate = 2.0  # steps of two voxels through the soft flames


def flame_example(tag, usage, default_frames, setup, show, exposure_offset=0.0, **look):
    """A flames example from the command line: OUT_DIR [FRAMES]. setup(scene, frames) builds the
    scene (Flame Sources, settings, camera); `look`: keywords of flame_look. Then the .blend is
    saved to OUT_DIR/TAG.blend, Bake Flames runs, the exposure is metered on the flames' light
    (metered_exposure, + exposure_offset), the frames at fractions `show` of the shot are
    rendered to OUT_DIR/TAG_####.png and OUT_DIR/TAG_strip.png, and the times are printed.
    Returns (scene, flames per frame)."""
    out_dir, frames = scene_kit.parse_args(usage, default_frames)
    scene = scene_kit.new_scene()
    flame_look(scene, tag, out_dir, **look)
    setup(scene, frames)
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, tag)
    bake_s, flames, particles = bake_flames(scene, tag)
    # Cycles' film exposure scales the render itself, before the denoiser: a dragon's 10⁹ W
    # would overflow OpenImageDenoise's half floats (it turns the flames green).
    scene.cycles.film_exposure = 2.0 ** metered_exposure(
        scene, scene_kit.shown_frames(show, frames), exposure_offset)
    bpy.ops.wm.save_mainfile()
    t0 = time.perf_counter()
    seconds, paths = scene_kit.render_frames_timed(
        scene, scene_kit.shown_frames(show, frames), out_dir, tag)
    lit = ", ".join(f"{scene_kit.lit_share(p) * 100:.0f}%" for p in paths)
    print(f"{tag}: render {seconds:.1f} s/frame ({scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {scene.cycles.samples} samples; lit pixels {lit}) -> "
          f"{scene_kit.strip(paths, os.path.join(out_dir, tag + '_strip.png'))}", flush=True)
    print(f"{tag}: total {time.perf_counter() - t0 + bake_s * len(flames):.0f} s "
          f"(bake + render)", flush=True)
    return scene, flames
