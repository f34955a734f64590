"""Jobs: every long Plume operation (bake, flames bake, Build Surfaces, toon build, graph build,
fire synthesis, mesh export) as one runner protocol and one operator mixin.

- runner.py   JobRunner: forecast() (how long, before it starts), prepare() (main thread, snapshot + validation), run() (worker thread, no
              bpy), main_steps() and finish() (main thread, Blender data); cancel(), progress()
- operator.py JobOperator: execute() blocking, invoke() worker thread + modal timer + status bar
              + Esc; cancel() when Blender drops the handler
- worker.py   the thread run() executes on (not a daemon: every live worker is cancelled and
              joined before Python finalizes, see its docstring)
- registry.py which jobs run, by the keys they hold (one job per domain at a time)
- folder_lock.py one writer per cache folder (.plume.lock: host, pid, job; flock; stale takeover)
- staging.py  new files kept in a hidden folder until the job succeeds (atomic renames)
- handlers.py file load, quit and add-on disable abort the running jobs; undo and redo hold them
- quiet.py    workers stand still at their next unit while Blender undoes or redoes (no Python
              thread may run then: Blender reads the GIL holder's thread state without the GIL)
"""

from . import handlers, quiet, registry
from .operator import JobOperator
from .runner import Forecast, JobCancelled, JobProgress, JobRunner
from .staging import Staging
from .worker import Worker

__all__ = ("JobOperator", "JobRunner", "Forecast", "JobProgress", "JobCancelled", "Staging",
           "Worker", "registry", "register", "unregister")


def register():
    handlers.register()


def unregister():
    handlers.unregister()
