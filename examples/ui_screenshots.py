"""Screenshots of the real panels for the README's candle recipe, taken in a windowed Blender
(timers and screen operators need a window; `.ci/screenshots` runs this under Xvfb):

    xvfb-run -a -s "-screen 0 1600x1000x24" blender --factory-startup \
        --python examples/ui_screenshots.py -- OUT_DIR

Builds the recipe's scene up to its Flame Source (the wick made one, with the Candle defaults),
then maximizes the Properties editor on each tab the recipe uses and saves it:
OUT_DIR/ui_flame_source.png (Properties › Physics › Plume with the wick selected: the Flame
Source and Flames panels, where the recipe presses Bake Flames and Auto Exposure). Prints each
path with the Blender version (the README's caption says which Blender drew it), then quits.
"""

import os
import sys

import bpy

#: (file name, Properties tab) of each screenshot, in order.
SHOTS = (("ui_flame_source.png", 'PHYSICS'),)
#: Timer steps (0.3 s) given to Blender to draw a tab before it is saved.
SETTLE_STEPS = 3


def recipe_scene():
    """The README's candle up to step 4: the wax and wick cylinders, the wick a Flame Source."""
    import addon_utils
    addon_utils.enable("plume", default_set=True)
    bpy.ops.object.select_all(action='SELECT')
    bpy.ops.object.select_by_type(type='MESH')
    bpy.ops.object.delete()
    bpy.ops.mesh.primitive_cylinder_add(radius=0.012, depth=0.08, location=(0.0, 0.0, 0.04))
    bpy.ops.mesh.primitive_cylinder_add(vertices=8, radius=0.0008, depth=0.008,
                                        location=(0.0, 0.0, 0.082))
    bpy.context.active_object.name = "Wick"
    if bpy.ops.plume.role_set(role='FLAME_SOURCE') != {'FINISHED'}:
        raise RuntimeError("ui_screenshots: could not make the wick a Flame Source")


def properties_area(window):
    return max((a for a in window.screen.areas if a.type == 'PROPERTIES'),
               key=lambda a: a.width * a.height)


def main():
    out_dir = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
    os.makedirs(out_dir, exist_ok=True)
    recipe_scene()
    window = bpy.context.window
    area = properties_area(window)
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screen_full_area()  # the Properties editor fills the window
    state = {"shot": 0, "step": 0}

    def tick():
        area = properties_area(window)
        name, tab = SHOTS[state["shot"]]
        area.spaces.active.context = tab
        state["step"] += 1
        if state["step"] < SETTLE_STEPS:
            return 0.3
        region = next(r for r in area.regions if r.type == 'WINDOW')
        path = os.path.join(out_dir, name)
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=path)
        print(f"ui_screenshots: {path} (Blender {bpy.app.version_string})", flush=True)
        state["shot"] += 1
        state["step"] = 0
        if state["shot"] == len(SHOTS):
            bpy.ops.wm.quit_blender()
            return None
        return 0.3

    bpy.app.timers.register(tick, first_interval=1.0)


if __name__ == "__main__":
    main()
