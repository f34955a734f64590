# Shared set-up of the README's two commands: Debian packages, native build, add-on install.
# Sourced by .ci/main and .ci/test; every step is idempotent.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"

PACKAGES=(blender cmake g++ pybind11-dev libopenvdb-dev libglm-dev libosd-dev libtbb-dev
          libboost-dev libboost-iostreams-dev googletest libgtest-dev libbenchmark-dev python3-pytest python3-numpy python3-matplotlib python3-markdown
          slurm-wlm munge
          xvfb xauth libgl1-mesa-dri python3-venv patchelf zip unzip binutils python3-openvdb
          ninja-build dpkg-dev clang-14 libclang-rt-14-dev)  # clang: .ci/fuzz's, installed here
# so that no apt run of .ci/fuzz meets .ci/test's background download of the portable sources

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

# The portable build takes its C++ dependencies from Debian's source packages (apt-get source):
# a deb-src entry for bookworm main, added once beside the machine's own entries.
SOURCES_ENTRY=/etc/apt/sources.list.d/plume-src.sources
enable_deb_src() {
  if ! grep -rqs '^Types:.*deb-src' /etc/apt/sources.list.d/ && \
     ! grep -qs '^deb-src .*bookworm' /etc/apt/sources.list; then
    echo "== adding a deb-src entry for bookworm ($SOURCES_ENTRY)"
    printf '%s\n' "Types: deb-src" "URIs: http://deb.debian.org/debian" "Suites: bookworm" \
      "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" \
      | $SUDO tee "$SOURCES_ENTRY" >/dev/null
    $SUDO apt-get update -q
  fi
}

build_native() {
  echo "== building the native module"
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
  cmake --build "$BUILD" -j "$(nproc)"
}

# Every Blender the tests run (blender_tests/run.py): Debian's 3.4.1 and the bpy wheels.
BLENDER_VERSIONS=(3.4 4.2 4.5 5.0 5.3)

# The Blenders that run CPython 3.11, the development module's.
BLENDERS_PY311=(3.4 4.2 4.5 5.0)

# Where the given Blenders find user add-ons: one folder when $BLENDER_USER_SCRIPTS is set, else
# each version's own under ~/.config/blender.
addon_dirs() {
  if [ -n "${BLENDER_USER_SCRIPTS:-}" ]; then
    echo "$BLENDER_USER_SCRIPTS/addons/plume"
  else
    local v
    for v in "$@"; do echo "$HOME/.config/blender/$v/scripts/addons/plume"; done
  fi
}

# The development install: the add-on with the module of build_native (Debian's libraries,
# CPython 3.11), for `.ci/main` and working on the add-on, in the Blenders it can serve.
install_addon() {
  local dest
  for dest in $(addon_dirs "${BLENDERS_PY311[@]}"); do
    echo "== installing the add-on into $dest"
    rm -rf "$dest"
    mkdir -p "$dest"
    (cd "$ROOT/addon" && tar --exclude='__pycache__' -cf - .) | (cd "$dest" && tar -xf -)
    cp "$BUILD"/native/_native*.so "$dest/"
    /usr/bin/python3 "$ROOT/blender_tests/install_zip/plume_manual.py" "$ROOT" "$dest/manual"
  done
}

# The artist's install: the zip's plume/ folder (both portable modules) into every Blender's
# user add-on folder, so the Blender tests run exactly what ships.
install_zip_package() {
  local zip="$1" dest stage
  stage="$(mktemp -d)"
  unzip -q "$zip" -d "$stage"
  for dest in $(addon_dirs "${BLENDER_VERSIONS[@]}"); do
    echo "== installing $(basename "$zip") into $dest"
    rm -rf "$dest"
    mkdir -p "$(dirname "$dest")"
    cp -r "$stage/plume" "$dest"
  done
  rm -rf "$stage"
}

# The bpy venvs (4.2 to 5.3, pinned in blender_tests/run.py), created once and reused.
setup_bpy() {
  /usr/bin/python3 "$ROOT/blender_tests/run.py" --setup all
}

