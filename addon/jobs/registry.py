"""The jobs running now, by the keys they hold, no ``bpy``.

A key names what one job at a time may work on: ("domain", name) for a domain's bake, surfaces,
toon smoke, flow graph and synthesis, ("flames",) for the scene's flames bake. A second job on a
held key is refused with the holder's busy_text(); Free Bake and the panels ask busy().
abort_all() stops every job for a file load or quit: its child killed, its temporaries removed."""

import traceback

from ..settings import BakeError

#: key -> the JobRunner holding it
_held = {}

#: Called as listener(runner) each time release() runs, i.e. whenever a job ends (finished,
#: failed, refused, cancelled or aborted): the panels' cache state is read again from there.
ended = []

#: Seconds abort() waits for a killed child to be reaped.
ABORT_WAIT_S = 10.0


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
    """Stops a job from outside its operator (file load, quit, add-on disabled): its child is
    killed at once (a bake's complete frames stay; nothing else it wrote was moved into place),
    its temporaries are removed and its keys freed. Its operator then ends without touching the
    scene."""
    runner.aborted = True
    runner.outcome = 'aborted'
    child = getattr(runner, "child", None)
    if child is not None:
        child.join(ABORT_WAIT_S if wait_s is None else wait_s)
    runner.discard()
    release(runner)


def abort_all(wait_s=None):
    """abort() for every running job (file load, quit, add-on disabled); how many."""
    jobs = running()
    for runner in jobs:
        runner.aborted = True
        if getattr(runner, "child", None) is not None:
            runner.child.kill()  # all at once, then reap: they end in parallel
    for runner in jobs:
        abort(runner, wait_s)
    return len(jobs)
