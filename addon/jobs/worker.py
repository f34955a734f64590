"""The thread a job's run() executes on (or the caller's own thread, blocking), no ``bpy``.

No worker may still run when Python finalizes: a thread that comes back from native code (a
pybind11 call that released the GIL) after finalization has begun is ended by CPython with
pthread_exit, whose forced unwind through the binding's noexcept GIL guard calls std::terminate
("terminate called without an active exception", Blender exits 134). So workers are not daemon
threads, and a hook that threading runs before it joins them at shutdown (stop_all()) cancels
every live worker and waits for it: quitting never leaves one behind, however Blender quits and
whatever the registry still holds."""

import sys
import threading
import time
import traceback

from ..files import no_room
from ..settings import BakeError
from . import quiet
from .runner import JobCancelled

#: Workers whose thread runs now (started, not ended).
_live = set()
_live_lock = threading.Lock()
#: Seconds between two "still waiting" lines while stop_all() waits at quit.
WAIT_NOTE_S = 5.0


def running_threads():
    """Thread idents of the workers running on threads of their own now (quiet.hold())."""
    return [w.thread_id for w in live() if w.thread_id is not None and not w.finished]


def live():
    """The workers whose thread was started and has not ended."""
    with _live_lock:
        return list(_live)


def stop_all():
    """Cancels every live worker and waits until each has ended (Python's shutdown, before it
    finalizes; also atexit). A worker stops within one unit of work of its job; it is waited for
    however long that takes, saying so every WAIT_NOTE_S seconds, because ending the process with
    the worker inside native code is what crashes."""
    quiet.release_all()  # a parked worker must see its cancel
    workers = live()
    for w in workers:
        w.runner.aborted = True
        w.runner.cancel()
    for w in workers:
        waited = 0.0
        while not w.join(WAIT_NOTE_S):
            waited += WAIT_NOTE_S
            print(f"Plume: waiting for {w.runner.title} to stop ({waited:.0f} s)",
                  file=sys.stderr, flush=True)
        w.runner.discard()


class Worker:
    """Runs runner.run() once and keeps how it ended: `error` (an exception, None when it
    returned or was cancelled), `finished`, and the thread it ran on."""

    def __init__(self, runner):
        self.runner = runner
        self.error = None
        self.finished = False
        self.thread = None
        self.thread_id = None
        self.started_at = None
        self.ended_at = None
        runner.worker = self

    def _run(self):
        self.thread_id = threading.get_ident()
        self.started_at = time.perf_counter()
        try:
            quiet.park()  # started inside an operator call made under quiet.held()
            self.runner.run()
        except JobCancelled:
            pass
        except Exception as e:  # reported by the operator on the main thread
            if not self.runner.cancelled:
                if not isinstance(e, BakeError) and no_room(e) is None:  # a bug: its trace
                    traceback.print_exc()  # (bad input and a full disk are reported, not bugs)
                self.error = e
        finally:
            self.ended_at = time.perf_counter()
            self.finished = True
            with _live_lock:
                _live.discard(self)
            if self.runner.aborted:  # abort() stopped waiting for it: its temporaries go now
                self.runner.discard()

    def run_here(self):
        """Blocking: run() on the calling thread (execute(), ``blender -b``)."""
        self._run()
        return self

    def start(self):
        """run() on a new thread; not a daemon: Python's shutdown waits for it, after stop_all()
        has cancelled it (see the module docstring)."""
        self.thread = threading.Thread(target=self._run, name=f"plume {self.runner.title}",
                                       daemon=False)
        with _live_lock:
            _live.add(self)
        try:
            self.thread.start()
        except BaseException:
            with _live_lock:
                _live.discard(self)
            raise
        return self

    @property
    def alive(self):
        return self.thread is not None and self.thread.is_alive()

    def join(self, timeout=None):
        """True when run() has ended (within `timeout` seconds)."""
        if self.thread is not None and self.thread is not threading.current_thread():
            self.thread.join(timeout)
        return self.finished