# openjd-cli, Open Job Description's own runner (the job format of AWS Deadline Cloud), for
# blender_tests/test_farm_openjd.py: a venv ~/.cache/plume/venvs/openjd from Debian's Python with
# the CLI and every dependency pinned (installed without resolving, then `pip check`), created
# once and made again when the pins change.
OPENJD_PINS=(openjd-cli==0.8.0 openjd-model==0.13.0 openjd-sessions==0.13.0 pydantic==2.14.4
             pydantic_core==2.50.5 annotated-types==0.8.0 typing-inspection==0.4.5
             typing_extensions==4.16.0 PyYAML==6.0.4)
setup_openjd() {
  local venv="${PLUME_VENV_ROOT:-$HOME/.cache/plume/venvs}/openjd"
  if [ "$(cat "$venv/plume-pins" 2>/dev/null)" = "${OPENJD_PINS[*]}" ] && \
     "$venv/bin/openjd" --version >/dev/null 2>&1; then
    echo "== openjd-cli: venv ready ($venv)"
    return
  fi
  echo "== openjd-cli: making its venv ($venv)"
  rm -rf "$venv"
  /usr/bin/python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check --no-deps "${OPENJD_PINS[@]}"
  "$venv/bin/pip" check -q --disable-pip-version-check >/dev/null
  echo "${OPENJD_PINS[*]}" >"$venv/plume-pins"
  "$venv/bin/openjd" --version
}

setup_all() {
  install_packages
  build_native
  install_addon
}

# The portable modules (cmake/portable/build.sh: static dependencies, glibc 2.28, one module per
# CPython); the dependency prefix is cached under ~/.cache/plume/deps by its key.
PORTABLE_BUILD="$ROOT/build-portable"
build_portable() {
  enable_deb_src
  echo "== building the portable native modules (CPython 3.11 and 3.13, glibc 2.28)"
  bash "$ROOT/cmake/portable/build.sh" "$PORTABLE_BUILD" | tail -n 1
}

# The installable zip dist/plume-<version>-linux-x64.zip: one top folder plume/ with the add-on
# and one self-contained _native per CPython; a Blender 3.4 add-on zip and a Blender 4.2+
# extension at once. Needs build_portable first; checks every ELF file against the glibc 2.28
# floor (plume_zip.py check) and prints the zip's path and size.
package_zip() {
  local helper="$ROOT/blender_tests/install_zip/plume_zip.py" version stage zip ext
  version="$(/usr/bin/python3 "$helper" version "$ROOT/addon")"
  zip="$ROOT/dist/plume-$version-linux-x64.zip"
  stage="$(mktemp -d)"
  echo "== packaging plume $version"
  if ! { /usr/bin/python3 "$helper" stage "$ROOT/addon" "$stage/plume" \
           "$PORTABLE_BUILD"/modules/_native.cpython-*.so &&
         /usr/bin/python3 "$helper" check "$stage/plume" &&
         mkdir -p "$ROOT/dist" && rm -f "$zip" &&
         (cd "$stage" && zip -q -r -X -9 "$zip" plume); }; then
    rm -rf "$stage"
    echo "== packaging failed" >&2
    return 1
  fi
  rm -rf "$stage"
  # Blender's own strict extension validator (`blender --command extension validate`, the
  # extensions platform's check) of every bpy venv there is, each in its own Python: the
  # manifest must pass the oldest (4.2) and the newest (5.3) alike.
  for ext in "${PLUME_VENV_ROOT:-$HOME/.cache/plume/venvs}"/bpy-*/lib/python3.1*/site-packages/\
bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py; do
    [ -f "$ext" ] || continue
    if ! "${ext%%/lib/python3.1*}/bin/python" "$ext" validate "$zip" >/dev/null 2>&1; then
      echo "== $zip fails Blender's extension validation ($ext):" >&2
      "${ext%%/lib/python3.1*}/bin/python" "$ext" validate "$zip" 2>&1 | sed 's/^/   /' >&2 || true
      rm -f "$zip"
      return 1
    fi
  done
  echo "== $zip: $(du -h "$zip" | cut -f1) ($(stat -c %s "$zip") bytes," \
       "$(unzip -Z1 "$zip" | wc -l) entries)"
  PLUME_ZIP_BUILT="$zip"
}
