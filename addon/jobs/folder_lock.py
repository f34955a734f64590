"""One writer per cache folder, no ``bpy``: the advisory lock file ``<folder>/.plume.lock``.

Every job that writes a cache folder takes its lock in prepare(), before it writes anything, and
holds it until the job ends in any way (registry.release(): finished, failed, refused, cancelled,
aborted by a file load or quit; a killed Blender's lock is stale, see below). A second writer,
in another Blender or in this one, is refused with a BakeError naming the holder.

The lock file holds a JSON record: host, pid, the process's start time (Linux: /proc, so a
reused pid is not mistaken for the holder), when the job started and its title. The holder also
keeps an flock() on the file for the job's life and refreshes the file's time every REFRESH_S
(keep_alive(), called by whoever waits for the job: Blender's poll of the job's child, or the
job command's main thread; no thread of its own). Blender holds the lock while its job's child
writes, and the child inherits nothing from it: the one writer is the pair.

- The lock is free when the file is missing. It is created whole: the record is written under
  a temporary name and flocked, then hard-linked to ``.plume.lock``, which fails when another
  taker was first (where hard links are not supported: O_CREAT | O_EXCL).
- A held flock means a live holder: refused.
- Otherwise the record decides. Same host: taken over when its pid is gone (or was reused);
  refused while it lives (the flock may be local-only on this file system). Another host: its
  pid cannot be checked, so the lock is honoured while the file was refreshed within
  REMOTE_STALE_S and taken over after; deleting ``.plume.lock`` by hand takes it over at once.
  An empty or unreadable record with a free flock is a taker killed while writing it: stale.
- A takeover happens under the stale file's flock: the new record (flocked) is renamed over the
  stale file. A second taker either fails the flock or, after it, finds the path no longer names
  the file it locked and starts over, so two takers never both win (on file systems that share
  flock between hosts: local disks, NFSv4, NFSv3 with lockd, SMB; where they do not, e.g. NFS
  mounted ``nolock``, two hosts starting within the same instant can both pass).
- Release: the file is deleted (if it is still ours) while the flock is held, then closed.
"""

import contextlib
import errno
import json
import os
import socket
import time
import uuid

try:
    import fcntl
except ImportError:  # Windows: the record alone decides
    fcntl = None

from ..files import no_room
from ..settings import BakeError

LOCK_NAME = ".plume.lock"
#: Seconds between two refreshes of the holder's lock file time (its sign of life).
REFRESH_S = 60.0
#: A lock from another host not refreshed for this long is stale (15 refreshes missed; covers
#: clock differences between hosts and NFS attribute caching by far).
REMOTE_STALE_S = 15 * 60.0
#: Attempts when the lock file changes under a taker (another taker was quicker, or released).
ATTEMPTS = 20


class LockHeld(BakeError):
    """Another writer holds the cache folder."""


def lock_path(folder):
    return os.path.join(folder, LOCK_NAME)


