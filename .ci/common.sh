# Shared set-up of the README's two commands: Debian packages, native build, add-on install.
# Sourced by .ci/main and .ci/test; every step is idempotent.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"

PACKAGES=(blender cmake g++ pybind11-dev libopenvdb-dev libglm-dev libosd-dev libtbb-dev
          libboost-dev libboost-iostreams-dev googletest libgtest-dev libbenchmark-dev python3-pytest python3-numpy python3-matplotlib
          xvfb xauth libgl1-mesa-dri python3-venv patchelf zip unzip binutils python3-openvdb)

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing: ${missing[*]}"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
}

build_native() {
  echo "== building the native module"
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
  cmake --build "$BUILD" -j "$(nproc)"
}

# Where each supported Blender (3.4.1, 4.5, 5.0) finds user add-ons: one folder when
# $BLENDER_USER_SCRIPTS is set, else each version's own under ~/.config/blender.
addon_dirs() {
  if [ -n "${BLENDER_USER_SCRIPTS:-}" ]; then
    echo "$BLENDER_USER_SCRIPTS/addons/plume"
  else
    local v
    for v in 3.4 4.5 5.0; do echo "$HOME/.config/blender/$v/scripts/addons/plume"; done
  fi
}

install_addon() {
  local dest
  for dest in $(addon_dirs); do
    echo "== installing the add-on into $dest"
    rm -rf "$dest"
    mkdir -p "$dest"
    (cd "$ROOT/addon" && tar --exclude='__pycache__' -cf - .) | (cd "$dest" && tar -xf -)
    cp "$BUILD"/native/_native*.so "$dest/"
  done
}

# The bpy 4.5 LTS and 5.x venvs (pinned in blender_tests/run.py), created once and reused.
setup_bpy() {
  /usr/bin/python3 "$ROOT/blender_tests/run.py" --setup all
}

setup_all() {
  install_packages
  build_native
  install_addon
}

# The installable zip dist/plume-<version>-linux-x64.zip: one top folder plume/ with the add-on,
# _native and lib/ (every library _native needs outside the allow-list in
# blender_tests/install_zip/plume_zip.py, RUNPATH $ORIGIN). A Blender 3.4 add-on zip and a
# Blender 4.2+ extension at once. Needs build_native first; prints the zip's path and size.
package_zip() {
  local helper="$ROOT/blender_tests/install_zip/plume_zip.py" version stage zip ext
  version="$(/usr/bin/python3 "$helper" version "$ROOT/addon")"
  zip="$ROOT/dist/plume-$version-linux-x64.zip"
  stage="$(mktemp -d)"
  echo "== packaging plume $version"
  if ! { /usr/bin/python3 "$helper" stage "$ROOT/addon" "$BUILD"/native/_native*.so \
           "$stage/plume" &&
         /usr/bin/python3 "$helper" check "$stage/plume" &&
         mkdir -p "$ROOT/dist" && rm -f "$zip" &&
         (cd "$stage" && zip -q -r -X -9 "$zip" plume); }; then
    rm -rf "$stage"
    echo "== packaging failed" >&2
    return 1
  fi
  rm -rf "$stage"
  # Blender's own strict extension validator (`blender --command extension validate`, the
  # extensions platform's check), from a bpy venv when there is one: the manifest must pass it.
  ext="$(ls "${PLUME_VENV_ROOT:-$HOME/.cache/plume/venvs}"/bpy-*/lib/python3.11/site-packages/\
bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | tail -n 1 || true)"
  if [ -n "$ext" ] && ! /usr/bin/python3 "$ext" validate "$zip" >/dev/null 2>&1; then
    echo "== $zip fails Blender's extension validation:" >&2
    /usr/bin/python3 "$ext" validate "$zip" 2>&1 | sed 's/^/   /' >&2 || true
    rm -f "$zip"
    return 1
  fi
  echo "== $zip: $(du -h "$zip" | cut -f1) ($(stat -c %s "$zip") bytes," \
       "$(unzip -Z1 "$zip" | wc -l) entries)"
}
