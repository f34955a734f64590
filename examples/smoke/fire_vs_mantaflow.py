"""Fire side by side: Blender's Mantaflow (Quick Smoke, style Fire) and Plume's combustion on one
burner, each with its own default material, rendered through the scene's default view transform.

    blender_tests/run.py --blender 4.5 --script examples/smoke/fire_vs_mantaflow.py -- OUT_DIR [RES] [FRAMES] [SAMPLES] [WIDTH]
    blender -b --factory-startup --python examples/smoke/fire_vs_mantaflow.py -- OUT_DIR ...

Scene: a burner (a box 0.3 x 0.3 x 0.06 m on the floor at z 0.03) in a 1 x 1 x 1.5 m domain
standing on the floor (z 0..1.5), RES cells on its longest side (default 96), FRAMES frames
(default 48), floor closed, other sides open, a black world and no lights (the fire lights
itself), a camera 3.2 m in front looking at z 0.6. Colour management is the factory one: AgX in
4.x/5.x, Filmic in 3.4 (nothing here sets a view transform, exposure or look).

- Mantaflow: the burner selected, bpy.ops.object.quick_smoke(style='FIRE') (flow type Fire,
  inflow, fuel 1; Quick Smoke's domain and its "Smoke Domain Material": Principled Volume with
  blackbody intensity 1), the domain moved onto the shared box with resolution RES, the floor
  closed and a Modular OpenVDB cache in OUT_DIR (Quick Smoke's Replay cache cannot be baked
  from a script); everything else as Quick Smoke leaves it (adaptive time steps, CFL 4, no
  noise, vorticity 0, flame settings). Baked with bpy.ops.fluid.bake_data().
- Plume: a domain on the same box (plume.role_set, Combustion on, every other setting its
  default), the burner a Source of Fuel 1 and Density 0 (plume.role_set), baked with
  plume.bake(); its Volume object gets the default "Plume Fire" material.

Both bakes are timed (wall clock around the bake operator). Frames 2/3 and 3/3 of FRAMES are
rendered for each (Cycles CPU, WIDTH x WIDTH·9/16, default 1280 x 720, SAMPLES samples, default
32), measured with blender_tests/fire_look.py, and put side by side (rows: frames; left
Mantaflow, right Plume) into OUT_DIR/fire_vs_mantaflow.png, with a crop of the middle half of
each image into OUT_DIR/fire_vs_mantaflow_crop.png. The last lines print the bake times and the
fire_look numbers of each render. In the bpy wheels Mantaflow needs
plume.blender_compat.repair_mantaflow_bindings() first (see README "Mantaflow in the bpy
wheels")."""

import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE), os.path.join(os.path.dirname(os.path.dirname(HERE)),
                                                           "blender_tests")]
import fire_look  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: fire_vs_mantaflow.py -- OUT_DIR [RES] [FRAMES] [SAMPLES] [WIDTH]\n"
         "  RES cells on the domain's longest side (96), FRAMES baked (48), SAMPLES (32), "
         "WIDTH px (1280)")
DOMAIN_SIZE = (1.0, 1.0, 1.5)
DOMAIN_CENTER = (0.0, 0.0, 0.75)
BURNER_SIZE = (0.3, 0.3, 0.06)
BURNER_CENTER = (0.0, 0.0, 0.03)
CAMERA = (0.0, -3.2, 0.6)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    try:
        res, frames, samples, width = (int(a) for a in (argv[1:] + ["96", "48", "32", "1280"][
            len(argv) - 1:])[:4])
    except ValueError:
        sys.exit(USAGE)
    if res < 8 or frames < 3 or samples < 1 or width < 16:
        sys.exit(USAGE)
    out = os.path.abspath(argv[0])
    os.makedirs(out, exist_ok=True)
    return out, res, frames, samples, width


def box(name, size, location):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    ob = bpy.context.active_object
    ob.name = name
    ob.scale = size
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    return ob


def mantaflow_fire(burner, res, frames, cache_dir):
    """Quick Smoke (Fire) on the burner; its domain moved onto the shared box. Returns it."""
    scene_kit.select([burner], burner)
    scene_kit.compat().repair_mantaflow_bindings()
    if bpy.ops.object.quick_smoke(style='FIRE') != {'FINISHED'}:
        sys.exit("bpy.ops.object.quick_smoke(style='FIRE') failed")
    dom = bpy.context.active_object
    dom.name = "Mantaflow Fire"
    dom.location = DOMAIN_CENTER
    dom.scale = tuple(s / 2.0 for s in DOMAIN_SIZE)  # Quick Smoke's domain is the 2 m cube
    ds = next(m for m in dom.modifiers if m.type == 'FLUID').domain_settings
    ds.resolution_max = res
    ds.use_collision_border_bottom = True  # the burner stands on the floor (Plume's default)
    ds.cache_type = 'MODULAR'
    ds.cache_directory = cache_dir
    ds.cache_frame_start, ds.cache_frame_end = 1, frames
    return dom


