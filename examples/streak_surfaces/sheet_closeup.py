"""A close-up of a streak sheet at 1920 x 1080 ([Smoke Surfaces] Figure 7: a NURBS sheet stays
smooth as the camera comes close, where a volume or particles break up).

    blender -b --factory-startup --python examples/streak_surfaces/sheet_closeup.py -- OUT_DIR [BEFORE]
    blender_tests/run.py --blender 4.5 --script examples/streak_surfaces/sheet_closeup.py -- OUT_DIR [BEFORE]

The newcomer's scene of first_streaks.py with every default (a 2 m domain at 40³, a UV sphere of
radius 0.25 m as the Source, 60 frames): Bake, Build Surfaces, then a camera 0.6 m from the
largest sheet at frame 60 where it flares out of the rim above the source (closeup_target: the
frame spans about 0.43 m, nine cells of the grid), Fast Sheet Render at 1920 x 1080, rendered
twice from the same build:
- fixed: at the resolution used without a camera (2 samples per control point along the
  streaklines, 4 across; 1 along an order-2 direction, whose samples are its control points);
- camera: with the tessellation sized by the camera on every frame (at most 8 px per edge).
Writes OUT_DIR/sheet_closeup_{fixed,camera}.png (1920 x 1080), CROP of each halved to
320 x 360 as *_crop.png, and OUT_DIR/sheet_closeup_strip.png: those crops side by side, after
BEFORE's if given (a
fixed render made by this script with an older add-on, whose fit fell back to order 2 and which
had no camera sizing: only the fixed render is made then). blender_tests/test_sheet_closeup.py
asserts what the camera render shows, on the same scene and camera.
"""

import math
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import scene_kit  # noqa: E402
from first_streaks import FRAMES, newcomer_scene  # noqa: E402,F401  (the test imports them here)

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/streak_surfaces/sheet_closeup.py -- OUT_DIR [BEFORE_PNG]")
WIDTH, HEIGHT = 1920, 1080
#: The close-up: DISTANCE from the control point of the largest sheet (most control points) at
#: frame 60 nearest TARGET_HEIGHT, where the sheets flare out of the rim above the source, seen
#: from outside the plume, VIEW_TURN_DEG around the vertical off the line from the plume's axis
#: (the frame spans about 0.43 m, nine cells).
DISTANCE = 0.6      # m, from the camera to its target
TARGET_HEIGHT = 0.75  # m
VIEW_TURN_DEG = 40.0
#: The manual's part of each render: left, top, width, height in pixels from the image's top
#: left (where the largest sheet curls out of the rim, its outline against the background),
#: halved to 320 x 360.
CROP = (300, 360, 640, 720)


def surfaces():
    return sorted((o for o in bpy.data.objects if o.type == 'SURFACE'), key=lambda o: o.name)


def tessellation(ob):
    """World vertices of the evaluated sheet as (u samples, v samples, 3)."""
    import numpy as np
    ev = ob.evaluated_get(bpy.context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    try:
        co = np.empty(len(me.vertices) * 3, dtype=np.float64)
        me.vertices.foreach_get("co", co)
    finally:
        ev.to_mesh_clear()
    sp = ob.data.splines[0]
    nu, nv = sp.point_count_u * sp.resolution_u, sp.point_count_v * sp.resolution_v
    m = np.array(ob.matrix_world)
    return (co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]).reshape(nu, nv, 3)


def closeup_target():
    """(target, camera location) of the close-up on the current frame's sheets."""
    import numpy as np
    from mathutils import Matrix, Vector
    sheet = max(surfaces(), key=lambda o: len(o.data.splines[0].points))
    co = np.array([tuple(p.co)[:3] for p in sheet.data.splines[0].points])
    co = co @ np.array(sheet.matrix_world)[:3, :3].T + np.array(sheet.matrix_world)[:3, 3]
    target = Vector(co[np.argmin(np.abs(co[:, 2] - TARGET_HEIGHT))])
    out = Vector((target.x, target.y, 0.0))
    out = out.normalized() if out.length > 1e-6 else Vector((0.0, -1.0, 0.0))
    out = Matrix.Rotation(math.radians(VIEW_TURN_DEG), 3, 'Z') @ out
    return target, target + DISTANCE * out


