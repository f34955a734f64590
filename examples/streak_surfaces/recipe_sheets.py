"""The streak manual's "Recipe: smoke sheets, and a hand edit", steps 1-6 (F12 is the artist's).
`blender_tests/test_recipe_sheets.py` performs it and checks the sheets and the edit;
`bash .ci/screenshots` saves its panel pictures. See examples/recipe_kit.py."""

import math

import bpy

from recipe_kit import Shot, new_file, press, sphere_domain

CAMERA_LOCATION, CAMERA_ROTATION_DEG = (0.0, -4.5, 1.0), (90.0, 0.0, 0.0)
RENDER_FRAME = 60
STREAK_PANEL = ("PHYSICS_PT_plume_streaks",)
#: Step 6: on frame 30, three control points of the first sheet's middle row, a third of the way
#: along it, moved by (0.1, 0, 0.05) m (G, then typed or dragged).
EDIT_FRAME = 30
MOVE = (0.1, 0.0, 0.05)


def sheets(cache_dir):
    """Steps 1-5: the sheets, rendered from the camera on frame 60. Returns (domain, sheets)."""
    yield from new_file()                                         # 1. File › New › General
    domain = sphere_domain(cache_dir, streaks=True)               # 2-3. source, domain, ticks
    yield Shot("ui_streak_domain.png", scroll=1500,
                                                                   open=STREAK_PANEL)               #    Streak Surfaces panel
    press(bpy.ops.plume.bake)                                     #    Bake
    press(bpy.ops.plume.surfaces_build)                           # 4. Build Surfaces
    press(bpy.ops.plume.surfaces_fast_render)                     #    Fast Sheet Render
    yield Shot("ui_streak_built.png", scroll=1500,
                                                                  open=STREAK_PANEL)                #    the panel after the build
    scene = bpy.context.scene
    cam = scene.camera                                            # 5. the camera
    cam.location = CAMERA_LOCATION
    cam.rotation_euler = tuple(math.radians(a) for a in CAMERA_ROTATION_DEG)
    domain.hide_render = True                                     #    domain and Volume unticked
    bpy.data.objects[domain.plume.domain.volume_object].hide_render = True
    scene.frame_set(RENDER_FRAME)
    found = sorted((o for o in bpy.data.objects if o.type == 'SURFACE'), key=lambda o: o.name)
    return domain, found


def edited_points(sheet):
    """The control points step 6 moves: three of the middle row, a third of the way along."""
    sp = sheet.data.splines[0]
    nu = sp.point_count_u
    return [(sp.point_count_v // 2) * nu + u for u in range(nu // 3, nu // 3 + 3)]


def hand_edit(sheet):
    """Step 6: frame 30, click the sheet, Tab, move three control points, Tab back."""
    scene = bpy.context.scene
    scene.frame_set(EDIT_FRAME)
    bpy.ops.object.select_all(action='DESELECT')                  # click the sheet
    sheet.select_set(True)
    bpy.context.view_layer.objects.active = sheet
    yield Shot("ui_sheet_panel.png", tab='DATA')                  # its own panel
    moved = edited_points(sheet)
    press(bpy.ops.object.mode_set, mode='EDIT')                   # Tab
    sp = sheet.data.splines[0]  # the edit-mode net
    for k in moved:                                               # select, G
        x, y, z, w = sp.points[k].co
        sp.points[k].co = (x + MOVE[0], y + MOVE[1], z + MOVE[2], w)
    press(bpy.ops.object.mode_set, mode='OBJECT')                 # Tab back
    return moved


def steps(cache_dir):
    """The whole recipe, as the manual lists it."""
    _domain, found = yield from sheets(cache_dir)
    yield from hand_edit(found[0])
