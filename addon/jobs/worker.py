"""The thread a job's run() executes on (or the caller's own thread, blocking), no ``bpy``."""

import threading
import time
import traceback

from ..files import no_room
from ..settings import BakeError
from .runner import JobCancelled


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

    def run_here(self):
        """Blocking: run() on the calling thread (execute(), ``blender -b``)."""
        self._run()
        return self

    def start(self):
        """run() on a new daemon thread (a hung native call never keeps Blender from quitting;
        quit and file load cancel and join it first)."""
        self.thread = threading.Thread(target=self._run, name=f"plume {self.runner.title}",
                                       daemon=True)
        self.thread.start()
        return self

    @property
    def alive(self):
        return self.thread is not None and self.thread.is_alive()

    def join(self, timeout=None):
        """True when run() has ended (within `timeout` seconds)."""
        if self.thread is not None:
            self.thread.join(timeout)
        return self.finished
