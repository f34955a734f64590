"""The farm from a terminal, for TDs (no Blender needed):

    python -m plume.farm status <job folder>          each task's state; failed ones' log tails
    python -m plume.farm wait <job folder> [SECONDS]  until every task is done (exit 0) or one
                                                      failed or went missing (exit 1)
    python -m plume.farm resubmit <job folder>        what is missing or failed, again
    python -m plume.farm cancel <job folder>          scancel the job's Slurm jobs
    python -m plume.farm openjd <job folder>          (re)writes the job's Open Job Description
                                                      template, job.openjd.json (no Slurm needed)

A job is submitted from its scene: Scene › Plume Farm › Submit, or headless
`blender -b shot.blend --python-expr "import bpy; bpy.ops.plume.farm_submit()"`."""

import os
import sys
import time

from . import graph as farm_graph
from . import openjd, slurm, status
from .graph import FarmError


def _print(states):
    for ts in states:
        counts = {}
        for s in ts.states.values():
            counts[s] = counts.get(s, 0) + 1
        text = ", ".join(f"{n} {s.lower()}" for s, n in sorted(counts.items()))
        print(f"{ts.name:14s} {ts.summary:8s} {ts.label} ({text})")
        for i, lines in sorted(ts.failures.items()):
            print(f"  [{i}] failed, last lines of logs/{ts.name}.{i}.log:")
            for line in lines:
                print("    " + line)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 2 or argv[0] not in ("status", "wait", "resubmit", "cancel",
                                           "openjd"):
        print(__doc__, file=sys.stderr)
        return 2
    cmd, root = argv[0], argv[1]
    try:
        if cmd == "status":
            _print(status.read(root))
        elif cmd == "wait":
            end = time.monotonic() + (float(argv[2]) if len(argv) > 2 else 86400.0)
            while True:
                states = status.read(root)
                summary = {ts.summary for ts in states}
                if summary <= {status.DONE} or summary & {status.FAILED, status.MISSING}:
                    _print(states)
                    return 0 if summary <= {status.DONE} else 1
                if time.monotonic() > end:
                    _print(states)
                    print("plume farm: still running", file=sys.stderr)
                    return 1
                time.sleep(1.0)
        elif cmd == "openjd":
            root = os.path.abspath(root)
            graph = farm_graph.load(root)
            cluster, farm_root = slurm.load_cluster(root)
            slurm.write_scripts(graph, root)
            path = openjd.write(graph, root, 60 * max(1, int(cluster.time_minutes))
                                if farm_root else None)
            print(path)
            print(f"run it with openjd-cli: openjd run {path}  (every task in order; the job "
                  f"folder is the template's, -p {openjd.FOLDER_PARAM}=PATH where the runner "
                  "sees it elsewhere)")
        elif cmd == "resubmit":
            print(slurm.resubmit(root, status.pending(status.read(root))))
        else:
            print(" ".join(slurm.cancel(root)))
    except FarmError as e:
        print(e, file=sys.stderr)
        return 1
    return 0
