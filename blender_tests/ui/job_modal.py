"""Runs inside a windowed Blender (under Xvfb, started by test_ui_jobs.py with
--enable-event-simulate): Plume's jobs as an artist runs them, from a button.

    blender --factory-startup --enable-event-simulate --python job_modal.py -- RESULT CASE...

Each CASE is <operator>:<action>, run in order:

    operator  bake (a 200-frame 40³ bake), surfaces (Build Surfaces), toon (Build Toon Smoke);
              surfaces and toon first bake a small streak scene (blocking), once, then reuse it
    action    esc     press Esc once the job has made progress
              delete  delete the domain while the job runs
              load    open another .blend file while the job runs
              quit    quit Blender while the job runs (the last case)
              ask     the job is made "long" (LONG_JOB_S = 0): the button opens a dialog
                      saying how long; Return starts the job, which then runs to its end
              decline the same dialog answered with Esc: nothing starts

A case sets its scene up, invokes the operator from the Properties editor's context
('INVOKE_DEFAULT': worker thread + modal timer), polls the job (its progress and status-bar line)
until it has done a few units and the status bar shows them with the time left, acts, waits for the
job to end, and records what it saw: the job's progress over time, the thread it ran on, the
seconds from the action to its end, and the scene's objects and the cache folder's files before and
after. RESULT (JSON) is rewritten after every case (and before quitting), so a crash still leaves
the cases before it."""

import json
import os
import sys
import tempfile
import threading
import time
import traceback

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from helpers import (add_domain, add_sphere_source, enable_addon, incense_streak_scene,  # noqa: E402
                     select_only, tree_listing)

ARGS = sys.argv[sys.argv.index("--") + 1:]
RESULT, CASES = ARGS[0], [tuple(c.split(":")) for c in ARGS[1:]]
OPERATORS = {"bake": "bake", "surfaces": "surfaces_build", "toon": "toon_build"}
#: Units of progress (frames, density maps) the job must report before the action.
TRIGGER = {"bake": 3, "surfaces": 2, "toon": 2}
CASE_LIMIT_S = 120.0
POLL_S = 0.05

state = {"case": -1, "phase": "next", "results": [], "t0": time.perf_counter(),
         "tmp": tempfile.mkdtemp(prefix="plume_ui_")}


def save(**extra):
    with open(RESULT, "w") as f:
        json.dump({"cases": state["results"], "tmp": state["tmp"], **extra}, f)


def window_and_area():
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = 'PROPERTIES'
    return win, area


def job():
    from plume.jobs import registry
    jobs = registry.running()
    return jobs[0] if jobs else None


def clear_objects():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)


def bake_scene(cache):
    """The old Esc test's scene: a 40³ domain over 200 frames, baked until Esc."""
    dom = add_domain(resolution=40, frame_end=200, cache_directory=cache + "/")
    add_sphere_source()
    return dom


def streak_scene(cache):
    """The shared small streak scene (24³, 60 frames, ~190 streaklines), baked blocking; the
    cache is complete after the first case, so later cases' bakes return at once."""
    dom = incense_streak_scene(cache, 24, 60)
    assert bpy.ops.plume.bake() == {'FINISHED'}
    return dom


