"""The jobs running now, by the keys they hold, no ``bpy``.

A key names what one job at a time may work on: ("domain", name) for a domain's bake, surfaces,
toon smoke, flow graph and synthesis, ("flames",) for the scene's flames bake. A second job on a
held key is refused with the holder's busy_text(); Free Bake and the panels ask busy().
abort_all() stops every job for a file load or quit: cancel, wait for the worker, discard."""

import traceback

from ..settings import BakeError

#: key -> the JobRunner holding it
_held = {}

#: Called as listener(runner) each time release() runs, i.e. whenever a job ends (finished,
#: failed, refused, cancelled or aborted): the panels' cache state is read again from there.
ended = []

#: Seconds abort_all() waits for a cancelled worker (cancel acts within one unit of work).
ABORT_WAIT_S = 30.0


def claim(runner, keys):
    """Gives `keys` to `runner`; BakeError (nothing held) when another job holds one."""
    for key in keys:
        holder = _held.get(key)
        if holder is not None and holder is not runner:
            raise BakeError(holder.busy_text())
    for key in keys:
        _held[key] = runner
    runner.keys = tuple(runner.keys) + tuple(k for k in keys if k not in runner.keys)


def release(runner):
    """Frees every key of `runner` (no-op when it holds none) and its cache folder locks."""
    runner.release_folders()
    for key in list(runner.keys):
        if _held.get(key) is runner:
            del _held[key]
    for listener in list(ended):
        try:
            listener(runner)
        except Exception:  # a listener never stops a job from ending
            traceback.print_exc()


def holder(key):
    """The JobRunner holding `key`, or None."""
    return _held.get(key)


def busy(key):
    return key in _held


def running():
    """Every running JobRunner, once each."""
    out = []
    for runner in _held.values():
        if runner not in out:
            out.append(runner)
    return out


def abort(runner, wait_s=None):
    """Stops a job from outside its operator: cancel, wait up to `wait_s` (ABORT_WAIT_S) for its
    worker thread, remove its temporaries, free its keys. Its operator then ends without touching
    the scene. A worker still running after the wait removes the temporaries itself when it ends
    (worker.py; at quit, worker.stop_all() waits for it)."""
    runner.aborted = True
    runner.outcome = 'aborted'
    runner.cancel()
    worker = getattr(runner, "worker", None)
    if worker is None or worker.join(ABORT_WAIT_S if wait_s is None else wait_s):
        runner.discard()
    release(runner)


def abort_all(wait_s=None):
    """abort() for every running job (file load, quit, add-on disabled); how many."""
    jobs = running()
    for runner in jobs:
        runner.aborted = True
        runner.cancel()  # all at once, then wait: they stop in parallel
    for runner in jobs:
        abort(runner, wait_s)
    return len(jobs)
