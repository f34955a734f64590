"""Run by test_jobs.py (test_11) in a Blender (``blender -b --python``) or a bpy module's Python:
starts a 200-frame bake on a worker thread, as a button does, and ends the script while the
worker is inside the solver, with no cancel. Python's shutdown must cancel and join the worker
(jobs/worker.py stop_all()): the process exits 0 within a frame or so, neither aborting (a worker
left in native code at finalization) nor running the bake to its end (a non-daemon thread
nobody cancelled).

    blender -b --factory-startup --python jobs_exit.py -- CACHE
    python jobs_exit.py -- CACHE          (bpy module)
"""

import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import add_domain, add_sphere_source, reset_scene, select_only  # noqa: E402

FRAMES = 200

cache = sys.argv[sys.argv.index("--") + 1]
reset_scene()
dom = add_domain(resolution=40, frame_end=FRAMES, cache_directory=cache + "/")
add_sphere_source()
select_only(dom)
from plume.jobs import Worker  # noqa: E402
from plume.operators.bake import BakeJob  # noqa: E402

job = BakeJob()
job.prepare(bpy.context)
Worker(job).start()
t0 = time.perf_counter()
while job.progress().done < 2 and time.perf_counter() - t0 < 60:
    time.sleep(0.01)
print(f"exiting with the worker at frame {job.progress().done} of {FRAMES}", flush=True)
