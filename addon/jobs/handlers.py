"""What stops running jobs from outside their operators: loading another file (a persistent
load_pre handler), quitting (Blender drops the modal handlers first, which calls the operators'
cancel(); atexit covers the rest, e.g. the bpy module) and disabling the add-on. Each kills the
jobs' children and removes their temporaries; a child also dies with Blender itself
(PR_SET_PDEATHSIG, process.py), so none outlives it however Blender ends."""

import atexit

import bpy

from . import process, registry


@bpy.app.handlers.persistent
def load_pre(*_args):
    """Another file is loaded: its objects replace the ones the jobs work on."""
    registry.abort_all()


def _at_exit():
    registry.abort_all()
    process.kill_all()


def register():
    if load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(load_pre)
    atexit.unregister(_at_exit)
    atexit.register(_at_exit)


def unregister():
    registry.abort_all()
    process.kill_all()
    while load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(load_pre)
    atexit.unregister(_at_exit)
