#!/usr/bin/env python3
"""The installable zip's native part, shared by ``.ci/package`` (which builds the zip) and
``blender_tests/test_install_zip.py`` (which checks it): the allow-list of system libraries,
ELF dynamic-section reading (``readelf -d``), the walk over NEEDED entries that finds which
shared libraries ``_native`` needs, and the check that every NEEDED entry of a staged tree
resolves inside the tree or to the allow-list.

    plume_zip.py version ADDON_DIR            # prints the add-on version (manifest == bl_info)
    plume_zip.py stage ADDON_DIR NATIVE_SO OUT_DIR
    plume_zip.py check PACKAGE_DIR            # exit 1, listing what does not resolve

Standard library only; runs under /usr/bin/python3 and inside any Blender's Python.
"""

import ast
import os
import re
import shutil
import subprocess
import sys

#: What every x86-64 Linux system (glibc, GCC runtime) and every Blender already has: never
#: bundled. Everything else ``_native`` needs, directly or transitively, goes into ``lib/``.
SYSTEM_LIBS = frozenset({
    "libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1",
    "ld-linux-x86-64.so.2", "libstdc++.so.6", "libgcc_s.so.1",
})

#: RUNPATH the packaging sets: the native module finds its libraries in lib/, each library
#: finds its siblings next to itself.
NATIVE_RUNPATH = "$ORIGIN/lib"
LIB_RUNPATH = "$ORIGIN"
LIB_DIR = "lib"
PACKAGE = "plume"
#: Never copied from the add-on's source folder into the zip.
EXCLUDED_DIRS = {"__pycache__"}
EXCLUDED_FILE = re.compile(r"(\.pyc$|^_native.*\.so$|^\.)")

_DYN = re.compile(r"\((NEEDED|RUNPATH|RPATH|SONAME)\)\s+[^\[]*\[(.*)\]")


class PackagingError(Exception):
    pass


def elf_dynamic(path):
    """{"needed": [...], "runpath": [...], "rpath": [...], "soname": str|None} of an ELF file."""
    out = subprocess.run(["readelf", "-d", "-W", path], capture_output=True, text=True)
    if out.returncode != 0:
        raise PackagingError(f"readelf -d {path} failed: {out.stderr.strip()}")
    info = {"needed": [], "runpath": [], "rpath": [], "soname": None}
    for kind, value in _DYN.findall(out.stdout):
        if kind == "NEEDED":
            info["needed"].append(value)
        elif kind == "SONAME":
            info["soname"] = value
        else:
            info[kind.lower()] = [p for p in value.split(":") if p]
    return info


def is_elf(path):
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


_ldconfig_cache = None


def ldconfig_map():
    """soname -> path of the x86-64 libraries in the dynamic loader's cache (``ldconfig -p``)."""
    global _ldconfig_cache
    if _ldconfig_cache is None:
        exe = shutil.which("ldconfig") or "/sbin/ldconfig"
        out = subprocess.run([exe, "-p"], capture_output=True, text=True, check=True).stdout
        found = {}
        for line in out.splitlines():
            m = re.match(r"\s*(\S+)\s+\(([^)]*)\)\s+=>\s+(\S+)", line)
            if m and "x86-64" in m.group(2):
                found.setdefault(m.group(1), m.group(3))
        _ldconfig_cache = found
    return _ldconfig_cache


def ldd_map(path):
    """soname -> path as ``ldd`` resolves the whole tree of `path` (the fallback of ldconfig)."""
    out = subprocess.run(["ldd", path], capture_output=True, text=True).stdout
    return {m.group(1): m.group(2) for m in re.finditer(r"^\s*(\S+)\s+=>\s+(/\S+)", out, re.M)}


def needed_closure(root):
    """{soname: real file} of every shared library `root` needs, transitively, outside
    SYSTEM_LIBS, found by walking NEEDED entries and resolving each with the loader's cache
    (ldconfig -p), falling back to ldd of `root`. Raises PackagingError on an unresolved one."""
    found, queue, via_ldd = {}, [root], None
    while queue:
        obj = queue.pop(0)
        for soname in elf_dynamic(obj)["needed"]:
            if soname in SYSTEM_LIBS or soname in found:
                continue
            path = ldconfig_map().get(soname)
            if path is None:
                via_ldd = via_ldd if via_ldd is not None else ldd_map(root)
                path = via_ldd.get(soname)
            if path is None or not os.path.exists(path):
                raise PackagingError(f"{soname} (needed by {os.path.basename(obj)}) is not "
                                     "found by ldconfig -p or ldd: install its Debian package")
            found[soname] = os.path.realpath(path)
            queue.append(found[soname])
    return found


def _expand(entry, origin):
    return os.path.normpath(entry.replace("$ORIGIN", origin).replace("${ORIGIN}", origin))


