"""Files of the cache folders, no ``bpy``: one atomic write (``atomic``) and one manifest.json
reader/writer (``manifest``) that every pipeline uses."""

from .atomic import load_npz, no_room, save_npz, sweep_temporaries, sync_folder, write_bytes
from .manifest import MANIFEST_NAME, manifest_path, read_manifest, write_manifest

__all__ = ["MANIFEST_NAME", "load_npz", "manifest_path", "no_room", "read_manifest", "save_npz",
           "sweep_temporaries", "sync_folder", "write_bytes", "write_manifest"]
