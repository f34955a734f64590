"""Shared pieces of the example scripts (run inside Blender): arguments, an empty scene with the
add-on enabled, a dark studio (camera, sun, world), Cycles CPU settings, and a strip image of
several rendered frames for the manuals.

The examples sit in one folder per pipeline (examples/<pipeline>/NAME.py, beside that
pipeline's manual, README.md); this module and the other kits stay in examples/ so that every
example imports them the same way, as its first lines after the standard imports::

    HERE = os.path.dirname(os.path.abspath(__file__))
    sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/
    import scene_kit
"""

import math
import os
import sys
import time

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


def camera(scene, location, rotation_deg=None, lens=50.0, name="Camera", target=None):
    """The scene camera at `location`, turned by `rotation_deg` (XYZ Euler) or looking at the
    point `target` (image up towards +z)."""
    from mathutils import Vector
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    scene.collection.objects.link(cam)
    cam.location = location
    if target is not None:
        view = Vector(target) - Vector(location)
        cam.rotation_euler = view.to_track_quat('-Z', 'Y').to_euler()
    else:
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
    plain_world(scene, world_color)
    return sun


def plain_world(scene, color):
    """The scene's world: one plain colour, strength 1."""
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = 1.0


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


def strip(paths, out_path, gap=4, columns=None):
    """Puts equally sized PNGs side by side (dark gap between them) into one PNG; with
    `columns`, in rows of that many images (the first row on top)."""
    import numpy as np
    images = [png_pixels(p, alpha=True) for p in paths]  # Blender's rows run bottom to top
    columns = columns or len(images)
    rows = (len(images) + columns - 1) // columns
    ch, cw = max(i.shape[0] for i in images), max(i.shape[1] for i in images)
    h, w = rows * ch + gap * (rows - 1), columns * cw + gap * (columns - 1)
    out = np.zeros((h, w, 4), dtype=np.float32)
    out[..., 3] = 1.0
    for n, i in enumerate(images):
        y, x = h - (n // columns + 1) * ch - (n // columns) * gap, (n % columns) * (cw + gap)
        out[y:y + i.shape[0], x:x + i.shape[1]] = i
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
    bpy.context.view_layer.objects.active = dom
    bake_s = run_op(bpy.ops.plume.bake, tag, "the bake")
    if bpy.ops.plume.surfaces_pick_threshold() != {'FINISHED'}:
        sys.exit(f"{tag}: no threshold joins two streaklines")
    build_s = run_op(bpy.ops.plume.surfaces_build, tag, "Build Surfaces")
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if smoke is not None:
        smoke.hide_render = True
    bpy.ops.wm.save_mainfile()
    surfaces = [o for o in bpy.data.objects if o.type == 'SURFACE']
    return bake_s, build_s, dom.plume.domain.streak_threshold, surfaces


def render_frames_timed(scene, frames, out_dir, prefix):
    """Renders `frames` to OUT_DIR/PREFIX_####.png; returns (seconds per frame, paths)."""
    t0 = time.perf_counter()
    paths = render_frames(scene, frames, os.path.join(out_dir, prefix + "_%04d.png"))
    return (time.perf_counter() - t0) / len(paths), paths


def render_strip(scene, frames, out_dir, prefix):
    """Renders `frames` to OUT_DIR/PREFIX_####.png and puts them side by side in
    OUT_DIR/PREFIX_strip.png; returns (seconds per frame, strip path)."""
    seconds, paths = render_frames_timed(scene, frames, out_dir, prefix)
    return seconds, strip(paths, os.path.join(out_dir, prefix + "_strip.png"))


def cpu_seconds():
    """CPU seconds of this process (all threads) and of its waited-for children: a bake runs in
    a job process of its own (addon/jobs/)."""
    import resource
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                 resource.getrusage(resource.RUSAGE_CHILDREN)))


def run_op_cpu(op, tag, what):
    """run_op, also returning the CPU time it took, of this process and of the job process it
    ran in: (wall s, CPU s). On a shared machine the CPU time is the steadier measure."""
    c0 = cpu_seconds()
    wall = run_op(op, tag, what)
    return wall, cpu_seconds() - c0


def run_op(op, tag, what):
    """Runs operator `op` (e.g. bpy.ops.plume.bake); exits naming `what` unless it finishes.
    Returns its seconds."""
    t0 = time.perf_counter()
    if op() != {'FINISHED'}:
        sys.exit(f"{tag}: {what} failed")
    return time.perf_counter() - t0


# --- Shared by the toon and flame examples ------------------------------------------------


def flat_box(name, location, size, color, add_primitive=None):
    """A box of `size` (m) at `location`, flat `color` (emission only): e.g. a floor or ceiling
    drawn in a toon picture, or a log under a fire (add_primitive: a bpy.ops.mesh primitive 2 m
    across, e.g. a cylinder); it is no Plume object."""
    if add_primitive is None:
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    else:
        add_primitive(location=location)
        size = tuple(v / 2.0 for v in size)
    box = bpy.context.active_object
    box.name = name
    box.scale = size
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    emission = nodes.new('ShaderNodeEmission')
    emission.inputs["Color"].default_value = (*color, 1.0)
    mat.node_tree.links.new(emission.outputs[0], nodes["Material Output"].inputs["Surface"])
    box.data.materials.append(mat)
    return box


def shown_frames(fractions, frames):
    """The frames at `fractions` of a shot of `frames` frames (1 .. frames, sorted, once each)."""
    return sorted({max(1, min(frames, round(f * frames))) for f in fractions})


# --- Flow-graph fire ([Graph Fire Synthesis]) ---------------------------------------------

#: RAM a pathline sample takes while the graph is built (pathline_group.h: velocity, density,
#: temperature as floats): the build holds every group of every state, |Ω| L 20 B per node.
PATHLINE_SAMPLE_BYTES = 20


def addon_module(name):
    """A module of the installed add-on, e.g. '_native', 'cache', 'flowgraph', 'snapshot'."""
    import importlib
    return importlib.import_module("plume." + name)


def compat():
    """The add-on's module of Blender version differences (plume.blender_compat)."""
    return addon_module("blender_compat")


def select(objects, active):
    """Selects exactly `objects` and makes `active` the active object."""
    bpy.ops.object.select_all(action='DESELECT')
    for ob in objects:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = active


def png_pixels(path, alpha=False):
    """RGB (h, w, 3), or with `alpha` RGBA (h, w, 4), pixels of an image file, read through
    Blender (rows bottom first)."""
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    px = px.reshape(h, w, 4)
    return px if alpha else px[..., :3]


def lit_share(path, level=0.05):
    """Share of the pixels of PNG `path` brighter than `level` in some channel."""
    return float((png_pixels(path).max(axis=2) > level).mean())
