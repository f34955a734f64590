"""Runs inside a windowed Blender (under Xvfb, started by test_ui_bake.py with
--enable-event-simulate): the UI path of plume.bake, as an artist uses it.

Invokes plume.bake from the Properties editor's context (worker thread + modal timer), waits for
a few frames, presses Esc with Window.event_simulate, waits for the operator to finish, and
writes what it saw to the JSON file named after `--`. Quits Blender when done (or after a time
limit)."""

import json
import os
import sys
import tempfile
import time
import traceback

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from helpers import add_domain, add_sphere_source, enable_addon, select_only  # noqa: E402

RESULT = sys.argv[sys.argv.index("--") + 1]
FRAMES = 200
LIMIT_S = 240.0
state = {"phase": "setup", "t0": time.perf_counter(), "seen": []}


def finish(**result):
    result["seen"] = state["seen"]
    with open(RESULT, "w") as f:
        json.dump(result, f)
    bpy.ops.wm.quit_blender()


def window_and_area():
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = 'PROPERTIES'
    return win, area


def domain_status():
    from plume.operators.bake import cache_status, is_baking
    dom = bpy.data.objects["Domain"]
    done, total = cache_status(dom)
    return done, total, is_baking(dom)


def tick():
    try:
        return step()
    except Exception:
        finish(error=traceback.format_exc())
        return None


def step():
    if time.perf_counter() - state["t0"] > LIMIT_S:
        finish(error=f"timed out in phase {state['phase']}")
        return None
    if state["phase"] == "setup":
        enable_addon()
        for ob in list(bpy.data.objects):
            bpy.data.objects.remove(ob, do_unlink=True)
        cache = tempfile.mkdtemp(prefix="plume_ui_")
        dom = add_domain(resolution=40, frame_end=FRAMES, cache_directory=cache + "/")
        add_sphere_source()
        select_only(dom)
        win, area = window_and_area()
        with bpy.context.temp_override(window=win, area=area, screen=win.screen):
            state["invoke"] = list(bpy.ops.plume.bake('INVOKE_DEFAULT'))
        state.update(phase="baking", cache=cache, pressed_at=None)
        return 0.2
    done, total, baking = domain_status()
    state["seen"].append([round(time.perf_counter() - state["t0"], 2), done, baking])
    if state["phase"] == "baking":
        if done >= 3:
            # The artist presses Esc over the Blender window.
            win = bpy.context.window_manager.windows[0]
            win.event_simulate(type='ESC', value='PRESS')
            win.event_simulate(type='ESC', value='RELEASE')
            state.update(phase="cancelling", done_at_esc=done, pressed_at=time.perf_counter())
        elif not baking and done >= total:
            finish(error="the bake finished before Esc could be pressed")
            return None
        return 0.05
    if state["phase"] == "cancelling" and not baking:
        vol = bpy.data.objects.get("Domain_smoke")
        with open(os.path.join(state["cache"], "Domain", "manifest.json")) as f:
            run = json.load(f)["last_run"]
        finish(invoke=state["invoke"], done_at_esc=state["done_at_esc"], done_after=done,
               done_at_cancel=run.get("frames_done_at_cancel"), cancelled=run.get("cancelled"),
               total=total, seconds_to_stop=time.perf_counter() - state["pressed_at"],
               volume_frames=vol.data.frame_duration if vol else None,
               vdb_files=sorted(n for n in os.listdir(os.path.join(state["cache"], "Domain"))
                                if n.endswith(".vdb")))
        return None
    return 0.05


bpy.app.timers.register(tick, first_interval=0.5)
