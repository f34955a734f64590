#!/usr/bin/env bash
# The portable build's C++ dependencies, static and position independent, built from Debian 12's
# source packages with zig for x86_64-linux-gnu glibc 2.28 (cmake/portable/README.md):
# zlib, LZ4, c-blosc, oneTBB, OpenSubdiv (Far + Osd CPU) and OpenVDB (core, no delayed loading,
# so no Boost.Iostreams). Prints the install prefix on its last line.
#
# The prefix is cached by a key of everything that decides its contents (this folder's files,
# the source package versions, zig's version) under $PLUME_CACHE (~/.cache/plume): a second run
# with the same key reuses it in a second; anything changed builds a new prefix.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
CACHE="${PLUME_CACHE:-$HOME/.cache/plume}"
JOBS="${PLUME_JOBS:-$(nproc)}"
# Debian 12's versions (apt-get source NAME=VERSION); bump together with the key below.
SOURCES=(zlib=1:1.2.13.dfsg-1 lz4=1.9.4-1 c-blosc=1.21.3+ds-1 onetbb=2021.8.0-2+deb12u1
         opensubdiv=3.5.0-2 openvdb=10.0.1-2)
ZIG_VERSION=0.13.0

log() { echo "== portable deps: $*" >&2; }

# zig from the Python package index (the ziglang wheel), in a venv of its own.
zig_binary() {
  local venv="$CACHE/venvs/ziglang-$ZIG_VERSION"
  if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -m ziglang version >/dev/null 2>&1; then
    log "installing ziglang $ZIG_VERSION into $venv"
    rm -rf "$venv"
    /usr/bin/python3 -m venv "$venv"
    "$venv/bin/pip" install -q "ziglang==$ZIG_VERSION" >&2
  fi
  "$venv/bin/python" -c 'import ziglang, os; print(os.path.join(os.path.dirname(ziglang.__file__), "zig"))'
}

# Debian's upstream tarballs (apt-get source --download-only; needs a deb-src entry, which
# .ci/common.sh adds). Debian's own patches are not applied: openvdb's .debian.tar.xz is absent
# from the archive, and none of the others changes the library code we build.
fetch_sources() {
  local dir="$CACHE/src" spec
  mkdir -p "$dir"
  for spec in "${SOURCES[@]}"; do
    local name="${spec%%=*}" version="${spec#*=}"
    version="${version#*:}"  # no epoch in file names
    if ! ls "$dir/${name}_${version%-*}".orig.tar.* >/dev/null 2>&1; then
      log "downloading the source of $name $version"
      # openvdb's .debian.tar.xz answers 404; the .orig tarball is all we need.
      (cd "$dir" && apt-get source --download-only -q "$spec" >&2) || true
      ls "$dir/${name}_${version%-*}".orig.tar.* >/dev/null 2>&1 || {
        echo "could not download the source of $name $version (is a deb-src line for bookworm" \
             "in /etc/apt/sources.list.d?)" >&2; exit 1; }
    fi
  done
  echo "$dir"
}

unpack() {  # unpack NAME VERSION: a fresh source tree in $WORK, printed
  local name="$1" version="$2" tarball
  tarball="$(ls "$SRC/${name}_${version}".orig.tar.* | head -n 1)"
  rm -rf "$WORK/$name"
  mkdir -p "$WORK/$name"
  tar -xf "$tarball" -C "$WORK/$name" --strip-components=1
  echo "$WORK/$name"
}

cmake_build() {  # cmake_build SOURCE_DIR [cmake args...]
  local src="$1"; shift
  cmake -S "$src" -B "$src/_build" -G Ninja -Wno-dev \
    -DCMAKE_TOOLCHAIN_FILE="$HERE/toolchain.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$PREFIX" -DCMAKE_INSTALL_LIBDIR=lib \
    -DCMAKE_FIND_ROOT_PATH="$PREFIX" -DCMAKE_PREFIX_PATH="$PREFIX" "$@" >"$src/_configure.log" 2>&1 \
    || { tail -n 40 "$src/_configure.log" >&2; return 1; }
  cmake --build "$src/_build" -j "$JOBS" >"$src/_build.log" 2>&1 \
    || { grep -m 20 -B 2 -A 8 'error' "$src/_build.log" >&2 || tail -n 40 "$src/_build.log" >&2; return 1; }
  cmake --install "$src/_build" >/dev/null
}

