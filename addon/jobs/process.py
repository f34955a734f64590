"""A job's child process, seen from Blender, no ``bpy`` and no thread.

JobProcess writes the runner's job file (jobfile.py), starts ``python -m plume.job run`` on it
with the running Blender's own Python (child.py), and is polled from the main thread: by the
operator's modal timer (a button) or by a blocking loop (execute(), ``blender -b``). Progress
arrives as JSON lines on a pipe; the child's output goes to the job's log in the cache folder.

How the child ends decides the report: its result file (the job ran; finish() builds it), its
error line (bad input, a full disk, an error: the same reports as before), or anything else (a
signal, an out-of-memory kill, another exit status): ChildCrashed, naming the job, the cache
folder, how it ended and the last lines of its log. Cancel sends SIGTERM (the child stops at its
next unit of work) and SIGKILL after a grace period; abort (quit, file load, add-on disabled)
kills at once. The child also dies with Blender (PR_SET_PDEATHSIG), so none outlives it."""

import json
import os
import select
import signal
import subprocess
import sys
import time

from ..settings import BakeError
from . import jobfile

#: Seconds a cancelled child may take to stop at its next unit of work before it is killed:
#: bakes write their last complete frame and report it; the other jobs' work is discarded
#: anyway (their native calls that cannot stop inside are killed within a second of Esc).
GRACE_S = 0.5
GRACE_PARTIAL_S = 10.0
#: Lines of the child's log quoted in a crash report.
LOG_TAIL_LINES = 6
PYTHON_ENV = "PLUME_PYTHON"

#: The JobProcesses started and not yet reaped (abort_all at quit kills what is left).
_live = set()


class ChildCrashed(Exception):
    """The child ended without reporting: a signal (a crash, SIGKILL), another exit status."""


def child_python():
    """The Python that runs the child: the running Blender's own (PLUME_PYTHON overrides).
    A venv (the bpy wheels): its python; Blender's bundled Python or the system Python Debian's
    Blender runs (sys.executable may name an unrelated python on PATH there): the interpreter
    under sys.prefix with the running version, else sys.executable."""
    chosen = os.environ.get(PYTHON_ENV)
    if chosen:
        return chosen
    if sys.prefix != sys.base_prefix:
        return sys.executable
    v = sys.version_info
    own = os.path.join(sys.prefix, "bin", f"python{v.major}.{v.minor}")
    return own if os.access(own, os.X_OK) else sys.executable


def _package():
    """(folder holding the add-on's package, its folder name): the child imports it from there
    as a top-level package (a 4.2+ extension too: ``bl_ext.*.plume`` is the folder ``plume``)."""
    addon = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return os.path.dirname(addon), os.path.basename(addon)


def signal_name(number):
    try:
        name = signal.Signals(number).name
    except ValueError:
        return f"signal {number}"
    meaning = {"SIGSEGV": "a crash in native code", "SIGABRT": "an abort in a library",
               "SIGKILL": "killed: out of memory, or by another program",
               "SIGBUS": "a crash in native code", "SIGFPE": "a crash in native code",
               "SIGTERM": "stopped by another program"}.get(name)
    return f"{name} ({meaning})" if meaning else name


def _stack_line(line):
    """A line of a Python stack dump (faulthandler's, a traceback's): left out of the tail."""
    s = line.strip()
    return (s.startswith(("File ", "Extension modules:", "Current thread", "Thread 0x",
                          "Stack (most recent", "Traceback (most recent"))
            or line.startswith("    "))


def log_tail(path, lines=LOG_TAIL_LINES):
    """The last `lines` lines of the child's log that say something (stack dumps left out)."""
    try:
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - 8192))
            text = f.read().decode("utf-8", "replace")
    except OSError:
        return []
    return [line.strip() for line in text.splitlines()
            if line.strip() and not _stack_line(line)][-lines:]


