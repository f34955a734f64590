"""What stops running jobs from outside their operators: loading another file (a persistent
load_pre handler), quitting (Blender drops the modal handlers first, which calls the operators'
cancel(); then Python's shutdown runs worker.stop_all() before it joins the worker threads, and
atexit covers the rest, e.g. the bpy module), and disabling the add-on."""

import atexit
import sys
import threading

import bpy

from . import quiet, registry, worker


@bpy.app.handlers.persistent
def load_pre(*_args):
    """Another file is loaded: its objects replace the ones the jobs work on."""
    registry.abort_all()


@bpy.app.handlers.persistent
def undo_pre(*_args):
    """Undo or redo: the workers hold still until it is done (quiet.py: no Python thread may run
    while Blender frees the datablocks)."""
    quiet.hold(worker.running_threads)


@bpy.app.handlers.persistent
def undo_post(*_args):
    quiet.release()


#: (handler list name, handler) of the undo and redo hold.
_UNDO_HANDLERS = (("undo_pre", undo_pre), ("redo_pre", undo_pre), ("undo_post", undo_post),
                  ("redo_post", undo_post))


def _at_exit():
    registry.abort_all()
    worker.stop_all()


def _register_shutdown_hook():
    """worker.stop_all() before Python joins the non-daemon worker threads at shutdown (that
    join comes before atexit, and would wait for an uncancelled job to finish). Once per
    process: threading keeps the hooks until it shuts down; the hook finds the worker module
    by name, so a reloaded add-on's workers are the ones stopped."""
    if getattr(threading, "_plume_stop_all", False):
        return
    hook = getattr(threading, "_register_atexit", None)  # CPython 3.9+
    if hook is None:
        return
    name = worker.__name__

    def stop_all():
        module = sys.modules.get(name)
        if module is not None:
            module.stop_all()

    hook(stop_all)
    threading._plume_stop_all = True


def register():
    if load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(load_pre)
    for name, handler in _UNDO_HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler not in handlers:
            handlers.append(handler)
    atexit.unregister(_at_exit)
    atexit.register(_at_exit)
    _register_shutdown_hook()


def unregister():
    registry.abort_all()
    while load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(load_pre)
    for name, handler in _UNDO_HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while handler in handlers:
            handlers.remove(handler)
    quiet.release_all()
    atexit.unregister(_at_exit)
