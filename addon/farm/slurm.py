"""Submits a farm job graph to Slurm: one `sbatch` job array per task (indices 0..count-1, or only
the missing ones on a resubmission), `--dependency=afterok` on the tasks it runs after
(`--kill-on-invalid-dep=yes`: when one fails, its dependants are cancelled instead of waiting
forever), `--requeue` (a preempted or requeued task starts again and its command resumes from
its own checkpoint), logs appended to `logs/<task>.<index>.log`. Each task runs through a small
bash script (`scripts/<task>.sh`) that exports PLUME_TASK_INDEX, runs the command and leaves
`state/<task>.<index>.ok` or `.failed` (the exit status) in the farm folder: a task's outcome is
known without Slurm's accounting database, on any cluster. Submissions are recorded in
`farm.json` (task → Slurm job id per index)."""

import json
import os
import shlex
import shutil
import subprocess
from dataclasses import dataclass

from ..files import atomic
from . import graph as farm_graph
from . import openjd
from .graph import FarmError

RECORD_NAME = "farm.json"
CLUSTER_NAME = "cluster.json"
#: Seconds a Slurm command may take before Plume gives up on the cluster (a hung controller).
SLURM_TIMEOUT_S = 30


@dataclass
class Cluster:
    """Where and how the tasks run (Scene › Plume Farm)."""
    partition: str = ""       # empty: the cluster's default partition
    account: str = ""         # empty: the user's default account
    time_minutes: int = 60    # each task's time limit
    cpus: int = 0             # CPUs per task; 0: each task's own (the graph's)


def save_cluster(root, cluster, farm_root):
    data = dict(vars(cluster), farm_root=farm_root)
    atomic.write_bytes(os.path.join(root, CLUSTER_NAME), json.dumps(data, indent=1).encode())


def load_cluster(root):
    """(Cluster, farm_root) saved by the job's first submission."""
    try:
        with open(os.path.join(root, CLUSTER_NAME), encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError):
        return Cluster(), None
    farm_root = data.pop("farm_root", None)
    return Cluster(**{k: v for k, v in data.items() if k in Cluster.__dataclass_fields__}), farm_root


def find_slurm():
    """The path of sbatch, or FarmError saying how to get it."""
    path = shutil.which("sbatch")
    if path is None:
        raise FarmError("Plume farm: Slurm's sbatch is not on this machine's PATH: install the "
                        "Slurm client (Debian: slurm-client) or submit from a machine of the "
                        "cluster")
    return path


def _run(argv, cwd=None):
    try:
        out = subprocess.run(argv, capture_output=True, text=True, timeout=SLURM_TIMEOUT_S,
                             cwd=cwd)
    except subprocess.TimeoutExpired:
        raise FarmError(f"Plume farm: `{' '.join(argv[:2])}` did not answer in "
                        f"{SLURM_TIMEOUT_S} s: is the Slurm controller up?") from None
    if out.returncode != 0:
        raise FarmError(f"Plume farm: `{' '.join(argv[:2])}` failed: "
                        f"{(out.stderr or out.stdout).strip()}")
    return out.stdout


def marker(root, task, index, ok=True):
    return os.path.join(root, "state", f"{task}.{index}.{'ok' if ok else 'failed'}")


def log_path(root, task, index):
    return os.path.join(root, "logs", f"{task}.{index}.log")


def done_indices(root, task):
    return {i for i in range(task.count) if os.path.exists(marker(root, task.name, i))}