class JobProcess:
    """The child of one runner (runner.child); same shape as a thread: start(), finished,
    error, join()."""

    def __init__(self, runner):
        self.runner = runner
        self.error = None
        self.finished = False
        self.proc = None
        self.pid = None
        self.started_at = self.ended_at = None
        self.killed = False
        self._fd = None
        self._buffer = b""
        self._message = None  # the child's "done" or "error" line
        self._term_at = None
        runner.child = self

    # ------------------------------------------------------------------ start
    def start(self):
        """Writes the job file and starts the child; the job's files are removed again and
        the error raised when it cannot start."""
        r = self.runner
        self.folder, self.name = r.job_folder(), r.job_name()
        self.paths = jobfile.job_paths(self.folder, self.name)
        spec = r.job_spec()
        self.started_at = time.perf_counter()
        try:
            job_file = jobfile.write_job(self.folder, r.kind, r.title, spec, self.name)
            self._spawn(job_file)
        except BaseException:
            jobfile.remove_job(self.folder, self.name)
            raise
        _live.add(self)
        if r.cancelled:  # cancelled while it was starting (prepare()'s progress, a script)
            self.cancel()
        return self

    def _spawn(self, job_file):
        root, package = _package()
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
        read_fd, write_fd = os.pipe()
        try:
            with open(self.paths["log"], "wb") as log:
                self.proc = subprocess.Popen(
                    [child_python(), "-m", f"{package}.job", "run", job_file,
                     "--report-fd", str(write_fd), "--parent", str(os.getpid())],
                    stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                    pass_fds=(write_fd,), env=env, start_new_session=True)
        except BaseException:
            os.close(read_fd)
            raise
        finally:
            os.close(write_fd)
        os.set_blocking(read_fd, False)
        self._fd, self.pid = read_fd, self.proc.pid

    # ------------------------------------------------------------------ polling
    def poll(self):
        """Reads what the child reported; True once it has ended (then `error` is set or the
        runner has its result)."""
        if self.finished or self.proc is None:  # ended, or never started
            return True
        self._read()
        for lock in self.runner.folder_locks:
            lock.keep_alive()
        if self._term_at is not None and not self.killed:
            grace = GRACE_PARTIAL_S if self.runner.keeps_partial else GRACE_S
            if time.perf_counter() - self._term_at > grace:
                self.kill()
        code = self.proc.poll()
        if code is None:
            return False
        self._read()
        self._end(code)
        return True

    def wait(self, timeout=None):
        """Blocks until the child ends (polling as the timer would); True when it has."""
        end = None if timeout is None else time.perf_counter() + timeout
        while not self.poll():
            left = 0.1 if end is None else min(0.1, end - time.perf_counter())
            if left <= 0:
                return False
            select.select([self._fd], [], [], left)
        return True

    def _read(self):
        if self._fd is None:
            return
        while True:
            try:
                chunk = os.read(self._fd, 65536)
            except BlockingIOError:
                break
            except OSError:
                chunk = b""
            if not chunk:
                break
            self._buffer += chunk
        *lines, self._buffer = self._buffer.split(b"\n")
        for line in lines:
            self._message_of(line)

    def _message_of(self, line):
        try:
            m = json.loads(line.decode("utf-8"))
        except ValueError:
            return
        if "progress" in m:
            done, total, label, left = m["progress"]
            # An empty label: the unit prepare() named ("frame") goes on.
            self.runner.set_progress(done, total, label or None, seconds_left=left)
        elif "done" in m or "error" in m:
            self._message = m

    # ------------------------------------------------------------------ the end
    def _end(self, code):
        self.ended_at = time.perf_counter()
        self.finished = True
        os.close(self._fd)
        self._fd = None
        _live.discard(self)
        r, m = self.runner, self._message
        if code == 0 and m is not None and m.get("done"):
            header, value = jobfile.load(self.paths["result"], self.paths["result_npz"],
                                         self.folder)
            if m.get("cancelled"):
                r.cancelled_by_child = True
            if value is not None or not m.get("cancelled"):  # None: stopped before a result
                r.take_result(value)
            jobfile.remove_job(self.folder, self.name)
        elif code == 1 and m is not None and "error" in m:
            self.error = _exception_of(m)
            if isinstance(self.error, BakeError) or m.get("no_room"):
                jobfile.remove_job(self.folder, self.name)
            else:  # a bug: the traceback is in the log
                self.error = RuntimeError(f"{m['error']} (its log: {self.paths['log']})")
        elif self.killed or (self._term_at is not None and code == -signal.SIGTERM):
            # Esc past its grace (or before the child could hear it), or an abort (quit, file
            # load): nothing to build
            r.killed = True
            jobfile.remove_job(self.folder, self.name)
        else:
            self.error = ChildCrashed(self._crash_text(code))

    def _crash_text(self, code):
        r = self.runner
        how = (f"was ended by {signal_name(-code)}" if code < 0
               else f"exited with status {code}")
        kept = r.kept_text if r.keeps_partial else "nothing was changed"
        text = (f"its process (pid {self.pid}) {how}, in cache folder '{self.folder}'; {kept}. "
                f"Blender and the scene are unharmed. Job file: {self.paths['json']}")
        tail = log_tail(self.paths["log"])
        if tail:
            text += f"; last lines of its log {self.paths['log']}: " + " | ".join(tail)
        return text

    # ------------------------------------------------------------------ stopping
    def cancel(self):
        """Esc: SIGTERM now (the child stops at its next unit), SIGKILL after the grace."""
        if self.finished or self.proc is None or self._term_at is not None:
            return
        self._term_at = time.perf_counter()
        self._signal(signal.SIGTERM)

    def kill(self):
        """SIGKILL at once (abort: quit, file load; or a cancel past its grace)."""
        if self.finished or self.proc is None:
            return
        self.killed = True
        self._signal(signal.SIGKILL)

    def _signal(self, sig):
        try:
            os.kill(self.pid, sig)
        except ProcessLookupError:
            pass

    def join(self, timeout=None):
        """Kills the child and reaps it (abort): True when it is gone. Its job files go either
        way (a killed child writes nothing more; an aborted job is not rerun from them)."""
        if self.proc is None:
            return True
        self.kill()
        try:
            self.proc.wait(timeout)
            gone = True
        except subprocess.TimeoutExpired:
            self.runner.killed, gone = True, False
        if gone:
            self.poll()
        jobfile.remove_job(self.folder, self.name)
        return gone

    @property
    def alive(self):
        return self.proc is not None and self.proc.poll() is None


def _exception_of(m):
    text = m.get("error", "")
    if m.get("type") == "BakeError":
        return BakeError(text)
    if m.get("errno") is not None:
        return OSError(m["errno"], text)
    return RuntimeError(text)


def kill_all():
    """Kills and reaps every child still running (quit, the add-on disabled); how many."""
    procs = list(_live)
    for p in procs:
        p.kill()
    for p in procs:
        p.join(5.0)
    return len(procs)