def check_tree(root):
    """(problems, report) for every ELF file under `root`: each NEEDED entry must be in
    SYSTEM_LIBS or exist in one of the file's RUNPATH folders, and those folders must lie inside
    `root`. `report` maps each file (relative) to its NEEDED, RUNPATH and where each resolved."""
    problems, report = [], {}
    root = os.path.abspath(root)
    for dirpath, dirs, files in os.walk(root):
        for name in sorted(files):
            path = os.path.join(dirpath, name)
            if os.path.islink(path) or not is_elf(path):
                continue
            rel = os.path.relpath(path, root)
            info = elf_dynamic(path)
            origin = os.path.dirname(path)
            dirs_ = [_expand(e, origin) for e in info["runpath"]]
            resolved = {}
            if info["rpath"]:
                problems.append(f"{rel}: has DT_RPATH {info['rpath']} (RUNPATH expected)")
            for d in dirs_:
                if os.path.commonpath([d, root]) != root:
                    problems.append(f"{rel}: RUNPATH entry {d} points outside the package")
            for soname in info["needed"]:
                hit = next((os.path.join(d, soname) for d in dirs_
                            if os.path.isfile(os.path.join(d, soname))), None)
                if hit is not None:
                    resolved[soname] = os.path.relpath(hit, root)
                elif soname in SYSTEM_LIBS:
                    resolved[soname] = "(system)"
                else:
                    problems.append(f"{rel}: NEEDED {soname} is neither in the package (RUNPATH "
                                    f"{info['runpath']}) nor a system library")
                    resolved[soname] = None
            report[rel] = {"needed": info["needed"], "runpath": info["runpath"],
                           "soname": info["soname"], "resolved": resolved}
    return problems, report


def addon_versions(addon_dir):
    """(manifest version, bl_info version as "x.y.z") of an add-on source folder."""
    import tomllib
    with open(os.path.join(addon_dir, "blender_manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    with open(os.path.join(addon_dir, "__init__.py"), encoding="utf-8") as f:
        tree = ast.parse(f.read())
    bl_info = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "bl_info"
                                                for t in node.targets):
            bl_info = ast.literal_eval(node.value)
    if bl_info is None:
        raise PackagingError(f"no bl_info in {addon_dir}/__init__.py")
    return str(manifest["version"]), ".".join(str(v) for v in bl_info["version"])


def addon_version(addon_dir):
    manifest, bl_info = addon_versions(addon_dir)
    if manifest != bl_info:
        raise PackagingError(
            f"version mismatch: blender_manifest.toml says {manifest!r} but bl_info['version'] in "
            f"__init__.py says {bl_info!r}; make them equal before packaging")
    return manifest


def _run(*cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise PackagingError(f"{' '.join(cmd)} failed: {out.stderr.strip()}")


def stage(addon_dir, native, out_dir):
    """Copies the add-on's files, the native module and its libraries into `out_dir` (the
    zip's top folder), strips them and sets their RUNPATH. Returns {soname: size in bytes}."""
    if os.path.exists(out_dir):
        shutil.rmtree(out_dir)

    def ignore(d, names):
        return [n for n in names if (n in EXCLUDED_DIRS and os.path.isdir(os.path.join(d, n)))
                or EXCLUDED_FILE.search(n)]
    shutil.copytree(addon_dir, out_dir, ignore=ignore)
    libs = needed_closure(native)
    lib_dir = os.path.join(out_dir, LIB_DIR)
    os.makedirs(lib_dir)
    sizes = {}
    for soname, src in sorted(libs.items()):
        dst = os.path.join(lib_dir, soname)
        shutil.copyfile(src, dst)  # the real file under its SONAME, no symlinks
        os.chmod(dst, 0o755)
        _run("strip", "--strip-unneeded", dst)   # strip first: patchelf after strip is safe
        _run("patchelf", "--set-rpath", LIB_RUNPATH, dst)
        sizes[soname] = os.path.getsize(dst)
    dst = os.path.join(out_dir, os.path.basename(native))
    shutil.copyfile(native, dst)
    os.chmod(dst, 0o755)
    _run("strip", "--strip-unneeded", dst)
    _run("patchelf", "--set-rpath", NATIVE_RUNPATH, dst)
    sizes[os.path.basename(native)] = os.path.getsize(dst)
    return sizes


def main(argv):
    try:
        if argv[:1] == ["version"] and len(argv) == 2:
            print(addon_version(argv[1]))
        elif argv[:1] == ["stage"] and len(argv) == 4:
            sizes = stage(*argv[1:])
            for name, size in sizes.items():
                print(f"  {name:40s} {size / 1e6:7.2f} MB")
        elif argv[:1] == ["check"] and len(argv) == 2:
            problems, report = check_tree(argv[1])
            for rel, r in sorted(report.items()):
                print(f"  {rel}: RUNPATH {':'.join(r['runpath']) or '-'}, "
                      f"{sum(v not in (None, '(system)') for v in r['resolved'].values())} "
                      f"bundled + {sum(v == '(system)' for v in r['resolved'].values())} system "
                      "NEEDED")
            for p in problems:
                print("PROBLEM:", p, file=sys.stderr)
            return 1 if problems else 0
        else:
            print(__doc__, file=sys.stderr)
            return 2
    except PackagingError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