def bake_mantaflow(dom):
    scene_kit.select([dom], dom)
    with bpy.context.temp_override(object=dom, active_object=dom, selected_objects=[dom]):
        t0 = time.perf_counter()
        result = bpy.ops.fluid.bake_data()
        seconds = time.perf_counter() - t0
    if result != {'FINISHED'}:
        sys.exit(f"bpy.ops.fluid.bake_data() returned {result}")
    return seconds


def plume_fire(burner, res, frames, cache_dir):
    """A Plume domain on the shared box, Combustion on; the burner a Source of fuel."""
    dom = box("Plume Fire Domain", DOMAIN_SIZE, DOMAIN_CENTER)
    bpy.ops.plume.role_set(role='DOMAIN')
    d = dom.plume.domain
    d.resolution, d.frame_start, d.frame_end = res, 1, frames
    d.combustion = True
    d.cache_directory = cache_dir
    scene_kit.select([burner], burner)
    bpy.ops.plume.role_set(role='SOURCE')
    burner.plume.source.fuel, burner.plume.source.density = 1.0, 0.0
    return dom


def bake_plume(dom):
    scene_kit.select([dom], dom)
    t0 = time.perf_counter()
    if bpy.ops.plume.bake() != {'FINISHED'}:
        sys.exit("bpy.ops.plume.bake() failed")
    return time.perf_counter() - t0


def crop_strip(paths, out_path):
    """The middle half (in x) of each PNG, in rows of two, into one PNG."""
    crops = []
    for p in paths:
        px = scene_kit.png_pixels(p, alpha=True)
        h, w = px.shape[:2]
        q = out_path[:-4] + "_" + os.path.basename(p)
        part = px[:, w // 4:w - w // 4].copy()
        tmp = bpy.data.images.new("plume_crop", part.shape[1], h, alpha=True)
        tmp.pixels.foreach_set(part.ravel())
        tmp.filepath_raw, tmp.file_format = q, 'PNG'
        tmp.save()
        bpy.data.images.remove(tmp)
        crops.append(q)
    scene_kit.strip(crops, out_path, columns=2)
    for q in crops:
        os.remove(q)
    return out_path


def main():
    out, res, frames, samples, width = parse_args()
    scene = scene_kit.new_scene()
    scene.frame_start, scene.frame_end = 1, frames
    burner = box("Burner", BURNER_SIZE, BURNER_CENTER)
    manta = mantaflow_fire(burner, res, frames, os.path.join(out, "mantaflow_cache"))
    burner.hide_render = True
    plume = plume_fire(burner, res, frames, os.path.join(out, "plume_cache") + "/")
    manta_s = bake_mantaflow(manta)
    plume_s = bake_plume(plume)
    print(f"bake: Mantaflow {manta_s:.1f} s, Plume {plume_s:.1f} s ({frames} frames, {res} cells "
          f"on the longest side)", flush=True)
    smoke = bpy.data.objects[plume.plume.domain.volume_object]
    scene_kit.camera(scene, CAMERA, rotation_deg=(90.0, 0.0, 0.0))
    scene_kit.plain_world(scene, (0.0, 0.0, 0.0))
    scene_kit.cycles(scene, width, width * 9 // 16, samples, "")
    shown = (frames * 2 // 3, frames)
    paths, looks = [], []
    for f in shown:
        for tag, on, off in (("mantaflow", manta, smoke), ("plume", smoke, manta)):
            on.hide_render, off.hide_render = False, True
            scene.frame_set(f)
            scene.render.filepath = os.path.join(out, f"fire_{tag}_{f:03d}.png")
            t0 = time.perf_counter()
            bpy.ops.render.render(write_still=True)
            seconds = time.perf_counter() - t0
            paths.append(scene.render.filepath)
            m = fire_look.measure(scene_kit.png_pixels(scene.render.filepath))
            looks.append((tag, f, m, seconds))
    scene_kit.strip(paths, os.path.join(out, "fire_vs_mantaflow.png"), columns=2)
    crop_strip(paths, os.path.join(out, "fire_vs_mantaflow_crop.png"))
    scene_kit.save_blend(out, "fire_vs_mantaflow")
    print(f"Blender {bpy.app.version_string}, view transform "
          f"{scene.view_settings.view_transform}, {width} x {width * 9 // 16}, {samples} samples")
    print(f"bake: Mantaflow {manta_s:.1f} s, Plume {plume_s:.1f} s")
    for tag, f, m, seconds in looks:
        print(f"{tag} frame {f} (render {seconds:.0f} s): {fire_look.text(m)}")
    # Free the Mantaflow domain while Python runs (the bpy module aborts freeing it at exit).
    bpy.ops.wm.read_homefile(use_factory_startup=True)


if __name__ == "__main__":
    main()
