"""The job command: runs one job file without Blender, no ``bpy``.

    python -m plume.job run <cache folder or job file>

It is the child every long operator starts (process.py) and the unit of work a farm runs. The
job's work (kinds.py) runs on a thread of this process while its main thread reports progress,
answers SIGTERM / SIGINT (cancel: the work stops at its next unit) and keeps the cache folder's
lock alive; a fatal signal dumps the Python stacks into the log (faulthandler). Started by
Blender (``--parent PID``): the child dies with its parent (PR_SET_PDEATHSIG), reports on the
pipe ``--report-fd`` as JSON lines, and the parent holds the folder's lock. Run by hand or by a
farm: it takes the lock itself and prints its progress.

Exit status: 0 the job ran (its result file written; cancelled or not), 1 it failed (the error
reported and printed), 2 the job file cannot be run (usage, damaged, from a newer Plume).
Two variables are read by the child only, for the tests: PLUME_JOB_FAULT="<what>@<n>" makes it
fail when its progress reaches n units (segv, abort, kill as the out-of-memory killer does, exit
with status 7, raise, hang); PLUME_JOB_GATE="<file>@<n>" holds it at n units until <file>
exists (at most GATE_S; a cancel goes through), so that a windowed test can act on a job of a
small scene before it ends."""

import argparse
import ctypes
import faulthandler
import json
import os
import signal
import sys
import threading
import time
import traceback

from ..files import no_room
from ..settings import BakeError
from . import folder_lock, jobfile, kinds
from .runner import JobCancelled

#: Seconds between two progress reports (and lock refreshes) of the main thread.
REPORT_S = 0.1
FAULT_ENV = "PLUME_JOB_FAULT"
GATE_ENV = "PLUME_JOB_GATE"
GATE_S = 10.0
_PR_SET_PDEATHSIG = 1


class ChildJob:
    """What a work function sees: set_progress(), cancelled / check_cancel(), watch() native
    objects that cancel(), on_cancel() hooks, follow() a progress source polled by the main
    thread (a native job's own progress)."""

    def __init__(self, fault=None, gate=None):
        self._gate = gate
        self._cancel = threading.Event()
        self._lock = threading.Lock()
        self._hooks = []
        self._progress = None  # nothing reported yet: Blender keeps what prepare() said
        self._source = None
        self._fault = fault

    def set_progress(self, done, total, label=None, seconds_left=None):
        if label is None:
            label = self._progress[2] if self._progress is not None else ""
        self._progress = (int(done), int(total), label, seconds_left)
        self._source = None
        if self._fault is not None and total > 0 and done >= self._fault[1]:
            _inject(self._fault[0])
        if self._gate is not None and total > 0 and done >= self._gate[1]:
            path, self._gate = self._gate[0], None
            end = time.monotonic() + GATE_S
            while not os.path.exists(path) and not self.cancelled and time.monotonic() < end:
                time.sleep(0.01)

    def follow(self, source):
        """source() -> (done, total, label) is polled instead of set_progress' values."""
        self._source = source

    def progress(self):
        source = self._source
        if source is not None:
            try:
                done, total, label = source()
                return (int(done), int(total), label, None)
            except Exception:
                pass
        return self._progress

    def on_cancel(self, hook):
        with self._lock:
            self._hooks.append(hook)
        if self._cancel.is_set():
            hook()

    def watch(self, native_object):
        self.on_cancel(native_object.cancel)
        return native_object

    def cancel(self):
        self._cancel.set()
        with self._lock:
            hooks = list(self._hooks)
        for hook in hooks:
            hook()

    @property
    def cancelled(self):
        return self._cancel.is_set()

    def check_cancel(self):
        if self._cancel.is_set():
            raise JobCancelled()


def _at_units(name):
    """(what, n) of a "<what>@<n>" variable, or None."""
    what, _, n = os.environ.get(name, "").rpartition("@")
    if not what:
        return None
    return what, int(n or 1)


def _inject(what):
    print(f"plume job: injected fault '{what}' ({FAULT_ENV})", file=sys.stderr, flush=True)
    if what == "segv":
        faulthandler._sigsegv()
    elif what == "abort":
        os.abort()
    elif what == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    elif what == "exit":
        os._exit(7)
    elif what == "hang":
        while True:
            time.sleep(1.0)
    raise RuntimeError(f"injected fault ({FAULT_ENV}={what})")


