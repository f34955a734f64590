"""Shared pieces of the structural-flames examples ([Structural Flames]), run inside
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

import scene_kit


def flame_source(name, add_primitive, location, preset, flames, source_radius, **primitive):
    """A mesh primitive (e.g. bpy.ops.mesh.primitive_cylinder_add with its keywords) at
    `location` made a Flame Source (plume.role_set) starting from `preset` (Flame Source ›
    Preset: 'CANDLE', 'TORCH', 'CAMPFIRE', 'DRAGON'; it sets the source and the scene's Flames
    settings), then `flames` flames of source radius r = `source_radius` (m); the mesh itself is
    left visible (it is the wick, torch or log)."""
    add_primitive(location=location, **primitive)
    ob = bpy.context.active_object
    ob.name = name
    bpy.ops.plume.role_set(role='FLAME_SOURCE')
    bpy.ops.plume.flame_preset(preset=preset)
    fl = ob.plume.flame
    fl.flames, fl.radius = flames, source_radius
    return ob


#: Emission strength of a glowing solid (pitch, embers): Auto Exposure sets the examples' film
#: exposure 2-4 stops up (the flames drawn at Flame Brightness 0.125), so an ember of strength 1
#: would read white; at 1/16 it glows at about its colour.
EMBER_STRENGTH = 1.0 / 16.0


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
        bsdf.inputs["Emission Strength"].default_value = EMBER_STRENGTH
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


#: Flame Brightness of the examples: the visible flames 3 stops under the light they cast. A room
#: lit only by its flames is 5-8 stops darker than the flames themselves (as in a photograph of
#: a candle); exposed so the flames' cores keep their colour (Auto Exposure), the room would be
#: black. Drawing the flames 3 stops dimmer than their light lets Auto Exposure raise the
#: exposure by those 3 stops: the room reads and the cores stay coloured.
FLAME_BRIGHTNESS = 0.125


def flame_look(scene, tag, out_dir, width=640, height=360, samples=64,
               world=(0.0015, 0.0015, 0.002), flame_brightness=FLAME_BRIGHTNESS):
    """Cycles on a near-black world (the flames and their lights light the scene), the
    Blender's own colour management (AgX in 4.x/5.x, Filmic in 3.4.1: untouched), the denoiser
    where the Blender has one (Debian's 3.4.1 has none), Flame Brightness
    `flame_brightness`."""
    scene_kit.cycles(scene, width, height, samples, os.path.join(out_dir, tag + "_"))
    if _has_denoiser():
        scene.cycles.use_denoising = True
        scene.cycles.denoiser = 'OPENIMAGEDENOISE'
    scene_kit.plain_world(scene, world)
    scene.cycles.volume_bounces = 0  # the flames emit; scattering in them is not worth its cost
    scene.cycles.volume_step_rate = 2.0  # steps of two voxels through the soft flames
    scene.plume_flames.emission = flame_brightness


def flame_example(tag, usage, default_frames, setup, show, **look):
    """A flames example from the command line: OUT_DIR [FRAMES]. setup(scene, frames) builds the
    scene (Flame Sources, settings, camera); `look`: keywords of flame_look. Then the .blend is
    saved to OUT_DIR/TAG.blend, Bake Flames runs, Auto Exposure (plume.flames_auto_exposure, as
    an artist presses it once after the bake) sets the film exposure, the frames at fractions
    `show` of the shot are
    rendered to OUT_DIR/TAG_####.png and OUT_DIR/TAG_strip.png, and the times are printed.
    Returns (scene, flames per frame)."""
    out_dir, frames = scene_kit.parse_args(usage, default_frames)
    scene = scene_kit.new_scene()
    flame_look(scene, tag, out_dir, **look)
    setup(scene, frames)
    scene.frame_start, scene.frame_end = 1, frames
    scene_kit.save_blend(out_dir, tag)
    bake_s, flames, particles = bake_flames(scene, tag)
    # Auto Exposure sets Cycles' film exposure, which scales the render itself before the
    # denoiser (a colour-management exposure would leave a dragon's 10⁹ W to overflow
    # OpenImageDenoise's half floats: it turns the flames green).
    assert bpy.ops.plume.flames_auto_exposure() == {'FINISHED'}
    stops = math.log2(scene.cycles.film_exposure)
    print(f"{tag}: Auto Exposure {stops:+.1f} stops (film exposure "
          f"{scene.cycles.film_exposure:.3g})", flush=True)
    # no fireflies from the bright, small flames (the clamp scaled with the exposure)
    scene.cycles.sample_clamp_indirect = 1.0 / max(scene.cycles.film_exposure, 1.0)
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
