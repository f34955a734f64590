"""The README's first recipe, "Your first effect in ten minutes: a candle", steps 1-8 (step 9,
the render, is the artist's F12). `blender_tests/test_recipe_candle.py` performs it and checks
the flame; `bash .ci/screenshots` saves its panel picture. See examples/recipe_kit.py."""

import bpy

from recipe_kit import Shot, flame_view, new_file, press

WAX = dict(radius=0.012, depth=0.08, location=(0.0, 0.0, 0.04))
WICK = dict(vertices=8, radius=0.0008, depth=0.008, location=(0.0, 0.0, 0.082))
FRAME_END = 48
CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS = (0.0, -0.34, 0.1), (90.0, 0.0, 0.0), 50.0


def steps(cache_dir):
    """Yields the recipe's Shots; returns the wick."""
    yield from new_file()                                   # 1. File › New › General, no cube
    press(bpy.ops.mesh.primitive_cylinder_add, **WAX)       # 2. the wax
    press(bpy.ops.mesh.primitive_cylinder_add, **WICK)      # 3. the wick
    wick = bpy.context.view_layer.objects.active
    wick.name = "Wick"
    press(bpy.ops.plume.role_set, role='FLAME_SOURCE')      # 4. Physics › Plume › Flame Source
    scene = bpy.context.scene
    flames = scene.plume_flames
    flames.frame_end = FRAME_END                            # 5. Flames › End 48
    flames.cache_directory = cache_dir
    yield Shot("ui_flame_source.png")
    press(bpy.ops.plume.flames_bake)                        #    Bake Flames
    flame_view(CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS,  # 6-8. camera, black world,
               FRAME_END)                                  #    Cycles, frame 48, Auto Exposure
    return wick
