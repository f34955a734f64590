"""pytest set-up for the native module: import _native from $PLUME_NATIVE_DIR.

PLUME_NATIVE_DIR is the directory holding _native.cpython-*.so; by default the CMake build
tree of this checkout (<repo>/build/native).
"""
import os
import pathlib
import sys

_REPO = pathlib.Path(__file__).resolve().parents[3]
NATIVE_DIR = os.environ.get("PLUME_NATIVE_DIR", str(_REPO / "build" / "native"))
if NATIVE_DIR not in sys.path:
    sys.path.insert(0, NATIVE_DIR)
