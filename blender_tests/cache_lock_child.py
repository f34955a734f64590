"""The second Blender of test_cache_lock.py (not a test file itself): started by the test as
``blender -b --factory-startup --python cache_lock_child.py -- MODE ARG`` (or the bpy module's
Python), it talks to the test over stdout lines and waits for the test on stdin.

    hold FOLDER   takes FOLDER's writer lock as a "Bake" job, prints "HELD <pid>", holds it until
                  stdin is closed (or the process is killed), releases it, prints "RELEASED"
    bake CACHE    bakes a small domain into CACHE; after its first frame it prints "BAKING <pid>"
                  and waits until stdin is closed, then finishes and prints "RESULT <result>"
    try CACHE     bakes the same domain into CACHE and prints "RESULT <result>" or
                  "REFUSED <message>"
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import add_domain, add_sphere_source, reset_scene, select_only  # noqa: E402

RESOLUTION = 16
FRAMES = 4


def say(line):
    print(line, flush=True)


def scene(cache):
    reset_scene()
    add_sphere_source()
    dom = add_domain(resolution=RESOLUTION, frame_end=FRAMES, cache_directory=cache + "/")
    select_only(dom)
    return dom


def hold(folder):
    from plume.jobs import folder_lock
    lock = folder_lock.acquire(folder, "Bake")
    say(f"HELD {os.getpid()}")
    sys.stdin.read()  # until the test closes it
    lock.release()
    say("RELEASED")


def bake(cache, wait_after_first_frame):
    from plume.operators.bake import BakeJob, PLUME_OT_bake
    scene(cache)
    job = BakeJob()

    said = []
    gate = os.path.join(cache, "gate")

    def first_frame(p):  # the bake's child waits at frame 1 (PLUME_JOB_GATE) until stdin closes
        if p.done >= 1 and not said:
            said.append(p.done)
            say(f"BAKING {os.getpid()}")
            sys.stdin.read()
            open(gate, "w").close()

    if wait_after_first_frame:
        job.on_progress = first_frame
        os.environ["PLUME_JOB_GATE"] = f"{gate}@1"
    PLUME_OT_bake.make_runner = lambda self, context: job
    try:
        say(f"RESULT {sorted(bpy.ops.plume.bake())}")
    except RuntimeError as e:
        say(f"REFUSED {str(e).strip()}")


def main():
    mode, arg = sys.argv[sys.argv.index("--") + 1:][:2]
    if mode == "hold":
        hold(arg)
    elif mode == "bake":
        bake(arg, wait_after_first_frame=True)
    elif mode == "try":
        bake(arg, wait_after_first_frame=False)
    else:
        raise SystemExit(f"cache_lock_child.py: unknown mode {mode!r}")
    bpy.ops.wm.read_homefile(use_factory_startup=True)


main()
