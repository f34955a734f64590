#!/usr/bin/env bash
# The artist's native modules: one self-contained _native per CPython that Blender bundles
# (3.11 for Blender 3.4 and 4.2-5.0, 3.13 for 5.1+), for x86_64 Linux with glibc 2.28
# (cmake/portable/README.md). Prints the folder holding the modules on its last line.
#
#   cmake/portable/build.sh [BUILD_DIR]      # default: build-portable/ in the repository
#
# CPython 3.11: Debian's /usr/bin/python3; 3.13: found by blender_tests/pythons.py
# (PLUME_PYTHON313, pyenv, python3.13 on PATH). Only their headers are used.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
BUILD="${1:-$ROOT/build-portable}"
CACHE="${PLUME_CACHE:-$HOME/.cache/plume}"
PYBIND11_VERSION=2.13.6

log() { echo "== portable build: $*" >&2; }

PREFIX="$(bash "$HERE/deps.sh" | tail -n 1)"
export PLUME_ZIG
PLUME_ZIG="$("$CACHE/venvs/ziglang-0.13.0/bin/python" -c \
  'import ziglang, os; print(os.path.join(os.path.dirname(ziglang.__file__), "zig"))')"
export ZIG_GLOBAL_CACHE_DIR="$CACHE/zig-cache" ZIG_LOCAL_CACHE_DIR="$CACHE/zig-cache"

# pybind11's headers, from its wheel (Debian's 2.10 predates CPython 3.13).
PB_VENV="$CACHE/venvs/pybind11-$PYBIND11_VERSION"
if ! "$PB_VENV/bin/python" -c "import pybind11" 2>/dev/null; then
  log "installing pybind11 $PYBIND11_VERSION into $PB_VENV"
  rm -rf "$PB_VENV"; /usr/bin/python3 -m venv "$PB_VENV"
  "$PB_VENV/bin/pip" install -q "pybind11==$PYBIND11_VERSION" >&2
fi
PB_INCLUDE="$("$PB_VENV/bin/python" -c 'import pybind11; print(pybind11.get_include())')"

# Each CPython's headers, copied into the build folder: only Python's own folder may be on the
# include path (Debian's /usr/include also holds glibc 2.36's headers), so Debian's multiarch
# pyconfig.h wrapper is replaced by the real one.
stage_headers() {  # stage_headers PYTHON -> "<tag>=<folder>"
  local py="$1" inc tag real out
  inc="$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
  tag="$("$py" -c 'import sys; print("%d%d" % sys.version_info[:2])')"
  [ -f "$inc/Python.h" ] || { echo "no Python.h in $inc (CPython $tag headers)" >&2; exit 1; }
  out="$BUILD/python-headers/$tag"
  # cp -a keeps the headers' own times: a rebuild does not recompile the bindings for nothing.
  rm -rf "$out"; mkdir -p "$out"; cp -a "$inc/." "$out/"
  real="$(dirname "$inc")/x86_64-linux-gnu/$(basename "$inc")/pyconfig.h"
  if grep -q '<x86_64-linux-gnu/' "$out/pyconfig.h" && [ -f "$real" ]; then
    cp -a "$real" "$out/pyconfig.h"
  fi
  echo "$tag=$out"
}
PY313="$(/usr/bin/python3 "$ROOT/blender_tests/pythons.py" 3.13)" || exit 1
INCLUDES="$(stage_headers /usr/bin/python3);$(stage_headers "$PY313")"

log "configuring $BUILD (dependencies: $PREFIX)"
mkdir -p "$BUILD"
cmake -S "$ROOT" -B "$BUILD" -G Ninja -Wno-dev -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="$HERE/toolchain.cmake" -DCMAKE_FIND_ROOT_PATH="$PREFIX" \
  -DPLUME_PORTABLE=ON -DPLUME_BUILD_TESTS=OFF -DPLUME_BUILD_BENCH=OFF \
  -DPLUME_DEPS_PREFIX="$PREFIX" -DPLUME_PYBIND11_INCLUDE="$PB_INCLUDE" \
  -DPLUME_PYTHON_INCLUDES="$INCLUDES" >"$BUILD/configure.log" 2>&1 \
  || { tail -n 30 "$BUILD/configure.log" >&2; exit 1; }
log "building the modules"
cmake --build "$BUILD" -j "${PLUME_JOBS:-$(nproc)}" >&2
echo "$BUILD/modules"
