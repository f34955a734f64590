"""The toon manual's "Recipe: a cartoon puff", steps 1-6 (F12 is the artist's).
`blender_tests/test_recipe_toon.py` performs it and checks the puffs and their outlines;
`bash .ci/screenshots` saves its panel picture. See examples/recipe_kit.py."""

import math

import bpy

from recipe_kit import Shot, new_file, press, sphere_domain

CAMERA_LOCATION, CAMERA_ROTATION_DEG = (0.0, -5.5, 1.0), (90.0, 0.0, 0.0)
RENDER_FRAME = 45


def steps(cache_dir):
    """Yields the recipe's Shot; returns the domain."""
    yield from new_file()                                         # 1. File › New › General
    domain = sphere_domain(cache_dir)                             # 2-3. source and domain
    press(bpy.ops.plume.bake)                                     #    Bake
    scene = bpy.context.scene
    cam = scene.camera                                            # 4. the camera first
    cam.location = CAMERA_LOCATION
    cam.rotation_euler = tuple(math.radians(a) for a in CAMERA_ROTATION_DEG)
    for ob in bpy.context.view_layer.objects:                     # 5. select the domain
        ob.select_set(ob == domain)
    bpy.context.view_layer.objects.active = domain
    press(bpy.ops.plume.toon_build)                               #    Build Toon Smoke
    yield Shot("ui_toon_panel.png", scroll=1500, open=("PHYSICS_PT_plume_toon",))
    domain.hide_render = True                                     # 6. domain and Volume unticked
    bpy.data.objects[domain.plume.domain.volume_object].hide_render = True
    scene.frame_set(RENDER_FRAME)                                 #    frame 45
    return domain