def closeup_camera(scene):
    """The WIDTH x HEIGHT close-up camera on the current frame's sheets, made the scene camera."""
    from mathutils import Vector
    cam = bpy.data.objects.new("Closeup", bpy.data.cameras.new("Closeup"))
    scene.collection.objects.link(cam)
    target, location = closeup_target()
    cam.location = location
    view = Vector(target) - Vector(location)
    cam.rotation_euler = view.to_track_quat('-Z', 'Y').to_euler()
    cam.data.lens = 50.0
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    bpy.context.view_layer.update()
    return cam


def render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return path


def crop(path, out_path):
    """The CROP of a render, halved (2 x 2 pixel means: the manual's image stays small), as its
    own PNG."""
    import numpy as np
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    x0, top, cw, ch = CROP
    y0 = h - top - ch  # Blender's rows run bottom to top
    part = px.reshape(h, w, 4)[y0:y0 + ch, x0:x0 + cw]
    part = part.reshape(ch // 2, 2, cw // 2, 2, 4).mean(axis=(1, 3))
    cw, ch = cw // 2, ch // 2
    out = bpy.data.images.new("plume_crop", cw, ch, alpha=True)
    out.pixels.foreach_set(np.ascontiguousarray(part).ravel())
    out.filepath_raw = out_path
    out.file_format = 'PNG'
    out.save()
    bpy.data.images.remove(out)
    return out_path


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    before = os.path.abspath(argv[1]) if len(argv) > 1 else None
    os.makedirs(out_dir, exist_ok=True)
    scene = scene_kit.new_scene()
    dom = newcomer_scene("//plume_cache/")
    scene_kit.camera(scene, (0.0, -4.5, 1.0), target=(0.0, 0.0, 1.0))
    scene_kit.dark_studio(scene)
    scene_kit.save_blend(out_dir, "sheet_closeup")
    scene_kit.select([dom], dom)
    scene_kit.run_op(bpy.ops.plume.bake, "closeup", "the bake")
    scene_kit.run_op(bpy.ops.plume.surfaces_build, "closeup", "Build Surfaces")
    smoke = bpy.data.objects.get(dom.plume.domain.volume_object)
    if smoke is not None:
        smoke.hide_render = True
    scene.frame_set(FRAMES)
    closeup_camera(scene)
    assert bpy.ops.plume.surfaces_fast_render() == {'FINISHED'}
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    bpy.ops.wm.save_mainfile()

    from plume.build import surfaces as build
    try:
        from plume.build import sheet_detail
    except ImportError:  # an add-on from before the camera sizing
        sheet_detail = None
    sized = sheet_detail.resolutions if sheet_detail is not None else None
    paths = [crop(before, os.path.join(out_dir, "sheet_closeup_before_crop.png"))] if before else []
    for tag in ("fixed", "camera") if sheet_detail is not None else ("fixed",):
        if sheet_detail is not None:  # "fixed": the resolutions used without a camera
            sheet_detail.resolutions = sized if tag == "camera" else (lambda *a, **k: None)
        scene.frame_set(FRAMES)
        nets = ", ".join(f"{o.data.splines[0].point_count_u}x{o.data.splines[0].point_count_v} "
                         f"order {o.data.splines[0].order_u}x{o.data.splines[0].order_v} "
                         f"res {o.data.splines[0].resolution_u}x{o.data.splines[0].resolution_v}"
                         for o in surfaces())
        ms = ", ".join(f"{1000 * s:.2f}" for s in build.last_update_seconds)
        t0 = time.perf_counter()
        full = render(scene, os.path.join(out_dir, f"sheet_closeup_{tag}.png"))
        paths.append(crop(full, os.path.join(out_dir, f"sheet_closeup_{tag}_crop.png")))
        print(f"closeup {tag}: {nets}; handler {ms} ms per surface; render "
              f"{time.perf_counter() - t0:.1f} s -> {full}", flush=True)
    if sheet_detail is not None:
        sheet_detail.resolutions = sized
    print(scene_kit.strip(paths, os.path.join(out_dir, "sheet_closeup_strip.png")), flush=True)


if __name__ == "__main__":
    main()
