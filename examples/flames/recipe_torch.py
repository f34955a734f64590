"""The flames manual's recipe "a torch", steps 1-8 (step 9, the render, is the artist's F12):
a handle and a head, the head made a Flame Source from the Torch preset, Bake Flames, the camera,
a black world, Auto Exposure. `blender_tests/test_recipe_torch.py` performs it and checks the
flames; `bash .ci/screenshots` saves its panel picture. See examples/recipe_kit.py."""

import bpy

from recipe_kit import Shot, flame_view, new_file, press

HANDLE = dict(radius=0.015, depth=0.5, location=(0.0, 0.0, 0.75))
HEAD = dict(radius=0.04, location=(0.0, 0.0, 1.0))
FRAME_END = 24
CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS = (0.0, -1.8, 1.25), (90.0, 0.0, 0.0), 50.0


def steps(cache_dir):
    """Yields the recipe's Shots; returns the torch head."""
    yield from new_file()                                   # 1. File › New › General, no cube
    press(bpy.ops.mesh.primitive_cylinder_add, **HANDLE)    # 2. the handle
    press(bpy.ops.mesh.primitive_uv_sphere_add, **HEAD)     # 3. the head
    head = bpy.context.view_layer.objects.active
    head.name = "Torch Head"
    press(bpy.ops.plume.role_set, role='FLAME_SOURCE')      # 4. Physics › Plume › Flame Source,
    press(bpy.ops.plume.flame_preset, preset='TORCH')       #    Preset › Torch
    scene = bpy.context.scene
    flames = scene.plume_flames
    flames.frame_end = FRAME_END                            # 5. Flames › End 24
    flames.cache_directory = cache_dir
    yield Shot("ui_torch_preset.png")
    press(bpy.ops.plume.flames_bake)                        #    Bake Flames
    flame_view(CAMERA_LOCATION, CAMERA_ROTATION_DEG, LENS,  # 6-8. camera, black world,
               FRAME_END)                                  #    Cycles, frame 24, Auto Exposure
    return head