def _proc_start(pid):
    """The start time of process `pid` in clock ticks since boot (Linux), or None."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            text = f.read().decode("ascii", "replace")
        return int(text[text.rindex(")") + 2:].split()[19])
    except (OSError, ValueError, IndexError):
        return None


def _pid_alive(pid, start):
    """True when process `pid` lives and (where known) started at `start`."""
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        pass  # exists, owned by someone else
    now_start = _proc_start(pid)
    return start is None or now_start is None or now_start == start


def own_record(job):
    return {"host": socket.gethostname(), "pid": os.getpid(), "pid_start": _proc_start(os.getpid()),
            "started": time.time(), "job": str(job)}


def _clock(t):
    """ "08:01" today, else "2026-11-25 08:01"."""
    if not isinstance(t, (int, float)):
        return "?"
    lt = time.localtime(t)
    same_day = time.localtime()[:3] == lt[:3]
    return time.strftime("%H:%M" if same_day else "%Y-%m-%d %H:%M", lt)


def holder_text(folder, record, refreshed):
    """The refusal: who holds `folder` and what to do."""
    path = lock_path(folder)
    host, pid = record.get("host", "?"), record.get("pid", "?")
    job, since = record.get("job", "?"), _clock(record.get("started"))
    if host == socket.gethostname() and pid == os.getpid():
        return (f"Plume: cache folder '{folder}' is being written by this Blender ({job}, since "
                f"{since}); wait for it or cancel it (Esc), then try again")
    text = (f"Plume: cache folder '{folder}' is being written by Blender pid {pid} on host "
            f"{host} ({job}, since {since}); wait for it or cancel it there, then try again")
    if host != socket.gethostname():
        text += (f". A lock from another host is taken over {REMOTE_STALE_S / 60:.0f} min after "
                 f"its last sign of life ({_clock(refreshed)}); if that Blender is gone, delete "
                 f"'{path}' to take it over now")
    return text


def _read_record(fd):
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        data = json.loads(os.read(fd, 65536).decode("utf-8"))
        return data if isinstance(data, dict) else None
    except (OSError, ValueError):
        return None


def _flock(fd):
    """True when the exclusive flock is ours, False when another holds it; True where flock is
    not supported (the record alone decides)."""
    if fcntl is None:
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False
    except OSError as e:
        if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            return False
        return True  # ENOLCK, EOPNOTSUPP...: no locks here


def is_stale(record, refreshed, now=None):
    """True when `record` (None: empty or unreadable) belongs to no live writer."""
    if record is None:
        return True
    if record.get("host") != socket.gethostname():
        now = time.time() if now is None else now
        return now - refreshed > REMOTE_STALE_S
    return not _pid_alive(record.get("pid"), record.get("pid_start"))


def _same_file(fd, path):
    try:
        a, b = os.fstat(fd), os.stat(path)
    except OSError:
        return False
    return (a.st_ino, a.st_dev) == (b.st_ino, b.st_dev)


def _made_dirs(folder):
    """Creates `folder` and its missing parents; the ones it made, deepest first."""
    made, probe = [], os.path.abspath(folder)
    while not os.path.isdir(probe):
        made.append(probe)
        parent = os.path.dirname(probe)
        if parent == probe:
            break
        probe = parent
    os.makedirs(folder, exist_ok=True)
    return made


class FolderLock:
    """The held lock of one cache folder (acquire() makes it)."""

    def __init__(self, folder, fd, record, made_dirs, on_lost):
        self.folder, self.path = folder, lock_path(folder)
        self.record, self.lost = record, False
        #: The setting naming the folder in reports ("the Cache Directory '//x/' (...)"), if any.
        self.setting = None
        self._fd, self._made, self._on_lost = fd, made_dirs, on_lost
        self._refreshed = time.monotonic()

    @property
    def held(self):
        return self._fd is not None

    def refresh(self):
        """Sign of life: the lock file's time set to now. False (and on_lost called) when the
        path no longer names our file (deleted by hand and taken by another writer)."""
        fd = self._fd
        if fd is None:
            return False
        self._refreshed = time.monotonic()
        ours = _same_file(fd, self.path)
        if ours:
            try:
                os.utime(fd if os.utime in os.supports_fd else self.path)
            except OSError:
                pass
        if not ours and not self.lost:
            self.lost = True
            if self._on_lost is not None:
                self._on_lost()
        return ours

    def keep_alive(self):
        """refresh() when REFRESH_S have passed since the last one (cheap to call often)."""
        if self._fd is not None and time.monotonic() - self._refreshed >= REFRESH_S:
            self.refresh()

    def release(self):
        """Deletes the lock file (when still ours) and drops the flock; safe to call twice."""
        fd, self._fd = self._fd, None
        if fd is None:
            return
        try:
            if _same_file(fd, self.path):
                os.remove(self.path)
        except OSError:
            pass
        finally:
            os.close(fd)
        for folder in self._made:  # made for this job and still empty: as it was
            try:
                os.rmdir(folder)
            except OSError:
                break


def _new_record_file(folder, record):
    """A temporary file holding `record`, flocked; (fd, path)."""
    tmp = os.path.join(folder, f"{LOCK_NAME}.{os.getpid()}_{uuid.uuid4().hex[:8]}.tmp")
    fd = os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
    try:
        _flock(fd)
        os.write(fd, json.dumps(record).encode("utf-8"))
        os.fsync(fd)
    except BaseException:
        os.close(fd)
        os.remove(tmp)
        raise
    return fd, tmp


def _create(folder, record):
    """The lock file made whole where none is; its fd, or None when another taker was first."""
    path = lock_path(folder)
    fd, tmp = _new_record_file(folder, record)
    try:
        os.link(tmp, path)
        return fd
    except (FileExistsError, FileNotFoundError):  # another was first (or swept our .tmp)
        os.close(fd)
        return None
    except OSError as e:
        if e.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EMLINK,
                           errno.ENOSYS):
            os.close(fd)
            raise
    finally:
        try:
            os.remove(tmp)
        except FileNotFoundError:
            pass
    os.close(fd)  # no hard links here: exclusive create, then the record
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        return None
    _flock(fd)
    os.write(fd, json.dumps(record).encode("utf-8"))
    os.fsync(fd)
    return fd


def _take_over(folder, old_fd, record):
    """Replaces the stale lock file (flocked through `old_fd`) by ours; our fd, or None when
    the path changed meanwhile."""
    path = lock_path(folder)
    fd, tmp = _new_record_file(folder, record)
    try:
        if not _same_file(old_fd, path):
            raise FileExistsError(path)
        os.replace(tmp, path)
        return fd
    except OSError:
        os.close(fd)
        try:
            os.remove(tmp)
        except OSError:
            pass
        return None


def _try_once(folder, record):
    """One attempt: (fd, None) when taken, (None, refusal text) when held, (None, None) when
    the lock file changed under us (try again)."""
    path = lock_path(folder)
    try:
        fd = os.open(path, os.O_RDWR)
    except FileNotFoundError:
        return _create(folder, record), None
    try:
        locked = _flock(fd)
        if not _same_file(fd, path):
            return None, None  # released or taken over meanwhile: read the new file
        current = _read_record(fd)
        refreshed = os.fstat(fd).st_mtime
        if not locked or not is_stale(current, refreshed):
            return None, holder_text(folder, current or {}, refreshed)
        return _take_over(folder, fd, record), None
    finally:
        os.close(fd)  # drops the stale file's flock (after the takeover's rename)


def acquire(folder, job, setting=None, on_lost=None):
    """The lock of cache folder `folder` for job title `job` (the folder is made when missing);
    LockHeld naming the holder, BakeError naming `setting` (e.g. "the Cache Directory '//x/'")
    when the folder cannot be written. on_lost() is called if the lock is taken from us (the file
    deleted by hand and another writer started)."""
    folder = os.path.abspath(folder)
    what = setting or f"cache folder '{folder}'"
    try:
        made = _made_dirs(folder)
    except OSError as e:
        raise BakeError(f"Plume: {what} is not writable ({folder}: {e.strerror or e})") from None
    record = own_record(job)
    try:
        for _ in range(ATTEMPTS):
            fd, refusal = _try_once(folder, record)
            if fd is not None:
                lock = FolderLock(folder, fd, record, made, on_lost)
                lock.setting = setting
                return lock
            if refusal is not None:
                raise LockHeld(refusal)
        raise LockHeld(f"Plume: cache folder '{folder}': its lock file '{lock_path(folder)}' "
                       f"keeps changing (other Blenders are starting to write it); try again")
    except OSError as e:
        full = no_room(e)  # "the disk is full"
        reason = f"cannot be written: {full}" if full else "is not writable"
        error = BakeError(f"Plume: {what} {reason} ({folder}: {e.strerror or e})")
    except BaseException:
        _remove_made(made)
        raise
    _remove_made(made)
    raise error


def _remove_made(made):
    for folder in made:
        try:
            os.rmdir(folder)
        except OSError:
            break


@contextlib.contextmanager
def holding(folder, job):
    """The lock of `folder` around a short write outside a job (Free): LockHeld when a job
    writes it; the folder is removed afterwards when it ends up empty."""
    lock = acquire(folder, job)
    try:
        yield lock
    finally:
        lock.release()
        try:
            os.rmdir(lock.folder)
        except OSError:
            pass  # not empty
