"""The state of a submitted farm graph, read from the markers its tasks leave and from `squeue`
(no accounting database needed): per task and index one of QUEUED, RUNNING, DONE, FAILED (with
the last lines of its log) or MISSING (never submitted, cancelled, or the job vanished)."""

import os
import subprocess
from dataclasses import dataclass, field
from typing import Dict, List

from . import slurm

QUEUED, RUNNING, DONE, FAILED, MISSING = "QUEUED", "RUNNING", "DONE", "FAILED", "MISSING"
#: Submitted, not ended, and squeue did not answer (a busy or restarting controller): not known
#: to be missing, so nothing gives up on it.
UNKNOWN = "UNKNOWN"
#: States after which a task changes no more by itself.
ENDED = frozenset((DONE, FAILED, MISSING))
#: squeue's states, mapped (a requeued or suspended task is waiting to run again).
_SQUEUE = {"PENDING": QUEUED, "REQUEUED": QUEUED, "REQUEUE_HOLD": QUEUED, "REQUEUE_FED": QUEUED,
           "SUSPENDED": QUEUED, "CONFIGURING": RUNNING, "RUNNING": RUNNING,
           "COMPLETING": RUNNING, "RESIZING": RUNNING, "STAGE_OUT": RUNNING,
           "SIGNALING": RUNNING}
LOG_LINES = 12


@dataclass
class TaskState:
    name: str
    label: str
    states: Dict[int, str] = field(default_factory=dict)   # index -> state
    jobs: Dict[int, str] = field(default_factory=dict)     # index -> Slurm job id, if submitted
    failures: Dict[int, List[str]] = field(default_factory=dict)  # index -> last log lines

    @property
    def summary(self):
        """The task's state: FAILED if any index failed, else the least advanced one's."""
        values = set(self.states.values())
        for s in (FAILED, MISSING, UNKNOWN, QUEUED, RUNNING):
            if s in values:
                return s
        return DONE


def _squeue_argv(job_ids):
    return ["squeue", "-h", "-r", "-j", ",".join(sorted(job_ids)), "-o", "%F %K %T"]


def _parse(text):
    found = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1].isdigit():
            found[(parts[0], int(parts[1]))] = parts[2]
    return found


def queue(job_ids):
    """{(array job id, index): squeue state} of the given jobs' tasks still in the queue, or
    None when squeue did not answer (missing, timed out, or an error such as a busy
    controller's "Socket timed out": an empty answer then would read as every task gone)."""
    if not job_ids:
        return {}
    try:
        out = subprocess.run(_squeue_argv(job_ids), capture_output=True, text=True,
                             timeout=slurm.SLURM_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return _parse(out.stdout) if out.returncode == 0 else None


class Poll:
    """squeue run in the background: start() returns at once, result() is None until it has
    answered, then read()'s [TaskState] (the panel's timer asks every few seconds)."""

    def __init__(self, root):
        self.root = root
        record = slurm.load_record(root)
        self.jobs = sorted({j for t in record.values() for j in t.values()})
        self.proc = None
        if self.jobs:
            try:
                self.proc = subprocess.Popen(_squeue_argv(self.jobs), stdout=subprocess.PIPE,
                                             stderr=subprocess.DEVNULL, text=True)
            except OSError:
                self.proc = None

    def result(self):
        if self.proc is not None and self.proc.poll() is None:
            return None
        queued = {} if not self.jobs else NO_ANSWER
        if self.proc is not None:
            text = self.proc.stdout.read()
            self.proc.stdout.close()
            if self.proc.returncode == 0:
                queued = _parse(text)
        return read(self.root, queued)


def last_lines(path, n=LOG_LINES):
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - 16384))
            return f.read().decode("utf-8", "replace").splitlines()[-n:]
    except OSError:
        return []


#: read()'s `queued` when squeue was asked and did not answer.
NO_ANSWER = "no answer"


def read(root, queued=None):
    """[TaskState] of the farm folder's graph, in graph order. `queued` is queue()'s answer
    when the caller already has it (the panel polls squeue in the background), NO_ANSWER when
    squeue did not answer (a submitted task without its marker is then UNKNOWN); None asks."""
    graph = slurm.farm_graph.load(root)
    record = slurm.load_record(root)
    if queued is None:
        queued = queue({j for t in record.values() for j in t.values()})
    answered = isinstance(queued, dict)
    queued = queued if answered else {}
    result = []
    for task in graph.tasks:
        ts = TaskState(task.name, task.label or task.name)
        jobs = record.get(task.name, {})
        for i in range(task.count):
            if os.path.exists(slurm.marker(root, task.name, i)):
                ts.states[i] = DONE
                continue
            job = jobs.get(str(i))
            if job:
                ts.jobs[i] = job
            in_queue = queued.get((job, i)) if job else None
            if in_queue is not None:
                ts.states[i] = _SQUEUE.get(in_queue, RUNNING)
            elif os.path.exists(slurm.marker(root, task.name, i, ok=False)):
                ts.states[i] = FAILED
                ts.failures[i] = last_lines(slurm.log_path(root, task.name, i))
            elif job and not answered:
                ts.states[i] = UNKNOWN
            else:
                ts.states[i] = MISSING
        result.append(ts)
    return result


def pending(states):
    """{task: {index: job id}} of what is queued or running, for slurm.submit()."""
    return {ts.name: {i: ts.jobs[i] for i, s in ts.states.items()
                      if s in (QUEUED, RUNNING, UNKNOWN)}
            for ts in states}
