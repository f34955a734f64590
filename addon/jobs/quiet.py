"""Workers hold still while Blender undoes or redoes, or a script calls an operator under a
context override; no ``bpy``.

An operator called from Python runs with the GIL released, and Blender then asks whether Python
is active (PyC_IsInterpreterActive -> PyThreadState_GetDict) without the GIL, e.g. to look a
context override up: when a worker thread holds the GIL at that instant, the answer is the
worker's thread state, and Blender's main thread touches Python objects while the worker runs
Python: the heap breaks. Seen as Blender 3.4.1 crashing while a job ran and the UI test called
Undo or started a job under a context override (about 1 run in 4 of test_ui_jobs; two cores:
SIGSEGV on the main thread in PyDict_New <- _PyThreadState_GetDict <- PyC_IsInterpreterActive,
and in PyDict_GetItemString, both inside an operator call). A third crash, in a redo, is not
explained by this (the issue's note).

So undo_pre/redo_pre (handlers.py) hold the workers: each running worker stops at its next unit
of work (park(), from JobRunner.set_progress), waiting on a Condition, which releases the GIL,
and Blender undoes with no Python thread running; undo_post/redo_post let them go on. A worker
inside a long native call is waited for at most PARK_WAIT_S (a native call that released the GIL
runs no Python until it returns, then parks)."""

import contextlib
import threading
import time

#: Longest an undo waits for a worker to reach its next unit (then it goes ahead anyway).
PARK_WAIT_S = 5.0
#: Longest a worker stays parked: a hold whose release never comes (an undo_post Blender skipped)
#: must not freeze the job for good.
PARKED_MAX_S = 60.0

_cond = threading.Condition()
_holds = 0
_parked = set()  # thread idents of parked workers


def park():
    """A worker between two units of work: blocks while an undo or redo holds the workers (the
    GIL released). Nothing on the main thread (a blocking job)."""
    if threading.current_thread() is threading.main_thread():
        return
    with _cond:
        if _holds == 0:
            return
        me = threading.get_ident()
        _parked.add(me)
        _cond.notify_all()
        end = time.monotonic() + PARKED_MAX_S
        while _holds > 0 and time.monotonic() < end:
            _cond.wait(end - time.monotonic())
        _parked.discard(me)


def hold(running, timeout=PARK_WAIT_S):
    """Main thread, before an undo: workers stop at their next unit; waits until every thread
    ident that `running()` returns is parked (or has ended), at most `timeout` seconds. True
    when all are still."""
    global _holds
    with _cond:
        _holds += 1
        deadline = time.monotonic() + timeout
        while True:
            if all(t in _parked for t in running()):
                return True
            left = deadline - time.monotonic()
            if left <= 0.0:
                return False
            _cond.wait(min(left, 0.05))


def release():
    """After the undo: the workers go on."""
    global _holds
    with _cond:
        _holds = max(0, _holds - 1)
        _cond.notify_all()


def release_all():
    """Quit or unregister: no hold may outlive the handlers that would release it."""
    global _holds
    with _cond:
        _holds = 0
        _cond.notify_all()


@contextlib.contextmanager
def held(timeout=PARK_WAIT_S):
    """Workers parked for the duration: for a script calling an operator under
    ``bpy.context.temp_override`` while a Plume job runs in the background. Blender (3.4-5.x)
    looks the override's members up in Python from the operator with the GIL released, asking
    whether Python is active by reading the GIL holder's thread state, so a worker running Python
    then breaks the heap (two cores of the windowed UI test: SIGSEGV in PyDict_New and in
    PyDict_GetItemString under BPY_context_member_get's PyC_IsInterpreterActive). A worker the
    call starts (an INVOKE of a Plume operator) parks before its first step."""
    from . import worker  # worker imports this module
    hold(worker.running_threads, timeout)
    try:
        yield
    finally:
        release()
