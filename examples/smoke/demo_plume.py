"""Plume demo: a smoke plume rising from a small sphere, baked and rendered headless.

    blender -b --factory-startup --python examples/smoke/demo_plume.py -- OUT_DIR [FRAMES]
        [--resolution N] [--matched] [--still WIDTH HEIGHT SAMPLES]

Builds the scene (domain cube, sphere source near the floor, camera, sun, dark world), saves it as
OUT_DIR/demo_plume.blend (so the cache path is '//'-relative), bakes a 50^3 plume (BFECC,
monotonic cubic, vorticity confinement; --resolution: N^3; --matched: Mantaflow's numerics,
MacCormack, trilinear, Euler traces, tolerance 1e-3) into OUT_DIR/plume_cache, renders
OUT_DIR/plume_####.png with Cycles on the CPU and prints the bake and render times. --still
renders only the last frame, WIDTH x HEIGHT with SAMPLES samples (the README's 256^3 picture:
`-- out 60 --resolution 256 --matched --still 640 480 64`). Needs the add-on installed
(BLENDER_USER_SCRIPTS/addons/plume or ~/.config/blender/3.4/scripts/addons/plume).
"""

import math
import os
import sys
import time

import addon_utils
import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402

RESOLUTION = 50
DEFAULT_FRAMES = 60
RESOLUTION_X, RESOLUTION_Y = 320, 240
SAMPLES = 16


def parse_args():
    import argparse
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(
        prog="blender -b --factory-startup --python examples/smoke/demo_plume.py --")
    parser.add_argument("out_dir")
    parser.add_argument("frames", nargs="?", type=int, default=DEFAULT_FRAMES)
    parser.add_argument("--resolution", type=int, default=RESOLUTION,
                        help="cells along each axis of the 2 m domain (default 50)")
    parser.add_argument("--matched", action="store_true",
                        help="Mantaflow's numerics: MacCormack, trilinear, Euler, tolerance 1e-3")
    parser.add_argument("--still", type=int, nargs=3, metavar=("WIDTH", "HEIGHT", "SAMPLES"),
                        help="render only the last frame, at this size and sample count")
    args = parser.parse_args(argv)
    if args.frames < 1:
        parser.error("FRAMES must be at least 1")
    if not 8 <= args.resolution <= 512:
        parser.error(f"--resolution must be in [8, 512] (got {args.resolution})")
    if args.still and (min(args.still[:2]) < 16 or args.still[2] < 1):
        parser.error("--still: WIDTH and HEIGHT must be >= 16, SAMPLES >= 1")
    args.out_dir = os.path.abspath(args.out_dir)
    return args


def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)


def make_domain(frames, resolution):
    # 2 m cube standing on the floor: 50 cells of 4 cm on every axis (by default).
    dom = scene_kit.domain_cube("PlumeDomain", 2.0, (0.0, 0.0, 1.0), resolution, frames)
    d = dom.plume.domain
    d.advection = 'BFECC'
    d.interpolation = 'MONOTONIC_CUBIC'
    d.vorticity = 0.4
    d.turbulence = 0.0  # the sway below moves this plume (tuned before Turbulence)
    d.alpha = 0.0  # density is passive: the heat lifts the smoke
    d.beta = 1.5
    d.boundary_neg_z = 'CLOSED'
    d.wind = (0.35, 0.0, 0.0)  # a light breeze bends the plume
    d.wind_strength = 0.4
    return dom


def make_source(frames):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.16, location=(0.0, 0.0, 0.3))
    src = bpy.context.active_object
    src.name = "PlumeSource"
    bpy.ops.plume.role_set(role='SOURCE')
    s = src.plume.source
    s.density, s.temperature = 1.0, 2.0
    s.smoke_noise = 0.0
    src.hide_render = True
    # Sway the source slowly from side to side: the plume gets a wavy, less symmetric body (and
    # the bake exercises moving sources: their motion is added to the air they emit).
    for frame, x in ((1, -0.2), (frames // 2 + 1, 0.2), (frames + 1, -0.2)):
        src.location.x = x
        src.keyframe_insert("location", index=0, frame=frame)
    return src


def make_floor():
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, 0.0))
    floor = bpy.context.active_object
    floor.name = "Floor"
    mat = bpy.data.materials.new("DemoFloor")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.006, 0.006, 0.007, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.8
    floor.data.materials.append(mat)
    return floor


def make_camera_and_light(scene):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location = (0.15, -4.3, 1.05)
    cam.rotation_euler = (math.radians(88.0), 0.0, 0.0)
    cam.data.lens = 55.0  # frames z ~ -0.1 .. 1.95: the plume leaves through the top
    scene.camera = cam
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
    sun.data.energy = 4.0
    sun.data.angle = math.radians(3.0)
    sun.rotation_euler = (math.radians(50.0), 0.0, math.radians(-40.0))
    scene.collection.objects.link(sun)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.012, 0.014, 0.02, 1.0)
    bg.inputs["Strength"].default_value = 1.0


def setup_render(scene, out_dir, frames, still):
    width, height, samples = still or (RESOLUTION_X, RESOLUTION_Y, SAMPLES)
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = os.path.join(out_dir, "plume_####")
    scene.frame_start, scene.frame_end = (frames if still else 1), frames


def main():
    args = parse_args()
    out_dir, frames = args.out_dir, args.frames
    os.makedirs(out_dir, exist_ok=True)
    if addon_utils.enable("plume", default_set=True) is None:
        sys.exit("the plume add-on is not installed (see README)")
    clear_scene()
    scene = bpy.context.scene
    make_floor()
    make_source(frames)
    dom = make_domain(frames, args.resolution)
    if args.matched:
        d = dom.plume.domain
        d.advection, d.interpolation, d.trace = 'MACCORMACK', 'LINEAR', 'EULER'
        d.pressure_tolerance = 1e-3
    make_camera_and_light(scene)
    setup_render(scene, out_dir, frames, args.still)
    bpy.context.preferences.filepaths.save_version = 0  # no demo_plume.blend1 next to it
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out_dir, "demo_plume.blend"))

    vl = bpy.context.view_layer
    vl.objects.active = dom
    t0 = time.perf_counter()
    bpy.ops.plume.bake()
    bake_s = time.perf_counter() - t0
    bpy.ops.wm.save_mainfile()

    t0 = time.perf_counter()
    bpy.ops.render.render(animation=True)
    render_s = time.perf_counter() - t0
    rendered = scene.frame_end - scene.frame_start + 1
    print(f"Plume demo: {frames} frames of a {args.resolution}^3 plume; bake {bake_s:.1f} s "
          f"({bake_s / frames:.2f} s/frame), render {render_s:.1f} s "
          f"({render_s / rendered:.2f} s/frame, {scene.render.resolution_x}x"
          f"{scene.render.resolution_y}, {scene.cycles.samples} samples) "
          f"-> {os.path.join(out_dir, 'plume_####.png')}", flush=True)


if __name__ == "__main__":
    main()
