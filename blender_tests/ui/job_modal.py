"""Runs inside a windowed Blender (under Xvfb, started by test_ui_jobs.py with
--enable-event-simulate): Plume's jobs as an artist runs them, from a button, and what the artist
may do while they run.

    blender --factory-startup --enable-event-simulate --python job_modal.py -- RESULT TMP CASE...

TMP is the run's temporary folder (its "shared" folder keeps the prerequisite bakes between
cases and processes). Each CASE is <operator>:<action>, run in order (job_cases.py has the
operators and their scenes):

    operator  bake, flames, surfaces, toon, graph (Build Flow Graph), synth (Synthesize Fire)
    action    esc      press Esc once the job has made progress
              load     open another .blend file
              undo     move an unrelated object, push an undo step, undo it (memfile undo
                       replaces every datablock the job's scene had)
              redo     the same, then redo
              delete   delete the object the job works on
              rename   rename it
              settings change its main settings (job_cases.change_settings)
              free     the pipeline's Free (plume.cache_free, plume.flames_free)
              save     save the .blend file under a new name
              quit     quit Blender (the last case: it ends the process)
              quit0    the same with the operator's wait for its child cut to 0 s
                       (registry.ABORT_WAIT_S): the child is killed and not waited for;
                       it must still not outlive Blender
              A+quit   action A, then quit Blender at the next poll while the job still runs
              ask      the job is made "long" (LONG_JOB_S = 0): the button opens a dialog saying
                       how long; Return starts the job, which then runs to its end
              decline  the same dialog answered with Esc: nothing starts

A case sets its scene up, invokes the operator from the Properties editor's context
('INVOKE_DEFAULT': the job's child process + modal timer), polls the job until it has done a few
units and the status bar shows them with the time left, acts, waits for the job to end, and
records what it saw: the job's progress over time, its child's pid, how the job ended and its
report, the
seconds from the action to its end, the scene's objects and the cache folder's files before and
after. RESULT (JSON) is rewritten after every case (and before quitting), so a crash still leaves
the cases before it."""

import contextlib
import json
import os
import sys
import time
import traceback

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]
from helpers import enable_addon, pid_alive, tree_listing  # noqa: E402
import job_cases  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:]
RESULT, TMP, CASES = ARGS[0], ARGS[1], [tuple(c.split(":")) for c in ARGS[2:]]
SHARED = os.path.join(TMP, "shared")
CASE_LIMIT_S = 120.0
POLL_S = 0.05

state = {"case": -1, "phase": "next", "results": [], "t0": time.perf_counter(),
         "gate_open": True}


def save(**extra):
    with open(RESULT, "w") as f:
        json.dump({"cases": state["results"], "tmp": TMP, **extra}, f)


def window_and_area():
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = 'PROPERTIES'
    return win, area


@contextlib.contextmanager
def override():
    """The window context for an operator call from a timer (as a script calls one)."""
    win, area = window_and_area()
    with bpy.context.temp_override(window=win, area=area, screen=win.screen):
        yield


def close_gate(operator):
    """The job's child will hold once it has reported TRIGGER units, until open_gate() (or a
    cancel, or 10 s: PLUME_JOB_GATE, jobs/child.py): on a fast, quiet machine the small
    scenes' jobs (a 0.3 s flow graph) would otherwise end before the status bar has shown their
    progress and the action could come. Only the wait is added; the job's work is unchanged,
    and once released the child goes straight back into its next (native) unit, where the
    action finds it."""
    # One name per process and case: TMP is shared by the matrix process and the quit ones.
    state["gate_file"] = os.path.join(TMP, f"gate_{os.getpid()}_{state['case']}")
    os.environ["PLUME_JOB_GATE"] = f"{state['gate_file']}@{job_cases.TRIGGER[operator]}"
    state["gate_open"] = False


def open_gate():
    state["gate_open"] = True
    path = state.get("gate_file")
    if path and not os.path.exists(path):
        open(path, "w").close()


def job():
    from plume.jobs import registry
    jobs = registry.running()
    return jobs[0] if jobs else None


