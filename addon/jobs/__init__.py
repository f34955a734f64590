"""Jobs: every long Plume operation (bake, flames bake, Build Surfaces, toon build, graph build,
fire synthesis, mesh export) as one runner protocol, one operator mixin and one child process.
Only operator.py and handlers.py import ``bpy``: the rest is what the child runs too.

- runner.py   JobRunner: forecast() (how long, before it starts), prepare() (main thread,
              snapshot + validation), job_spec() (what the child needs), take_result(),
              main_steps() and finish() (main thread, Blender data); cancel(), progress()
- operator.py JobOperator: execute() blocking, invoke() in the background with a modal timer,
              status bar and Esc; cancel() when Blender drops the handler
- process.py  JobProcess: the child, seen from Blender (start, poll, cancel, kill, how it ended)
- child.py    the job command ``python -m plume.job run <cache folder>`` (the child itself)
- kinds.py    what the child computes, one function per job kind
- jobfile.py  the versioned job file in the cache folder (<folder>/jobs/<kind>.json + .npz)
- registry.py which jobs run, by the keys they hold (one job per domain at a time)
- folder_lock.py one writer per cache folder (.plume.lock: host, pid, job; flock; stale takeover)
- staging.py  new files kept in a hidden folder until the job succeeds (atomic renames)
- handlers.py file load, quit and add-on disable end the running jobs
"""

from . import registry
from .runner import Forecast, JobCancelled, JobProgress, JobRunner
from .staging import Staging

__all__ = ("JobRunner", "Forecast", "JobProgress", "JobCancelled", "Staging", "registry")
