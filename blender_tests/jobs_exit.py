"""Run by test_jobs.py (test_11) in a Blender (``blender -b --python``) or a bpy module's Python:
starts a 200-frame bake in its child process, as a button does, and ends the script while the
child is inside the solver, with no cancel. Blender's exit (atexit: jobs/handlers.py) kills the
child, and the kernel would anyway (PR_SET_PDEATHSIG): the process exits 0 at once, no child
outlives it, and the bake stopped with whole frames, not run to its end.

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
from plume.jobs.process import JobProcess  # noqa: E402
from plume.operators.bake import BakeJob  # noqa: E402

job = BakeJob()
job.prepare(bpy.context)
JobProcess(job).start()
t0 = time.perf_counter()
while job.progress().done < 2 and time.perf_counter() - t0 < 60:
    job.child.poll()
    time.sleep(0.01)
print(f"exiting with the child (pid {job.child.pid}) at frame {job.progress().done} of {FRAMES}",
      flush=True)
