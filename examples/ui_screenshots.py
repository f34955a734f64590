"""Screenshots of the real panels for the manuals' recipes, taken in a windowed Blender (timers
and screen operators need a window; `bash .ci/screenshots` runs this under Xvfb):

    xvfb-run -a -s "-screen 0 960x1000x24" blender --python examples/ui_screenshots.py -- \
        OUT_ROOT [RECIPE ...]

Runs every recipe `examples/<pipeline>/recipe_<name>.py` (or those named, e.g. `candle`) through
its own steps (examples/recipe_kit.py) and, at each Shot it yields, maximizes the editor the Shot
names, shows its tab, lets Blender draw it and saves it as OUT_ROOT/<pipeline>/images/<image>.
Prints each path with the Blender version (the manuals' captions say which Blender drew it),
then quits; a recipe step that fails quits with status 1.
"""

import glob
import importlib.util
import os
import shutil
import sys
import tempfile
import traceback

import bpy

EXAMPLES = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, EXAMPLES)
#: Timer steps (0.3 s) given to Blender to draw an editor before it is saved.
SETTLE_STEPS = 4


def recipes(names):
    """[(pipeline folder, recipe module)] of every recipe file, or of those named."""
    found = []
    for path in sorted(glob.glob(os.path.join(EXAMPLES, "*", "recipe_*.py"))):
        name = os.path.basename(path)[len("recipe_"):-3]
        if names and name not in names:
            continue
        folder = os.path.dirname(path)
        sys.path.insert(0, folder)  # a recipe may import its pipeline's kit
        spec = importlib.util.spec_from_file_location(f"recipe_{name}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        found.append((os.path.basename(folder), module))
    missing = set(names) - {m.__name__[len("recipe_"):] for _, m in found}
    if missing:
        raise SystemExit(f"ui_screenshots: no recipe named {', '.join(sorted(missing))}")
    return found


def viewport(window):
    """The context of a click in the 3D Viewport, where a recipe's steps happen."""
    area = max((a for a in window.screen.areas if a.type == 'VIEW_3D'),
               key=lambda a: a.width * a.height, default=None)
    if area is None:  # maximized Properties: the steps run in the window's context
        return dict(window=window, screen=window.screen)
    region = next(r for r in area.regions if r.type == 'WINDOW')
    return dict(window=window, screen=window.screen, area=area, region=region)


#: Panels open_panels() opened: {class: its own bl_options}, restored for the next shot.
_OPENED = {}


def open_panels(names):
    """Panels an artist opened by a click on their header: registered again without
    DEFAULT_CLOSED (panel states are not in Blender's Python API), so they draw open; every
    other panel a previous shot opened is closed again. The add-on's panels after the first one
    changed are registered again too, so the order stays."""
    from plume import ui
    wanted = {}
    for cls in ui.classes:
        own = _OPENED.get(cls, set(getattr(cls, "bl_options", ())))
        wanted[cls] = own - {'DEFAULT_CLOSED'} if cls.__name__ in names else own
    changed = [c for c in ui.classes if set(getattr(c, "bl_options", ())) != wanted[c]]
    if not changed:
        return
    later = list(ui.classes[ui.classes.index(changed[0]):])
    for cls in reversed(later):
        bpy.utils.unregister_class(cls)
    for cls in changed:
        _OPENED.setdefault(cls, set(getattr(cls, "bl_options", ())))
        cls.bl_options = wanted[cls]
    for cls in later:
        bpy.utils.register_class(cls)


def fresh_properties(window):
    """A new Properties editor, maximized: the largest 3D Viewport is split and its new half,
    never a Properties editor before, becomes one, so it draws every panel for the first time
    (a panel takes DEFAULT_CLOSED or not only then; an editor that drew it keeps its state)."""
    screen = window.screen
    if len(screen.areas) == 1:
        with bpy.context.temp_override(window=window, area=screen.areas[0]):
            bpy.ops.screen.back_to_previous()
        screen = window.screen
    view3d = max((a for a in screen.areas if a.type == 'VIEW_3D'),
                 key=lambda a: a.width * a.height)
    before = {a.as_pointer() for a in screen.areas}
    with bpy.context.temp_override(window=window, area=view3d):
        bpy.ops.screen.area_split(direction='VERTICAL', factor=0.5)
    area = next(a for a in screen.areas if a.as_pointer() not in before)
    area.type = 'PROPERTIES'
    with bpy.context.temp_override(window=window, area=area):
        bpy.ops.screen.screen_full_area()
    return window.screen.areas[0]


def show(window, shot):
    """Maximizes the editor the shot names (restoring the layout first if another one is) and
    returns its area."""
    screen = window.screen
    if len(screen.areas) == 1 and screen.areas[0].type != shot.editor:
        with bpy.context.temp_override(window=window, area=screen.areas[0]):
            bpy.ops.screen.back_to_previous()
        screen = window.screen
    area = max((a for a in screen.areas if a.type == shot.editor),
               key=lambda a: a.width * a.height)
    if len(screen.areas) > 1:
        with bpy.context.temp_override(window=window, area=area):
            bpy.ops.screen.screen_full_area()
        area = window.screen.areas[0]
    if shot.editor == 'PROPERTIES':
        area.spaces.active.context = shot.tab
    return area


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    out_root, names = os.path.abspath(args[0]), args[1:]
    to_run = recipes(names)
    # A fixed cache folder: the panels that show it draw the same text on every run.
    cache = os.path.join(tempfile.gettempdir(), "plume_screenshots")
    shutil.rmtree(cache, ignore_errors=True)
    state = {"recipe": 0, "steps": None, "shot": None, "settle": 0}

    def quit_with(code):
        sys.stdout.flush()
        if code:
            os._exit(code)  # a failed step: no save prompt, no half-made picture set
        bpy.ops.wm.quit_blender()

    def tick():
        try:
            window = bpy.context.window_manager.windows[0]
            if state["shot"] is None:  # the recipe's next steps, up to its next Shot
                if state["steps"] is None:
                    if state["recipe"] == len(to_run):
                        quit_with(0)
                        return None
                    folder, module = to_run[state["recipe"]]
                    state["folder"] = folder
                    state["steps"] = module.steps(os.path.join(cache, folder) + "/")
                try:
                    with bpy.context.temp_override(**viewport(window)):
                        state["shot"] = next(state["steps"])
                except StopIteration:
                    state["recipe"] += 1
                    state["steps"] = None
                    return 0.1
                if state["shot"] is None:  # a file was read: its screen is drawn first
                    return 0.3
                state["settle"] = 0
            shot = state["shot"]
            if state["settle"] == 0 and shot.open:  # panels an artist opened: a new editor
                open_panels(shot.open)
                area = fresh_properties(window)
                area.spaces.active.context = shot.tab
            elif state["settle"] == 0:
                open_panels(())
                area = show(window, shot)
            else:
                area = window.screen.areas[0]
            region = next(r for r in area.regions if r.type == 'WINDOW')
            with bpy.context.temp_override(window=window, area=area, region=region):
                if state["settle"] == 0:  # the top of the editor, no tooltip under the pointer
                    window.cursor_warp(0, 0)
                    for _ in range(100):
                        bpy.ops.view2d.scroll_up(page=True)
                elif state["settle"] == 1:  # once drawn, its height is known; 40 px a step
                    for _ in range(shot.scroll // 40):
                        bpy.ops.view2d.scroll_down()
            state["settle"] += 1
            if state["settle"] < SETTLE_STEPS:
                return 0.3
            path = os.path.join(out_root, state["folder"], "images", state["shot"].image)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with bpy.context.temp_override(window=window, area=area, region=region):
                bpy.ops.screen.screenshot_area(filepath=path)
            print(f"ui_screenshots: {path} (Blender {bpy.app.version_string})", flush=True)
            state["shot"] = None
            return 0.1
        except Exception:
            traceback.print_exc()
            quit_with(1)
            return None

    bpy.app.timers.register(tick, first_interval=1.0, persistent=True)


if __name__ == "__main__":
    main()
