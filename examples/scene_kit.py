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
