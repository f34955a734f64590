"""The flames manual's recipe "a campfire", steps 1-10 (step 11, the render, is the artist's F12):
the ground, a log made a Flame Source from the Campfire preset, copied into two crossed layers
of two logs, Bake Flames, the camera, a black world, Auto Exposure.
`blender_tests/test_recipe_campfire.py` performs it and checks the flames; `bash .ci/screenshots`
saves its panel picture. See examples/recipe_kit.py."""

import math

import bpy

from recipe_kit import Shot, flame_view, new_file, press

GROUND = dict(size=4.0)
LOG = dict(radius=0.05, depth=0.55, location=(0.0, -0.09, 0.05),
           rotation=(0.0, math.radians(90.0), 0.0))
SECOND_LOG = (0.0, 0.18, 0.0)        # Shift+D, Y 0.18
UPPER_LAYER = (0.0, 0.0, 0.1)        # both logs: Shift+D, Z 0.1, then R Z 90
FRAME_END = 20
CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS = (0.0, -3.8, 0.95), (86.0, 0.0, 0.0), 35.0


def steps(cache_dir):
    """Yields the recipe's Shots; returns the four logs."""
    yield from new_file()                                   # 1. File › New › General, no cube
    press(bpy.ops.mesh.primitive_plane_add, **GROUND)       # 2. the ground
    press(bpy.ops.mesh.primitive_cylinder_add, **LOG)       # 3. the first log
    first = bpy.context.view_layer.objects.active
    first.name = "Log"
    press(bpy.ops.plume.role_set, role='FLAME_SOURCE')      # 4. Physics › Plume › Flame Source,
    press(bpy.ops.plume.flame_preset, preset='CAMPFIRE')    #    Preset › Campfire
    scene = bpy.context.scene
    flames = scene.plume_flames
    flames.frame_end = FRAME_END                            #    Flames › End 20
    flames.cache_directory = cache_dir
    yield Shot("ui_campfire_preset.png")
    press(bpy.ops.object.duplicate_move,                    # 5. the second log: Shift+D, Y 0.18
          TRANSFORM_OT_translate=dict(value=SECOND_LOG))
    first.select_set(True)                                  # 6. both logs: Shift+D, Z 0.1,
    press(bpy.ops.object.duplicate_move,                    #    R Z 90
          TRANSFORM_OT_translate=dict(value=UPPER_LAYER))
    press(bpy.ops.transform.rotate, value=math.radians(90.0), orient_axis='Z')
    press(bpy.ops.plume.flames_bake)                        # 7. Flames › Bake Flames
    flame_view(CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS,  # 8-10. camera, black world,
               FRAME_END)                                  #    Cycles, frame 20, Auto Exposure
    return [ob for ob in scene.objects if ob.plume.role == 'FLAME_SOURCE']
