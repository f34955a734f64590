"""Shared pieces of the example scripts (run inside Blender): arguments, an empty scene with the
add-on enabled, a dark studio (camera, sun, world), Cycles CPU settings, and a strip image of
several rendered frames for the README.

Import from an example run as ``blender -b --python examples/NAME.py``::

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import scene_kit
"""

import math
import os
import sys

import addon_utils
import bpy


def parse_args(usage, default_frames):
    """(out_dir, frames) from the arguments after ``--``; exits with `usage` when they are bad."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(usage)
    out_dir = os.path.abspath(argv[0])
    try:
        frames = int(argv[1]) if len(argv) > 1 else default_frames
    except ValueError:
        sys.exit(f"FRAMES must be an integer (got {argv[1]!r})\n{usage}")
    if frames < 1:
        sys.exit(f"FRAMES must be at least 1 (got {frames})\n{usage}")
    os.makedirs(out_dir, exist_ok=True)
    return out_dir, frames


def new_scene():
    """Enables the add-on and removes every object of the factory scene."""
    if addon_utils.enable("plume", default_set=True) is None:
        sys.exit("the plume add-on is not installed (see README)")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    return bpy.context.scene


def save_blend(out_dir, name):
    """Saves OUT_DIR/NAME.blend (no .blend1), so '//' cache paths land in OUT_DIR."""
    bpy.context.preferences.filepaths.save_version = 0
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, name + ".blend"))


def camera(scene, location, rotation_deg, lens=50.0, name="Camera"):
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    cam.data.lens = lens
    scene.camera = cam
    return cam


def dark_studio(scene, world_color=(0.012, 0.014, 0.02), sun_energy=4.0):
    """A sun from the upper left and a near-black world."""
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
    sun.data.energy = sun_energy
    sun.data.angle = math.radians(3.0)
    sun.rotation_euler = (math.radians(50.0), 0.0, math.radians(-40.0))
    scene.collection.objects.link(sun)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*world_color, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    return sun


def cycles(scene, width, height, samples, filepath):
    """Cycles on the CPU, no denoiser (Debian's Blender has no OIDN), PNG output. Streak sheets
    overlap in many layers, so transparent bounces are raised well above the default 8 (with 8
    the light of the deepest layers is cut off and shows as black patches)."""
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.transparent_max_bounces = 64
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = filepath


def render_frames(scene, frames, pattern):
    """Renders each frame of `frames` to pattern % frame; returns the paths."""
    paths = []
    for f in frames:
        scene.frame_set(f)
        scene.render.filepath = pattern % f
        bpy.ops.render.render(write_still=True)
        paths.append(scene.render.filepath)
    return paths


def strip(paths, out_path, gap=4):
    """Puts equally sized PNGs side by side (dark gap between them) into one PNG."""
    import numpy as np
    images = []
    for p in paths:
        img = bpy.data.images.load(p, check_existing=False)
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
        images.append(px.reshape(h, w, 4))
        bpy.data.images.remove(img)
    h = max(i.shape[0] for i in images)
    w = sum(i.shape[1] for i in images) + gap * (len(images) - 1)
    out = np.zeros((h, w, 4), dtype=np.float32)
    out[..., 3] = 1.0
    x = 0
    for i in images:
        out[:i.shape[0], x:x + i.shape[1]] = i
        x += i.shape[1] + gap
    img = bpy.data.images.new("plume_strip", w, h, alpha=True)
    img.pixels.foreach_set(out.ravel())
    img.filepath_raw = out_path
    img.file_format = 'PNG'
    img.save()
    bpy.data.images.remove(img)
    return out_path


def domain_cube(name, size, location, resolution, frames):
    """A cube mesh made a Plume domain: `resolution` cells on its longest axis, frames 1..frames,
    cache in '//plume_cache/' (next to the saved .blend)."""
    bpy.ops.mesh.primitive_cube_add(size=size, location=location)
    dom = bpy.context.active_object
    dom.name = name
    bpy.ops.plume.role_set(role='DOMAIN')
    d = dom.plume.domain
    d.resolution = resolution
    d.frame_start, d.frame_end = 1, frames
    d.cache_directory = "//plume_cache/"
    return dom


def bake_surfaces(dom, tag):
    """Bake, the Most Surfaces threshold (the peak of the Figure-4 curve the panel shows), Build
    Surfaces; the Volume object is hidden from renders so the sheets show alone, and the .blend
    is saved. Returns (bake seconds, build seconds, h0, surface objects); exits on failure."""
    import time
    bpy.context.view_layer.objects.active = dom
    t0 = time.perf_counter()
    if bpy.ops.plume.bake() != {'FINISHED'}:
        sys.exit(f"{tag}: the bake failed")
    bake_s = time.perf_counter() - t0
    if bpy.ops.plume.surfaces_pick_threshold() != {'FINISHED'}:
        sys.exit(f"{tag}: no threshold joins two streaklines")
    t0 = time.perf_counter()
    if bpy.ops.plume.surfaces_build() != {'FINISHED'}:
        sys.exit(f"{tag}: Build Surfaces failed")
    build_s = time.perf_counter() - t0
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if smoke is not None:
        smoke.hide_render = True
    bpy.ops.wm.save_mainfile()
    surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
    return bake_s, build_s, dom.plume.domain.streak_threshold, surfaces


def render_strip(scene, frames, out_dir, prefix):
    """Renders `frames` to OUT_DIR/PREFIX_####.png and puts them side by side in
    OUT_DIR/PREFIX_strip.png; returns (seconds per frame, strip path)."""
    import time
    t0 = time.perf_counter()
    paths = render_frames(scene, frames, os.path.join(out_dir, prefix + "_%04d.png"))
    seconds = (time.perf_counter() - t0) / len(paths)
    return seconds, strip(paths, os.path.join(out_dir, prefix + "_strip.png"))