def _die_with_parent(parent):
    """The kernel kills this process when Blender (the thread that started it) ends."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:  # the parent ended before the prctl
        os._exit(1)


class _Reporter:
    """Progress and the end of the job: JSON lines on the parent's pipe, or text on stdout."""

    def __init__(self, fd, title):
        self.fd, self.title = fd, title
        self._last = None
        self._printed = 0.0

    def send(self, message):
        if self.fd is None:
            return
        data = (json.dumps(message) + "\n").encode("utf-8")
        try:
            while data:
                data = data[os.write(self.fd, data):]
        except OSError:  # the parent is gone: the death signal follows
            pass

    def progress(self, p):
        if p is None or p == self._last:
            return
        self._last = p
        if self.fd is not None:
            self.send({"progress": list(p)})
            return
        now = time.monotonic()
        if now - self._printed >= 2.0 and p[1] > 0:
            self._printed = now
            print(f"Plume {self.title}: {p[2]} {p[0]} of {p[1]}", flush=True)


def _error_message(exc):
    """The error line the parent turns back into an exception."""
    errno_ = getattr(exc, "errno", None) if isinstance(exc, OSError) else None
    kind = ("BakeError" if isinstance(exc, BakeError)
            else "OSError" if isinstance(exc, OSError) else type(exc).__name__)
    return {"error": str(exc), "type": kind, "errno": errno_,
            "no_room": no_room(exc)}


def run_job(job_file, report_fd=None, parent=None):
    """Runs a job file; the exit status (see the module docstring)."""
    if parent is not None:
        _die_with_parent(parent)
    faulthandler.enable(file=sys.stderr, all_threads=True)
    try:
        header, spec, folder = jobfile.read_job(job_file)
        work = kinds.KINDS[header["kind"]]
    except (jobfile.JobFileError, KeyError) as e:
        print(f"plume job: {e}", file=sys.stderr, flush=True)
        return 2
    title, kind = header.get("title", header["kind"]), header["kind"]
    reporter = _Reporter(report_fd, title)
    job = ChildJob(_at_units(FAULT_ENV), _at_units(GATE_ENV))
    lock = None
    if parent is None:  # by hand or on a farm: one writer per folder, as in Blender
        try:
            lock = folder_lock.acquire(folder, f"{title} (job command)")
        except BakeError as e:
            print(str(e), file=sys.stderr, flush=True)
            return 1
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: job.cancel())
    # A write past the file size limit (ulimit -f, a farm's quota) fails with EFBIG and is
    # reported as such, instead of SIGXFSZ ending the job without a word.
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    out = {}

    def work_thread():
        try:
            out["result"] = work(spec, job)
        except JobCancelled:
            out["result"] = None
        except BaseException as e:  # reported below (after a cancel: the way it stopped)
            if job.cancelled:
                out["result"] = None
                return
            out["error"] = e
            if not isinstance(e, BakeError) and no_room(e) is None:
                traceback.print_exc()

    print(f"plume job: {title} ({kind}) in {folder}, pid {os.getpid()}", flush=True)
    thread = threading.Thread(target=work_thread, name=f"plume {kind}")
    thread.start()
    try:
        while thread.is_alive():
            thread.join(REPORT_S)
            reporter.progress(job.progress())
            if lock is not None:
                lock.keep_alive()
        if "error" in out:
            message = _error_message(out["error"])
            reporter.send(message)
            print(f"plume job: failed: {message['error']}", file=sys.stderr, flush=True)
            return 1
        paths = jobfile.job_paths(folder, os.path.basename(job_file)[:-len(".json")])
        jobfile.dump(out.get("result"), paths["result"], paths["result_npz"], folder,
                     {"kind": kind, "cancelled": job.cancelled})
        reporter.send({"done": True, "cancelled": job.cancelled})
        print(f"plume job: {title} {'cancelled' if job.cancelled else 'done'}", flush=True)
        return 0
    finally:
        if lock is not None:
            lock.release()


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m plume.job",
        description="Run a Plume job (a bake, Build Surfaces, ...) written by Blender into a "
                    "cache folder, without Blender.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run the job of a cache folder (or a job file)")
    run.add_argument("target", help="cache folder holding one job, or its jobs/<kind>.json")
    run.add_argument("--report-fd", type=int, default=None, help=argparse.SUPPRESS)
    run.add_argument("--parent", type=int, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    try:
        job_file = jobfile.find_job(args.target)
    except (jobfile.JobFileError, OSError) as e:
        print(f"plume job: {e}", file=sys.stderr)
        return 2
    return run_job(job_file, args.report_fd, args.parent)