def start_case():
    operator, action = CASES[state["case"]]
    enable_addon()
    clear_objects()
    if operator == "bake":
        cache = tempfile.mkdtemp(prefix="bake_", dir=state["tmp"])
        dom = bake_scene(cache)
    else:
        cache = os.path.join(state["tmp"], "streaks")
        dom = streak_scene(cache)
    select_only(dom)
    rec = {"operator": operator, "action": action, "cache": cache, "seen": [],
           "objects_before": sorted(o.name for o in bpy.data.objects),
           "files_before": tree_listing(cache)}
    state["results"].append(rec)
    if action == "load":
        path = os.path.join(state["tmp"], "other.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
        rec["other_file"] = path
    win, area = window_and_area()
    from plume.jobs import operator as job_operator
    long_job_s = job_operator.LONG_JOB_S
    if action in ("ask", "decline"):
        job_operator.LONG_JOB_S = 0.0  # every forecast is "long": the dialog opens
    try:
        with bpy.context.temp_override(window=win, area=area, screen=win.screen):
            rec["invoke"] = sorted(getattr(bpy.ops.plume, OPERATORS[operator])('INVOKE_DEFAULT'))
    finally:
        job_operator.LONG_JOB_S = long_job_s
    j = job()
    rec["job_title"] = j.title if j else None
    state["job"] = j
    state.update(phase="running", case_t0=time.perf_counter(), acted_at=None)


def act(rec, j):
    """The artist's action on the running job."""
    action = rec["action"]
    rec["done_at_action"] = j.progress().done
    rec["worker_is_main_thread"] = j.worker.thread_id == threading.main_thread().ident
    state["acted_at"] = time.perf_counter()
    if action == "esc":
        win = bpy.context.window_manager.windows[0]
        win.event_simulate(type='ESC', value='PRESS')
        win.event_simulate(type='ESC', value='RELEASE')
    elif action == "delete":
        bpy.data.objects.remove(bpy.data.objects["Domain"], do_unlink=True)
    elif action == "load":
        bpy.ops.wm.open_mainfile(filepath=rec["other_file"], load_ui=False)
    elif action == "quit":
        save(quitting=True)
        bpy.ops.wm.quit_blender()


def answer_dialog(rec):
    """ask/decline: the dialog is open and no job runs yet; Return (OK) or Esc answers it."""
    rec["job_before_answer"] = job() is not None
    key = 'RET' if rec["action"] == "ask" else 'ESC'
    win = bpy.context.window_manager.windows[0]
    win.event_simulate(type=key, value='PRESS')
    win.event_simulate(type=key, value='RELEASE')
    state["acted_at"] = time.perf_counter()


def end_case(rec):
    """The job has ended: what it left behind."""
    j = state["job"]
    rec["seconds_to_stop"] = time.perf_counter() - state["acted_at"]
    if j is not None:
        rec["seconds_to_cancel"] = (j.cancelled_at - state["acted_at"]) if j.cancelled_at else None
        rec["seconds_worker_ran_on"] = (j.worker.ended_at - state["acted_at"]
                                        if j.worker.ended_at else None)
    rec["objects_after"] = sorted(o.name for o in bpy.data.objects)
    rec["files_after"] = tree_listing(rec["cache"])
    if rec["operator"] == "bake":
        folder = os.path.join(rec["cache"], "Domain")
        with open(os.path.join(folder, "manifest.json")) as f:
            m = json.load(f)
        run = m["last_run"]
        vol = bpy.data.objects.get("Domain_smoke")
        rec.update(done_after=m["last_complete_frame"] - m["frame_start"] + 1,
                   done_at_cancel=run.get("frames_done_at_cancel"), cancelled=run.get("cancelled"),
                   total=m["frame_end"] - m["frame_start"] + 1,
                   volume_frames=vol.data.frame_duration if vol else None,
                   vdb_files=sorted(n for n in os.listdir(folder) if n.endswith(".vdb")))
    state["phase"] = "next"
    save()


def tick():
    try:
        return step()
    except Exception:
        save(error=traceback.format_exc())
        bpy.ops.wm.quit_blender()
        return None


def step():
    if state["phase"] == "next":
        state["case"] += 1
        if state["case"] >= len(CASES):
            save(finished=True)
            bpy.ops.wm.quit_blender()
            return None
        start_case()
        return POLL_S
    rec = state["results"][-1]
    if time.perf_counter() - state["case_t0"] > CASE_LIMIT_S:
        save(error=f"case {rec['operator']}:{rec['action']} timed out")
        bpy.ops.wm.quit_blender()
        return None
    j = job()
    if rec["action"] in ("ask", "decline"):
        if state["acted_at"] is None:
            answer_dialog(rec)
            return POLL_S
        if j is not None:
            state["job"] = j
            rec["job_title"] = j.title
            rec["worker_is_main_thread"] = j.worker.thread_id == threading.main_thread().ident
        elif state["job"] is None and rec["action"] == "ask" and \
                time.perf_counter() - state["acted_at"] < 5.0:
            return POLL_S  # Return not handled yet
    if j is not None:
        p = j.progress()
        rec["seen"].append([round(time.perf_counter() - state["case_t0"], 3), p.done, p.total,
                            p.label, j.status_text])
        # Act once the job has done a few units and the status bar has shown them.
        if (state["acted_at"] is None and p.total > 0 and p.done >= TRIGGER[rec["operator"]]
                and " s left" in j.status_text):
            act(rec, j)
        return POLL_S
    if state["acted_at"] is None:
        save(error=f"the job of case {rec['operator']}:{rec['action']} ended before the action")
        bpy.ops.wm.quit_blender()
        return None
    end_case(rec)
    return POLL_S


# persistent: the timer survives the "load" case's file load.
bpy.app.timers.register(tick, first_interval=0.5, persistent=True)
