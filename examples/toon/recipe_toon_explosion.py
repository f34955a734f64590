"""The toon manual's recipe "a cartoon explosion", steps 1-9 (step 10, the render, is the
artist's F12). `blender_tests/test_recipe_toon_explosion.py` performs it and checks the
picture; `bash .ci/screenshots` saves its panel pictures. See examples/recipe_kit.py."""

import math

import bpy

from recipe_kit import Shot, new_file, press, sphere_domain

#: The blast: the Source throws smoke up at 6 m/s on frame 1, and its Density and Initial
#: Velocity are keyed to 0 on frame BURST_FRAMES + 1 (Blender's default keys ease between the
#: two over the frames between). No heat and no Density Buoyancy: the blast is thrown, not
#: lifted, so it rolls out sideways and slows down.
VELOCITY = (0.0, 0.0, 6.0)
BURST_FRAMES = 3
FRAME_END = 36
DENSITY_BUOYANCY, VORTICITY = 0.0, 2.0
CAMERA_LOCATION, CAMERA_ROTATION_DEG = (0.0, -3.5, 1.1), (90.0, 0.0, 0.0)
#: Toon Smoke: coloured by speed, from orange (slow) to yellow (2.5 m/s and faster), with bold
#: lines (6 px at 1080 lines; 3 px at 540), also between billows 8 cm apart in depth.
DRIVER_LOW, DRIVER_HIGH = 0.3, 2.5
COLOR_LOW, COLOR_HIGH = (0.8, 0.1, 0.02, 1.0), (1.0, 0.75, 0.1, 1.0)
OUTLINE_WIDTH = 6.0
DEPTH_THRESHOLD = 0.08
SKY = (0.3, 0.5, 0.8, 1.0)
TOON_PANEL = ("PHYSICS_PT_plume_toon",)
SHOW_FRAME = 14


def steps(cache_dir):
    """Yields the recipe's Shots; returns the domain."""
    yield from new_file()                                    # 1. File › New › General, no cube
    domain = sphere_domain(cache_dir)                        # 2.-3. Source sphere, Domain cube
    d = domain.plume.domain
    d.frame_end = FRAME_END                                  # 3. Settings › End 36
    d.alpha, d.vorticity = DENSITY_BUOYANCY, VORTICITY       #    Forces
    scene = bpy.context.scene
    source = bpy.data.objects["Sphere"]                      # 4. the burst, keyed on the Source
    bpy.context.view_layer.objects.active = source
    for ob in bpy.context.view_layer.objects:
        ob.select_set(ob == source)
    s = source.plume.source
    s.temperature = 0.0
    for frame, on in ((1, True), (BURST_FRAMES + 1, False)):
        scene.frame_set(frame)
        s.density = 1.0 if on else 0.0
        s.velocity = VELOCITY if on else (0.0, 0.0, 0.0)
        for name in ("density", "velocity"):                 # I over each field
            source.keyframe_insert("plume.source." + name)
    scene.frame_set(1)
    yield Shot("ui_explosion_source.png")
    bpy.context.view_layer.objects.active = domain           # 5. Bake
    for ob in bpy.context.view_layer.objects:
        ob.select_set(ob == domain)
    press(bpy.ops.plume.bake)
    cam = scene.camera                                       # 6. the camera
    cam.location = CAMERA_LOCATION
    cam.rotation_euler = tuple(math.radians(a) for a in CAMERA_ROTATION_DEG)
    t = d.toon                                               # 7. Toon Smoke: colour, lines
    t.color_driver, t.color_low, t.color_high = 'SPEED', DRIVER_LOW, DRIVER_HIGH
    t.ramp_color_low, t.ramp_color_high = COLOR_LOW, COLOR_HIGH
    t.outline_width = OUTLINE_WIDTH
    t.depth_threshold = DEPTH_THRESHOLD
    press(bpy.ops.plume.toon_build)                          #    Build Toon Smoke
    yield Shot("ui_explosion_toon.png", scroll=1600, open=TOON_PANEL)
    domain.hide_render = True                                # 8. hide the domain and its smoke
    bpy.data.objects[d.volume_object].hide_render = True
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = SKY  # 9. the look
    scene.view_settings.view_transform = 'Standard'  # toon's flat colours: Filmic/AgX grey them
    scene.frame_set(SHOW_FRAME)
    return domain
