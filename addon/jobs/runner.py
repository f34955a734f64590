"""The runner protocol of every long Plume operation (a *job*), no ``bpy``.

A job is split in parts, so that one operator mixin (operator.py) can run any of them blocking
(``blender -b``, scripts) or in the background with progress and Esc (the UI), and so that its
work runs in a child process, never in Blender's (process.py, child.py):

    runner.prepare(context)   main thread: settings snapshot + validation; BakeError on bad
                              input, nothing written and nothing changed
    runner.job_spec()         main thread, once prepare() succeeded: the plain data the child
                              needs (written to the job file, jobfile.py); may stage()
    kinds.<kind>(spec, job)   the child: the computation (no bpy); new files go to the staging
                              folder (a bake: its cache folder, frame by frame)
    runner.take_result(v)     main thread: what the child returned (default: self.result)
    runner.main_steps(ctx)    main thread, optional: short bpy steps (saving images into the
                              staging folder), each yielding progress; Esc cancels between them
    runner.finish(context)    main thread: commits the staged files, builds the Blender data,
                              returns the report (kind, text)

and, when the job is cancelled or fails, ``runner.discard()`` removes whatever it wrote, so the
scene and the cache folder are left as they were. Bakes (keeps_partial) are the exception: their
per-frame files are complete and resumable, so a cancelled or crashed bake keeps them (and a
cancelled one that reported its result still builds what is there).

A job that writes a cache folder takes its lock in prepare() (lock_folder(), folder_lock.py)
before writing anything: one writer per folder across Blenders and hosts, held by Blender for
the child's whole life, released however the job ends. A write that fails for want of room is
reported by no_room_text().
"""

import abc
import time
from dataclasses import dataclass
from typing import Optional

from ..files import no_room, sweep_temporaries
from ..settings import BakeError
from . import folder_lock, registry
from .staging import Staging


class JobCancelled(Exception):
    """Raised by check_cancel() inside run(): the job stops between two units of work."""


@dataclass(frozen=True)
class JobProgress:
    """What the status bar shows: `done` of `total` units named by `label` ("frame",
    "surface"); total 0 while unknown. seconds_left None: estimated from the rate since
    `stage_started` (time.perf_counter() when this label and total were first reported)."""

    done: int = 0
    total: int = 0
    label: str = ""
    seconds_left: Optional[float] = None
    stage_started: float = 0.0

    def estimate_left(self, now):
        """Seconds left: the runner's own figure, else the stage's rate so far; None when
        nothing is known yet."""
        if self.seconds_left is not None:
            return self.seconds_left
        if self.total <= 0 or self.done <= 0:
            return None
        return (now - self.stage_started) / self.done * (self.total - self.done)


@dataclass(frozen=True)
class Forecast:
    """How long a job is expected to take, said before it starts: `seconds` and `what` the
    figure is made of ("1,024 streaklines x 60 frames")."""

    seconds: float
    what: str

    def about(self):
        """ "about 2 min" """
        s = self.seconds
        return "about " + (f"{s:.0f} s" if s < 90 else (f"{s / 60:.0f} min" if s < 5400 else
                                                        f"{s / 3600:.1f} h"))

    def text(self, title):
        """ "Build Surfaces: 1,024 streaklines x 60 frames, about 2 min" """
        return f"{title}: {self.what}, {self.about()}"