build_zlib() {  # compiled by hand: Debian's dfsg tarball lacks files zlib's CMake lists
  local src f; src="$(unpack zlib 1.2.13.dfsg)"
  mkdir -p "$src/_obj" "$PREFIX/lib" "$PREFIX/include"
  for f in adler32 compress crc32 deflate gzclose gzlib gzread gzwrite infback inffast inflate \
           inftrees trees uncompr zutil; do
    "$HERE/zig-cc" -O2 -w -fPIC -fvisibility=hidden -DHAVE_UNISTD_H -c "$src/$f.c" -o "$src/_obj/$f.o"
  done
  "$HERE/zig-ar" rcs "$PREFIX/lib/libz.a" "$src"/_obj/*.o
  cp "$src/zlib.h" "$src/zconf.h" "$PREFIX/include/"
}

build_lz4() {  # LZ4's CMake lives in build/cmake
  local src; src="$(unpack lz4 1.9.4)"
  cmake_build "$src/build/cmake" -DLZ4_BUILD_CLI=OFF -DLZ4_BUILD_LEGACY_LZ4C=OFF \
    -DBUILD_SHARED_LIBS=OFF -DBUILD_STATIC_LIBS=ON
}

build_blosc() {  # Debian's +ds tarball has no bundled compressors: LZ4 and zlib from $PREFIX
  local src; src="$(unpack c-blosc 1.21.3+ds)"
  cmake_build "$src" -DBUILD_SHARED=OFF -DBUILD_STATIC=ON -DBUILD_TESTS=OFF -DBUILD_FUZZERS=OFF \
    -DBUILD_BENCHMARKS=OFF -DPREFER_EXTERNAL_LZ4=ON -DPREFER_EXTERNAL_ZLIB=ON \
    -DDEACTIVATE_SNAPPY=ON -DDEACTIVATE_ZSTD=ON -DDEACTIVATE_AVX2=ON \
    -DLZ4_INCLUDE_DIR="$PREFIX/include" -DLZ4_LIBRARY="$PREFIX/lib/liblz4.a"
}

build_tbb() {
  local src; src="$(unpack onetbb 2021.8.0)"
  cmake_build "$src" -DBUILD_SHARED_LIBS=OFF -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF -DTBB_STRICT=OFF \
    -DTBBMALLOC_BUILD=OFF -DTBB_ENABLE_IPO=OFF
}

build_opensubdiv() {  # Far + Osd CPU only: no GPU back ends, no examples
  local src; src="$(unpack opensubdiv 3.5.0)"
  cmake_build "$src" -DNO_EXAMPLES=ON -DNO_TUTORIALS=ON -DNO_REGRESSION=ON -DNO_DOC=ON \
    -DNO_PTEX=ON -DNO_OMP=ON -DNO_TBB=ON -DNO_CUDA=ON -DNO_OPENCL=ON -DNO_CLEW=ON \
    -DNO_OPENGL=ON -DNO_GLFW=ON -DNO_DX=ON -DNO_METAL=ON -DNO_TESTS=ON -DNO_GLTESTS=ON \
    -DNO_MACOS_FRAMEWORK=ON -DBUILD_SHARED_LIBS=OFF
  rm -f "$PREFIX"/lib/libosd*.so*
}

build_headers() {  # header-only libraries, Debian's (libboost-dev, libglm-dev)
  # Linked into the prefix's own include folder, so that nothing else of the host's
  # /usr/include (glibc 2.36's headers) is ever on the include path. Boost: the headers
  # OpenVDB includes (uuid, numeric casts); GLM: Plume's own vector maths.
  mkdir -p "$PREFIX/include"
  ln -sfn /usr/include/boost "$PREFIX/include/boost"
  ln -sfn /usr/include/glm "$PREFIX/include/glm"
}

build_openvdb() {
  local src; src="$(unpack openvdb 10.0.1)"
  cmake_build "$src" -DOPENVDB_BUILD_CORE=ON -DOPENVDB_CORE_SHARED=OFF -DOPENVDB_CORE_STATIC=ON \
    -DOPENVDB_BUILD_BINARIES=OFF -DOPENVDB_BUILD_PYTHON_MODULE=OFF -DOPENVDB_BUILD_UNITTESTS=OFF \
    -DOPENVDB_USE_DELAYED_LOADING=OFF -DUSE_EXPLICIT_INSTANTIATION=OFF -DUSE_BLOSC=ON \
    -DUSE_ZLIB=ON -DUSE_LOG4CPLUS=OFF -DUSE_EXR=OFF -DUSE_IMATH_HALF=OFF -DUSE_PNG=OFF \
    -DUSE_CCACHE=OFF -DUSE_PKGCONFIG=OFF -DUSE_STATIC_DEPENDENCIES=ON \
    -DDISABLE_CMAKE_SEARCH_PATHS=ON -DDISABLE_DEPENDENCY_VERSION_CHECKS=ON \
    -DTBB_ROOT="$PREFIX" -DBLOSC_ROOT="$PREFIX" -DZLIB_ROOT="$PREFIX" \
    -DBlosc_INCLUDE_DIR="$PREFIX/include" -DBlosc_LIBRARY="$PREFIX/lib/libblosc.a" \
    -DOPENVDB_ENABLE_RPATH=OFF -DCMAKE_CXX_FLAGS="-I$PREFIX/include"
}

main() {
  export PLUME_ZIG; PLUME_ZIG="$(zig_binary)"
  SRC="$(fetch_sources)"
  local key
  key="$( (cat "$HERE/deps.sh" "$HERE/toolchain.cmake" "$HERE/zig-wrap"; printf '%s\n' "${SOURCES[@]}" \
          "$ZIG_VERSION") | sha256sum | cut -c1-16)"
  PREFIX="$CACHE/deps/$key"
  if [ -f "$PREFIX/.complete" ]; then
    log "reusing $PREFIX"
    echo "$PREFIX"; return
  fi
  export ZIG_GLOBAL_CACHE_DIR="$CACHE/zig-cache" ZIG_LOCAL_CACHE_DIR="$CACHE/zig-cache"
  # Prefixes of other keys that never completed (an interrupted build) are only litter.
  local other
  for other in "$CACHE"/deps/*/; do
    [ -f "$other/.complete" ] || rm -rf "$other"
  done
  rm -rf "$PREFIX" "$CACHE"/deps-build.*; mkdir -p "$PREFIX"
  WORK="$(mktemp -d "$CACHE/deps-build.XXXXXX")"
  local start=$SECONDS step
  for step in headers zlib lz4 blosc tbb opensubdiv openvdb; do
    log "building $step"
    "build_$step"
    log "$step done ($((SECONDS - start)) s so far)"
  done
  rm -rf "$WORK"
  touch "$PREFIX/.complete"
  echo "$PREFIX"
}

main "$@"