def start_case():
    operator, action = CASES[state["case"]]
    enable_addon()
    os.makedirs(SHARED, exist_ok=True)
    t0 = time.perf_counter()
    ob, cache = job_cases.set_up(operator, TMP, SHARED)
    marker = bpy.data.objects.new("Marker", None)  # what undo / redo move
    bpy.context.scene.collection.objects.link(marker)
    rec = {"operator": operator, "action": action, "cache": cache, "seen": [],
           "object": ob.name, "set_up_s": round(time.perf_counter() - t0, 2),
           "objects_before": sorted(o.name for o in bpy.data.objects),
           "files_before": tree_listing(cache)}
    state["results"].append(rec)
    if action == "load":
        path = os.path.join(TMP, "other.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
        rec["other_file"] = path
    with override():
        bpy.ops.ed.undo_push(message="Plume test scene")
    from plume.jobs import operator as job_operator
    long_job_s = job_operator.LONG_JOB_S
    if action in ("ask", "decline"):
        job_operator.LONG_JOB_S = 0.0  # every forecast is "long": the dialog opens
    close_gate(operator)
    try:
        with override():
            op = getattr(bpy.ops.plume, job_cases.OPERATORS[operator][0])
            rec["invoke"] = sorted(op('INVOKE_DEFAULT'))
    finally:
        job_operator.LONG_JOB_S = long_job_s
    j = job()
    rec["job_title"] = j.title if j else None
    state["job"] = j
    state.update(phase="running", case_t0=time.perf_counter(), acted_at=None)


def call(rec, operator, **kw):
    """Calls an operator as a button would (window context); its result, or the error it
    reported (bpy.ops raises RuntimeError for an ERROR report)."""
    try:
        with override():
            return sorted(operator(**kw))
    except RuntimeError as e:
        return str(e).strip()


def act(rec, j):
    """The artist's action on the running job (A+quit: A now, quit at the next poll)."""
    action, operator = rec["action"].split("+")[0], rec["operator"]
    if "+" in rec["action"]:
        state["then"] = rec["action"].split("+")[1]
    rec["done_at_action"] = j.progress().done
    rec["ran_in_child"] = j.child is not None and j.child.pid != os.getpid()
    rec["child_pid"] = j.child.pid if j.child is not None else None
    state["acted_at"] = time.perf_counter()
    open_gate()
    ob = bpy.data.objects[rec["object"]]
    if action == "esc":
        win = bpy.context.window_manager.windows[0]
        win.event_simulate(type='ESC', value='PRESS')
        win.event_simulate(type='ESC', value='RELEASE')
    elif action == "load":
        bpy.ops.wm.open_mainfile(filepath=rec["other_file"], load_ui=False)
    elif action in ("undo", "redo"):
        bpy.data.objects["Marker"].location.x += 1.0
        with override():
            bpy.ops.ed.undo_push(message="Move Marker")
        rec["undo"] = call(rec, bpy.ops.ed.undo)
        if action == "redo":
            rec["redo"] = call(rec, bpy.ops.ed.redo)
        rec["marker_x"] = bpy.data.objects["Marker"].location.x
    elif action == "delete":
        bpy.data.objects.remove(ob, do_unlink=True)
    elif action == "rename":
        ob.name = rec["object"] + " renamed"
    elif action == "settings":
        job_cases.change_settings(operator, ob)
    elif action == "free":
        rec["free"] = call(rec, getattr(bpy.ops.plume, job_cases.OPERATORS[operator][1]))
    elif action == "save":
        rec["saved_file"] = os.path.join(TMP, f"saved_{operator}.blend")
        rec["objects_at_save"] = sorted(o.name for o in bpy.data.objects)
        rec["save"] = call(rec, bpy.ops.wm.save_as_mainfile, filepath=rec["saved_file"])
    elif action in ("quit", "quit0"):
        if action == "quit0":
            from plume.jobs import registry
            registry.ABORT_WAIT_S = 0.0
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
    open_gate()


def end_case(rec):
    """The job has ended: how, and what it left behind."""
    j = state["job"]
    rec["seconds_to_stop"] = time.perf_counter() - state["acted_at"]
    if j is not None:
        rec["seconds_to_cancel"] = (j.cancelled_at - state["acted_at"]) if j.cancelled_at else None
        child = j.child
        rec["seconds_child_ran_on"] = (child.ended_at - state["acted_at"]
                                       if child is not None and child.ended_at else None)
        rec["outcome"], rec["report"] = j.outcome, j.report_text
        rec["child_alive"] = child is not None and pid_alive(child.pid)
    rec["objects_after"] = sorted(o.name for o in bpy.data.objects)
    rec["files_after"] = tree_listing(rec["cache"])
    rec["leftovers"] = job_cases.leftovers(rec["cache"])
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
                   resolution=m["resolution"],
                   vdb_files=sorted(n for n in os.listdir(folder) if n.endswith(".vdb")))
    if rec["operator"] == "flames":
        with open(os.path.join(rec["cache"], "flames_manifest.json")) as f:
            m = json.load(f)
        spines = bpy.data.objects.get(bpy.context.scene.plume_flames.spines_object)
        rec.update(baked_light_unit=m["settings"]["light_unit"],
                   lights_light_unit=spines.get("plume_flames_light_unit") if spines else None)
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
            rec["ran_in_child"] = j.child is not None and j.child.pid != os.getpid()
            rec["child_pid"] = j.child.pid if j.child is not None else None
        elif state["job"] is None and rec["action"] == "ask" and \
                time.perf_counter() - state["acted_at"] < 5.0:
            return POLL_S  # Return not handled yet
    if j is not None and state.get("then") == "quit":
        rec["done_at_quit"] = j.progress().done
        save(quitting=True)
        bpy.ops.wm.quit_blender()
        return None
    if j is not None:
        p = j.progress()
        rec["seen"].append([round(time.perf_counter() - state["case_t0"], 3), p.done, p.total,
                            p.label, j.status_text])
        # Act once the job has done a few units and the status bar has shown them.
        if (state["acted_at"] is None and p.total > 0
                and p.done >= job_cases.TRIGGER[rec["operator"]]
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
