"""A job's new files, kept apart until the job succeeds, no ``bpy``.

run() writes into a hidden folder inside the cache folder (same file system, so moving a file
into place is one atomic rename); finish() commits: every staged file replaces its namesake in
the cache folder, then the files of the previous result that the new one does not replace are
deleted. A cancelled or failed job discards the folder, so the cache folder is left exactly as it
was: no new file, no partial file. Folders left by a killed Blender are removed by the next job
in the same cache folder."""

import os
import shutil
import uuid

from ..files import sync_folder

PREFIX = ".plume_job_"


def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # exists, owned by someone else
    return True


def sweep(folder):
    """Removes staging folders of processes that are gone (a killed Blender's)."""
    try:
        names = os.listdir(folder)
    except OSError:
        return
    for name in names:
        if not name.startswith(PREFIX):
            continue
        try:
            pid = int(name[len(PREFIX):].split("_", 1)[0])
        except ValueError:
            continue
        if pid != os.getpid() and not _pid_alive(pid):
            shutil.rmtree(os.path.join(folder, name), ignore_errors=True)


class Staging:
    """The staging folder of one job inside `folder` (the cache folder it will commit to)."""

    def __init__(self, folder):
        self.folder = folder
        self.path = None
        self._made_folder = False

    def create(self):
        """Makes the staging folder (and the cache folder when missing); returns its path."""
        if self.path is None:
            self._made_folder = not os.path.isdir(self.folder)
            os.makedirs(self.folder, exist_ok=True)
            sweep(self.folder)
            self.path = os.path.join(self.folder, f"{PREFIX}{os.getpid()}_{uuid.uuid4().hex[:8]}")
            os.makedirs(self.path)
        return self.path

    def staged_files(self):
        """Paths of the staged files relative to the staging folder, sorted."""
        out = []
        if self.path is None:
            return out
        for root, _dirs, files in os.walk(self.path):
            for name in files:
                out.append(os.path.relpath(os.path.join(root, name), self.path))
        return sorted(out)

    def final_path(self, staged_path):
        """Where a file written under the staging folder ends up after commit()."""
        return os.path.join(self.folder, os.path.relpath(staged_path, self.path))

    def commit(self, replaced=()):
        """Moves every staged file into the cache folder (atomic rename each), then deletes the
        files of `replaced` (the previous result) that no staged file replaced; removes the
        staging folder. Returns the final paths. Staged files are written with files.write_bytes
        (fsynced); the cache folder is fsynced after the renames."""
        moved = []
        for rel in self.staged_files():
            if rel.endswith(".tmp"):
                continue  # an unfinished write inside the staging folder never goes live
            dest = os.path.join(self.folder, rel)
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            os.replace(os.path.join(self.path, rel), dest)
            moved.append(os.path.abspath(dest))
        for folder in sorted({os.path.dirname(path) for path in moved}):
            sync_folder(folder)  # the renames are durable before the old result is deleted
        for path in replaced:
            if os.path.abspath(path) not in moved:
                try:
                    os.remove(path)
                except FileNotFoundError:
                    pass
        self._remove()
        return moved

    def discard(self):
        """Removes the staging folder and what is in it (and the cache folder if this job made
        it and it is empty again)."""
        self._remove()
        if self._made_folder:
            try:
                os.rmdir(self.folder)
            except OSError:
                pass  # not empty: files of others
            self._made_folder = False

    def _remove(self):
        if self.path is not None:
            shutil.rmtree(self.path, ignore_errors=True)
            self.path = None
