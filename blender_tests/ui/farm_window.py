"""Scene Properties › Plume Farm in a real window (test_farm.py runs it under Xvfb on a saved
shot whose farm settings are made): Plume enabled, the panel open in a Properties editor on the
Scene tab, then Submit pressed as its button does (the operator in the editor's context). From
then on a timer ticks every TICK_S and records when it ran, each state the panel's background
poll holds, and what the panel drew (its draw_job wrapped). When every task is done, failed or
missing, or after WAIT_S, the record is written as JSON and Blender quits.

Run: xvfb-run -a blender --factory-startup SHOT.blend --python farm_window.py -- RESULT.json GATE
(GATE: the file that releases a bake held by PLUME_JOB_GATE, made once the job shows running)
"""

import json
import os
import sys
import time
import traceback

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.dirname(HERE), os.path.join(os.path.dirname(os.path.dirname(HERE)),
                                                    "examples")]

from helpers import enable_addon  # noqa: E402

TICK_S = 0.05
WAIT_S = 240.0
RESULT, GATE = sys.argv[sys.argv.index("--") + 1:][:2]
REC = {"ticks": [], "polled": [], "drawn": [], "report": "", "error": ""}


def finish(code):
    with open(RESULT, "w", encoding="utf-8") as f:
        json.dump(REC, f)
    os._exit(code)  # a timer cannot quit through the operator in every Blender


def setup():
    enable_addon()
    import ui_screenshots
    from plume.ui import farm_panel
    ui_screenshots.open_panels({"SCENE_PT_plume_farm"})
    window = bpy.context.window_manager.windows[0]
    area = ui_screenshots.fresh_properties(window)
    area.spaces.active.context = 'SCENE'
    draw_job = farm_panel.draw_job

    def drawn(layout, folder):
        from plume.operators import farm as farm_ops
        states = farm_ops.LAST["states"]
        REC["drawn"].append([(ts.name, ts.summary) for ts in states] if states else None)
        return draw_job(layout, folder)
    farm_panel.draw_job = drawn  # the panel's draw() looks it up at each redraw
    return window, area


def submit(window, area):
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=window, area=area, region=region):
        t0 = time.monotonic()
        result = bpy.ops.plume.farm_submit()
        REC["submit_s"] = time.monotonic() - t0
    REC["submitted"] = sorted(result)
    REC["folder"] = bpy.context.scene.plume_farm.last_job


STATE = {"phase": 0, "end": 0.0}


def tick():
    try:
        now = time.monotonic()
        if STATE["phase"] == 0:
            STATE["window"], STATE["area"] = setup()
            STATE["phase"] = 1
            return 0.5  # the editor draws once before the button is pressed
        if STATE["phase"] == 1:
            submit(STATE["window"], STATE["area"])
            STATE["phase"], STATE["end"] = 2, now + WAIT_S
            return TICK_S
        from plume.operators import farm as farm_ops
        REC["ticks"].append(now)
        states = farm_ops.LAST["states"]
        summary = [(ts.name, ts.summary) for ts in states] if states else None
        if not REC["polled"] or REC["polled"][-1] != summary:
            REC["polled"].append(summary)
        ended = summary and all(s in ("DONE", "FAILED", "MISSING") for _, s in summary)
        if summary and not ended and not os.path.exists(GATE):
            open(GATE, "w").close()  # the job is shown running: its bake may go on
        drawn_ended = REC["drawn"] and REC["drawn"][-1] == summary
        if (ended and drawn_ended) or now > STATE["end"]:
            finish(0)
        return TICK_S
    except Exception:
        REC["error"] = traceback.format_exc()
        finish(1)


bpy.app.timers.register(tick, first_interval=1.0, persistent=True)