class JobRunner(abc.ABC):
    """Base of every job (see the module docstring for the protocol)."""

    #: Name in reports and the status bar: the operator's label ("Bake", "Build Surfaces").
    title = "Job"
    #: Exceptions of prepare() that mean bad input (reported as refusal_text, nothing changed).
    prepare_errors = (BakeError,)
    #: True for bakes: a cancelled run keeps its complete frames and finish() still builds them.
    keeps_partial = False
    #: What a stopped or crashed run of a keeps_partial job leaves, in the reports.
    kept_text = "the frames it finished are kept, and the next run resumes from them"
    #: The work function of the child (jobs/kinds.py).
    kind = None

    def __init__(self):
        self._cancelled = False
        self._progress = JobProgress(label="starting")  # until prepare() or the child says more
        #: Called with each JobProgress from the thread that reports it (tests use it).
        self.on_progress = None
        #: Registry keys this job holds ("domain", name): one job per key at a time.
        self.keys = ()
        #: Names of the objects the job works on: deleting one cancels the job.
        self.objects = ()
        #: The job's Staging (files written by run(), moved into place by finish()), if any.
        self.staging = None
        #: Set when the job was stopped from outside its operator (file load, quit): the
        #: operator must neither finish() nor touch the scene.
        self.aborted = False
        #: The JobProcess running the job's child (process.py), once started.
        self.child = None
        #: What the child returned (take_result()).
        self.result = None
        #: The child reported that it stopped early (SIGTERM from Esc, or from another program).
        self.cancelled_by_child = False
        #: The child was killed (Esc past its grace period, or an abort): no result.
        self.killed = False
        #: The status bar's last line (operator.py), for scripts and tests.
        self.status_text = ""
        #: The Forecast said before a long job started (operator.py), for its report.
        self.forecast_said = None
        #: time.perf_counter() of the first cancel() (None while not cancelled).
        self.cancelled_at = None
        #: The FolderLocks of the cache folders the job writes (lock_folder()).
        self.folder_locks = []
        #: How the job ended (operator.py, registry.py): 'finished', 'cancelled' (Esc; a bake
        #: keeps its frames), 'gone' (an object it works on was deleted or renamed), 'failed',
        #: 'aborted' (file load, quit); None while it runs. `report_text`: what was reported.
        self.outcome = None
        self.report_text = ""

    # ------------------------------------------------------------------ the four parts
    def forecast(self, context):
        """A Forecast of how long the job will take, from the settings and what is on disk,
        before prepare() (cheap: the operator asks it when the button is pressed); None when it
        cannot tell or the job is short. Must not raise for bad input: prepare() reports that."""
        return None

    def shorter_hint(self):
        """Lines the long-job dialog adds: which settings make the job shorter."""
        return ()

    @abc.abstractmethod
    def prepare(self, context):
        """Snapshot and checks on the main thread; BakeError on bad input, nothing written."""

    @abc.abstractmethod
    def job_spec(self):
        """The plain data the child's kinds.<kind>() needs (main thread, after prepare())."""

    def job_folder(self):
        """The cache folder holding the job file and log (default: self.folder)."""
        return self.folder

    def job_name(self):
        """The job file's name in the folder's jobs/ (the kind; unique where two may run)."""
        return self.kind

    def take_result(self, value):
        """What the child's work returned (main thread)."""
        self.result = value

    def main_steps(self, context):
        """Main-thread steps after run(), each yielding a JobProgress; none by default."""
        return iter(())

    @abc.abstractmethod
    def finish(self, context):
        """Commits and builds; returns (report kind, text), e.g. ('INFO', "Plume: ...")."""

    def stage(self, folder):
        """A Staging in the cache folder `folder` for the child's new files (made now); its
        path."""
        self.staging = Staging(folder)
        return self.staging.create()

    def discard(self):
        """Removes the job's temporaries (cancelled, failed, killed): its staging folder and
        the unfinished writes a killed child left in the folders it holds; safe twice."""
        if self.staging is not None:
            self.staging.discard()
        for lock in self.folder_locks:
            if lock.held:
                sweep_temporaries(lock.folder)
                if self.keeps_partial:
                    self.tidy_partial(lock.folder)

    def tidy_partial(self, folder):
        """A keeps_partial job stopped anywhere (killed, crashed): removes the frames written
        after the last one its manifest calls complete (a kill between a frame's file and the
        manifest), so the folder holds exactly the complete frames. Default: nothing."""

    # ------------------------------------------------------------------ messages
    def refusal_text(self, exc):
        """The report of bad input found by prepare()."""
        return str(exc)

    def error_text(self, exc):
        """The report of an error in the child, main_steps() or finish()."""
        if isinstance(exc, BakeError):
            return str(exc)
        return f"Plume: {self.title} failed: {exc}"

    def no_room_text(self, exc):
        """The report of a write that failed for want of room (a full disk, the file size
        limit), naming the cache folder and its setting; None for any other error."""
        reason = no_room(exc)
        if reason is None:
            return None
        lock = self.folder_locks[0] if self.folder_locks else None
        where = "the cache folder" if lock is None else f"cache folder '{lock.folder}'"
        if lock is not None and lock.setting:
            where += f" ({lock.setting})"
        kept = ("the frames finished before are kept" if self.keeps_partial
                else "nothing was changed")
        return (f"Plume: {self.title} stopped: {reason} writing into {where}: {exc}. Free space "
                f"there or choose another cache folder, then run {self.title} again; {kept}")

    def cancelled_text(self):
        if self.keeps_partial:  # killed past its grace period: no result to build
            return f"Plume: {self.title} cancelled: {self.kept_text}"
        return f"Plume: {self.title} cancelled: nothing was changed"

    def busy_text(self):
        """What a second job on one of this job's keys is told."""
        return f"Plume: {self.title} is running on the same data (Esc cancels it): wait for it"

    # ------------------------------------------------------------------ cancel
    def claim(self, *keys):
        """Holds registry keys for the job's life (BakeError with the holder's busy_text when
        another job holds one); call it in prepare() as soon as the keys are known."""
        registry.claim(self, keys)

    def lock_folder(self, folder, setting=None):
        """Makes the job the one writer of cache folder `folder` (folder_lock.py) until it ends
        in any way (registry.release()); LockHeld naming the holder when another Blender or job
        writes it, BakeError naming `setting` when the folder cannot be written. Call it in
        prepare() before anything is written. Once held, the unfinished writes a killed writer
        left there are removed (files.sweep_temporaries)."""
        self.folder_locks.append(folder_lock.acquire(folder, self.title, setting=setting,
                                                     on_lost=self.cancel))
        sweep_temporaries(folder)

    def release_folders(self):
        """Drops the job's cache folder locks (registry.release() calls it); safe twice."""
        for lock in self.folder_locks:
            lock.release()

    def cancel(self):
        """Esc, a deleted object, a lost lock: the child stops at its next unit of work (and is
        killed if it does not within its grace period, process.py)."""
        if self.cancelled_at is None:
            self.cancelled_at = time.perf_counter()
        self._cancelled = True
        if self.child is not None:
            self.child.cancel()

    @property
    def cancelled(self):
        return self._cancelled or self.cancelled_by_child

    def check_cancel(self):
        """Raises JobCancelled when cancel() was called (main-thread steps)."""
        if self.cancelled:
            raise JobCancelled()

    # ------------------------------------------------------------------ progress
    def set_progress(self, done, total, label=None, seconds_left=None):
        """`done` of `total` units (the child's reports, main-thread steps)."""
        last = self._progress
        label = last.label if label is None else label
        same = (label, int(total)) == (last.label, last.total) and last.stage_started
        p = JobProgress(int(done), int(total), label, seconds_left,
                        last.stage_started if same else time.perf_counter())
        self._progress = p  # one reference swap: readers see the old or the new value
        if self.on_progress is not None:
            self.on_progress(p)

    def progress(self):
        """The latest JobProgress (the operator's timer shows it)."""
        return self._progress
