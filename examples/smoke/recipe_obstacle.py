"""The smoke manual's recipe "smoke flowing around an obstacle", steps 1-8 up to the render
(F12 is the artist's). `blender_tests/test_recipe_obstacle.py` performs it and checks the
smoke; `bash .ci/screenshots` saves its panel picture. See examples/recipe_kit.py."""

import math

import bpy

from recipe_kit import Shot, new_file, press, sphere_domain

#: The obstacle: a beam 0.5 x 1.6 x 0.5 m across the smoke's path above the Source (a 0.5 m
#: cube, Scale Y 3.2), seen end-on by the camera: the smoke must go round its sides.
OBSTACLE_SIZE, OBSTACLE_LOCATION = 0.5, (0.0, 0.0, 1.1)
OBSTACLE_SCALE = (1.0, 3.2, 1.0)
FRAME_END = 28
CAMERA_LOCATION, CAMERA_ROTATION_DEG = (0.0, -5.5, 1.0), (90.0, 0.0, 0.0)
#: Lit from the side against a dark sky, so the smoke reads white.
SUN_STRENGTH, SUN_ROTATION_DEG = 8.0, (50.0, 0.0, -40.0)
WORLD = (0.01, 0.012, 0.02, 1.0)


def steps(cache_dir):
    """Yields the recipe's Shots; returns (domain, obstacle)."""
    yield from new_file()                                    # 1. File › New › General, no cube
    domain = sphere_domain(cache_dir)                        # 2.-3. Source sphere, Domain cube
    domain.plume.domain.frame_end = FRAME_END                #    Settings › End 28
    press(bpy.ops.mesh.primitive_cube_add, size=OBSTACLE_SIZE,  # 4. the obstacle
          location=OBSTACLE_LOCATION)
    obstacle = bpy.context.view_layer.objects.active
    obstacle.name = "Obstacle"
    obstacle.scale = OBSTACLE_SCALE                          #    N › Item › Scale Y 3.2
    press(bpy.ops.plume.role_set, role='OBSTACLE')
    yield Shot("ui_obstacle.png")
    bpy.context.view_layer.objects.active = domain           # 5. Bake
    for ob in bpy.context.view_layer.objects:
        ob.select_set(ob == domain)
    press(bpy.ops.plume.bake)
    scene = bpy.context.scene
    cam = scene.camera                                       # 6. the camera
    cam.location = CAMERA_LOCATION
    cam.rotation_euler = tuple(math.radians(a) for a in CAMERA_ROTATION_DEG)
    domain.hide_render = True
    press(bpy.ops.object.light_add, type='SUN',              # 7. a sun, a dark sky
          rotation=tuple(math.radians(a) for a in SUN_ROTATION_DEG))
    bpy.context.view_layer.objects.active.data.energy = SUN_STRENGTH
    world = scene.world.node_tree.nodes["Background"]
    world.inputs["Color"].default_value = WORLD
    scene.render.engine = 'CYCLES'                           # 8. Cycles, frame 28
    scene.frame_set(FRAME_END)
    return domain, obstacle
