"""The one way the add-on writes a cache file, so a cancelled or killed job never leaves a half
file (DESIGN.md "Cache folder"): the bytes go to a temporary name in the same folder
(``<name>.<pid>_<random>.tmp``, which the cache cleaners recognise), are flushed and fsynced,
renamed over the final name, and the folder is fsynced so the rename itself survives a crash.
A write that fails (a full disk) removes its temporary file and leaves the final name as it was;
no_room() tells such a failure from others, for the reports."""

import errno
import io
import os
import uuid

import numpy as np

#: Ending of every temporary file; cache cleaners and job staging skip or delete these.
TMP_SUFFIX = ".tmp"


#: errno of a write that failed for want of room -> what the report says.
NO_ROOM = {errno.ENOSPC: "the disk is full", errno.EDQUOT: "the disk quota is used up",
           errno.EFBIG: "the file size limit is reached"}


def no_room(exc):
    """What a failed write means when it failed for want of room ("the disk is full", "the file
    size limit is reached"), else None: from an OSError's errno, or from the reason the native
    writers put in their RuntimeError (the errno's text, e.g. "No space left on device")."""
    if isinstance(exc, OSError) and exc.errno in NO_ROOM:
        return NO_ROOM[exc.errno]
    text = str(exc)
    for code, meaning in NO_ROOM.items():
        if os.strerror(code) in text:
            return meaning
    return None


def temporary_path(path):
    """A temporary name next to `path`, unique to this process and call."""
    return f"{path}.{os.getpid()}_{uuid.uuid4().hex[:8]}{TMP_SUFFIX}"


def sweep_temporaries(folder):
    """Removes the unfinished writes a killed process left in cache folder `folder` and its
    subfolders (``*.tmp``: this module's, and the native writers' ``<name>.tmp``), but not
    Plume's hidden files (lock records, probes: their owners handle them) nor job staging
    folders (staging.sweep). Only safe while holding the folder's lock (jobs/folder_lock.py):
    then no other writer can own them. Returns how many were removed."""
    removed = 0
    for root, dirs, names in os.walk(folder):
        dirs[:] = [d for d in dirs if not d.startswith(".plume_job_")]
        for name in names:
            if name.endswith(TMP_SUFFIX) and not name.startswith("."):
                try:
                    os.remove(os.path.join(root, name))
                    removed += 1
                except OSError:
                    pass
    return removed


def sync_folder(folder):
    """fsync of a directory, so renames into it are durable (a no-op where not supported)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_bytes(path, data: bytes, durable=True):
    """Writes `data` to `path` atomically (temporary name, fsync, rename, folder fsync). Not
    `durable`: no fsyncs (still atomic against a killed process, whose writes the kernel keeps;
    a power cut may leave the previous version, or on some file systems an empty file)."""
    tmp = temporary_path(path)
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            if durable:
                f.flush()
                os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise
    if durable:
        sync_folder(os.path.dirname(os.path.abspath(path)))
    return path


def npz_bytes(compressed=False, **arrays):
    """The bytes of a NumPy .npz archive of `arrays`."""
    buf = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(buf, **arrays)
    return buf.getvalue()


def save_npz(path, compressed=False, **arrays):
    """np.savez (or savez_compressed) to `path`, atomically."""
    return write_bytes(path, npz_bytes(compressed, **arrays))


def load_npz(path, names):
    """dict name -> array of the arrays `names` of an .npz file (no pickles); OSError when it
    cannot be read, ValueError naming the file when it is no .npz or an array is missing. The
    caller checks the sizes."""
    import zipfile
    import numpy as np
    try:
        with np.load(path, allow_pickle=False) as data:
            return {name: np.array(data[name]) for name in names}
    except KeyError as e:
        raise ValueError(f"{path}: no {e} array") from None
    except zipfile.BadZipFile as e:
        raise ValueError(f"{path}: {e}") from None