def load_record(root):
    try:
        with open(os.path.join(root, RECORD_NAME), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def _save_record(root, record):
    atomic.write_bytes(os.path.join(root, RECORD_NAME),
                       json.dumps(record, indent=1, sort_keys=True).encode("utf-8"))


def task_script(task):
    """The batch script of a task: the index, the command, the marker. Every path in it is
    relative to the farm folder, its working directory, so a copy of the folder at another
    path runs as well (`cd COPY && bash scripts/<task>.sh`)."""
    name = task.name
    argv = " ".join(shlex.quote(a) for a in task.argv)
    return f"""#!/bin/bash
# Plume farm task '{name}' ({task.label or name}); made by plume.farm.slurm.
i="${{SLURM_ARRAY_TASK_ID:-${{PLUME_TASK_INDEX:-0}}}}"
export PLUME_TASK_INDEX="$i"
mkdir -p state logs
rm -f state/{name}."$i".failed
echo "== plume farm: {name}[$i] on $(hostname) (job ${{SLURM_JOB_ID:-none}}, restart ${{SLURM_RESTART_COUNT:-0}}) in $PWD"
cmd=()
for a in {argv}; do cmd+=("${{a//\\{{index\\}}/$i}}"); done
"${{cmd[@]}}"
rc=$?
if [ "$rc" -eq 0 ]; then
  echo "${{SLURM_JOB_ID:-}}" >state/.{name}."$i".tmp && mv state/.{name}."$i".tmp state/{name}."$i".ok
else
  echo "$rc" >state/{name}."$i".failed
fi
exit "$rc"
"""


def write_scripts(graph, root):
    """scripts/<task>.sh of every task of `graph` (the same text each time for the same graph):
    what Slurm runs, and what the job's Open Job Description template (openjd.py) runs."""
    os.makedirs(os.path.join(root, "scripts"), exist_ok=True)
    for task in graph.tasks:
        script = os.path.join(root, "scripts", f"{task.name}.sh")
        atomic.write_bytes(script, task_script(task).encode("utf-8"))
        os.chmod(script, 0o755)


def _array_spec(indices):
    return ",".join(str(i) for i in sorted(indices))


def submit(graph, root, cluster=None, pending=None, farm_root=None):
    """Submits what is missing of `graph` (saved into `root` first; `farm_root` is where the
    farm's machines see that folder, `root` itself by default). Tasks whose every index
    succeeded are skipped; indices still queued or running from an earlier submission
    (`pending`: {task: {index: job id}}, from status.py) are not submitted again, and
    dependants wait for them. Returns {task: job id} of this submission."""
    cluster = cluster or Cluster()
    sbatch = find_slurm()
    root = os.path.abspath(root)
    for sub in ("state", "logs", "scripts"):
        os.makedirs(os.path.join(root, sub), exist_ok=True)
    farm_graph.save(graph, root)
    save_cluster(root, cluster, farm_root or root)
    write_scripts(graph, root)
    openjd.write(graph, root, 60 * max(1, int(cluster.time_minutes)))  # the same job, for OpenJD
    pending = pending or {}
    record = load_record(root)
    waits = {}  # task -> job ids its dependants wait for
    submitted = {}
    for task in graph.tasks:
        running = pending.get(task.name, {})
        missing = [i for i in range(task.count)
                   if i not in done_indices(root, task) and i not in running]
        waits[task.name] = sorted(set(running.values()))
        if not missing:
            continue
        argv = [sbatch, "--parsable", f"--job-name=plume-{task.name}",
                f"--array={_array_spec(missing)}",
                f"--chdir={farm_root or root}", f"--output=logs/{task.name}.%a.log",
                "--open-mode=append", "--requeue", "--kill-on-invalid-dep=yes",
                f"--cpus-per-task={cluster.cpus or task.cpus}",
                f"--time={max(1, int(cluster.time_minutes))}"]
        if cluster.partition:
            argv.append(f"--partition={cluster.partition}")
        if cluster.account:
            argv.append(f"--account={cluster.account}")
        deps = sorted({j for a in task.after for j in waits.get(a, [])})
        if deps:
            argv.append("--dependency=afterok:" + ":".join(deps))
        job = _run(argv + [os.path.join("scripts", f"{task.name}.sh")], cwd=root)
        job = job.strip().split(";")[0]
        submitted[task.name] = job
        waits[task.name] = sorted(set(waits[task.name]) | {job})
        for i in missing:
            record.setdefault(task.name, {})[str(i)] = job
    _save_record(root, record)
    return submitted


def resubmit(root, pending):
    """Submits again what is missing or failed of the job in `root`, with its own cluster
    settings; what is queued or running (`pending`) is waited for, not doubled."""
    cluster, farm_root = load_cluster(root)
    return submit(farm_graph.load(root), root, cluster, pending, farm_root)


def cancel(root):
    """scancel every Slurm job of the job in `root`."""
    jobs = sorted({j for t in load_record(root).values() for j in t.values()})
    if jobs:
        _run(["scancel", *jobs])
    return jobs
