#!/usr/bin/env python3
"""The installable zip's native part, shared by ``.ci/package`` (which builds the zip) and
``blender_tests/test_install_zip.py`` (which checks it).

The zip holds one self-contained native module per CPython (``_native.cpython-311-…so`` for
Blender 3.4-5.0, ``_native.cpython-313-…so`` for 5.1+), built by the portable build
(cmake/portable/): OpenVDB, oneTBB, Blosc, OpenSubdiv, zlib and libc++ linked in statically
with hidden symbols. So each module needs nothing but glibc, exports nothing but its
``PyInit__native``, and within glibc asks for no symbol version above Blender's own floor
(glibc 2.28, Rocky 8). ``check`` proves all three for every ELF file of a staged tree, reading
the ELF dynamic section (``readelf -d``), the version needs (``readelf -V``, what
``objdump -T`` and ``auditwheel`` read) and the dynamic symbol table (``readelf --dyn-syms``).

    plume_zip.py version ADDON_DIR                 # the add-on version (manifest == bl_info)
    plume_zip.py stage ADDON_DIR OUT_DIR NATIVE_SO [NATIVE_SO ...]   # with manual/ (plume_manual.py)
    plume_zip.py check PACKAGE_DIR                 # exit 1, listing every problem
    plume_zip.py floor ELF_FILE [ELF_FILE ...]     # each file's highest version needs

Standard library only; runs under /usr/bin/python3 and inside any Blender's Python.
"""

import ast
import os
import re
import shutil
import subprocess
import sys

#: glibc's own libraries: the only ones a shipped ELF file may need (every Linux has them).
SYSTEM_LIBS = frozenset({
    "libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1",
    "ld-linux-x86-64.so.2",
})
#: The highest symbol version a shipped file may ask for, per version family: glibc 2.28 (Rocky
#: 8 / RHEL 8, Blender's Linux floor, manylinux_2_28) and, should libstdc++ ever be needed
#: again, GCC 8's runtime (GLIBCXX_3.4.25, CXXABI_1.3.11, libgcc_s GCC_7.0.0).
VERSION_FLOOR = {"GLIBC": (2, 28), "GLIBCXX": (3, 4, 25), "CXXABI": (1, 3, 11), "GCC": (7, 0, 0)}
#: The only dynamic symbol a native module defines (pybind11's entry point).
EXPORTS = frozenset({"PyInit__native"})
#: The CPython minor versions a release holds a module for, oldest first.
PYTHONS = ((3, 11), (3, 13))
#: Written into the package: what was built, for whom (the add-on's native.py reads MODULES).
BUILD_INFO = "PLUME_BUILD.txt"
PACKAGE = "plume"
#: Never copied from the add-on's source folder into the zip (README.md is the developers' page).
EXCLUDED_DIRS = {"__pycache__"}
EXCLUDED_FILE = re.compile(r"(\.pyc$|^_native.*\.so$|^\.|^README\.md$)")

_DYN = re.compile(r"\((NEEDED|RUNPATH|RPATH|SONAME)\)\s+[^\[]*\[(.*)\]")
_VERNEED_FILE = re.compile(r"^\s*0x[0-9a-f]+:\s+Version:\s+\d+\s+File:\s+(\S+)", re.M)
_VERNEED_NAME = re.compile(r"Name:\s+([A-Z_]+)_([0-9][0-9.]*)\s")
_MODULE = re.compile(r"^_native\.cpython-3(\d+)-x86_64-linux-gnu\.so$")


class PackagingError(Exception):
    pass


def _readelf(path, *flags):
    out = subprocess.run(["readelf", *flags, "-W", path], capture_output=True, text=True)
    if out.returncode != 0:
        raise PackagingError(f"readelf {' '.join(flags)} {path} failed: {out.stderr.strip()}")
    return out.stdout


def elf_dynamic(path):
    """{"needed": [...], "runpath": [...], "rpath": [...], "soname": str|None} of an ELF file."""
    info = {"needed": [], "runpath": [], "rpath": [], "soname": None}
    for kind, value in _DYN.findall(_readelf(path, "-d")):
        if kind == "NEEDED":
            info["needed"].append(value)
        elif kind == "SONAME":
            info["soname"] = value
        else:
            info[kind.lower()] = [p for p in value.split(":") if p]
    return info


def version_needs(path):
    """{family: highest version tuple} of the symbol versions an ELF file needs from the
    libraries it links (its .gnu.version_r section), e.g. {"GLIBC": (2, 28)}."""
    text = _readelf(path, "-V")
    start = text.find(".gnu.version_r")
    highest = {}
    for family, version in _VERNEED_NAME.findall(text[start:] if start >= 0 else ""):
        v = tuple(int(x) for x in version.strip(".").split("."))
        if v > highest.get(family, ()):
            highest[family] = v
    return highest


def dynamic_exports(path):
    """Names of the symbols an ELF file defines in its dynamic symbol table (what another
    library in the process could bind to)."""
    names = set()
    for line in _readelf(path, "--dyn-syms").splitlines():
        parts = line.split()
        # Num: Value Size Type Bind Vis Ndx Name
        if len(parts) >= 8 and parts[0].endswith(":") and parts[6] != "UND" \
                and parts[4] in ("GLOBAL", "WEAK", "UNIQUE") and parts[3] != "SECTION":
            names.add(parts[7].split("@")[0])
    return names


def is_elf(path):
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


def _fmt(v):
    return ".".join(str(x) for x in v)


def check_elf(path):
    """Problems of one shipped ELF file: a library outside glibc, a symbol version above the
    floor, an RPATH/RUNPATH, or a defined dynamic symbol other than the module's entry point."""
    name = os.path.basename(path)
    info = elf_dynamic(path)
    problems = [f"{name}: needs {lib}, which is not part of glibc (link it in statically)"
                for lib in info["needed"] if lib not in SYSTEM_LIBS]
    if info["runpath"] or info["rpath"]:
        problems.append(f"{name}: has a search path {info['runpath'] or info['rpath']} "
                        "(a self-contained module needs none)")
    for family, v in sorted(version_needs(path).items()):
        floor = VERSION_FLOOR.get(family)
        if floor is None:
            problems.append(f"{name}: needs symbol version {family}_{_fmt(v)}, of no library "
                            "allowed")
        elif v > floor:
            problems.append(f"{name}: needs {family}_{_fmt(v)}, above the floor "
                            f"{family}_{_fmt(floor)} (glibc 2.28 / GCC 8)")
    extra = sorted(dynamic_exports(path) - EXPORTS)
    if extra:
        problems.append(f"{name}: exports {len(extra)} symbols besides PyInit__native "
                        f"(e.g. {', '.join(extra[:5])}): they could bind to Blender's own "
                        "OpenVDB / oneTBB")
    return problems


def check_tree(root):
    """(problems, report) for a staged package: one module per CPython of PYTHONS, each ELF
    file within the floor (check_elf), and BUILD_INFO naming exactly the modules present.
    `report` maps each ELF file (relative) to its NEEDED entries and highest version needs."""
    problems, report = [], {}
    root = os.path.abspath(root)
    for dirpath, dirs, files in os.walk(root):
        for name in sorted(files):
            path = os.path.join(dirpath, name)
            if os.path.islink(path) or not is_elf(path):
                continue
            rel = os.path.relpath(path, root)
            problems += check_elf(path)
            report[rel] = {"needed": elf_dynamic(path)["needed"],
                           "versions": version_needs(path)}
    modules = sorted(n for n in os.listdir(root) if _MODULE.match(n))
    expected = sorted(module_name(p) for p in PYTHONS)
    if modules != expected:
        problems.append(f"native modules {modules}, expected {expected}")
    listed = build_info_modules(root)
    if listed != modules:
        problems.append(f"{BUILD_INFO} lists {listed}, the package holds {modules}")
    return problems, report


def module_name(python):
    return f"_native.cpython-{python[0]}{python[1]}-x86_64-linux-gnu.so"


def build_info_modules(package_dir):
    """The module file names BUILD_INFO lists (its "module:" lines), sorted; [] without it."""
    try:
        with open(os.path.join(package_dir, BUILD_INFO), encoding="utf-8") as f:
            return sorted(line.split(":", 1)[1].strip() for line in f
                          if line.startswith("module:"))
    except OSError:
        return []


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


def stage(addon_dir, out_dir, natives):
    """Copies the add-on's files and the native modules into `out_dir` (the zip's top folder),
    strips the modules and writes BUILD_INFO. Returns {file name: size in bytes}."""
    if os.path.exists(out_dir):
        shutil.rmtree(out_dir)

    def ignore(d, names):
        return [n for n in names if (n in EXCLUDED_DIRS and os.path.isdir(os.path.join(d, n)))
                or EXCLUDED_FILE.search(n)]
    shutil.copytree(addon_dir, out_dir, ignore=ignore)
    # The manual the add-on's help opens (manual.py), from the repository the add-on is in.
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plume_manual
    plume_manual.build(os.path.dirname(os.path.abspath(addon_dir)), os.path.join(out_dir, "manual"))
    sizes, lines = {}, [f"plume {addon_version(addon_dir)}",
                        "built by cmake/portable (zig, x86_64-linux-gnu glibc 2.28, static "
                        "OpenVDB / oneTBB / Blosc / OpenSubdiv / zlib / libc++)"]
    for native in natives:
        name = os.path.basename(native)
        if not _MODULE.match(name):
            raise PackagingError(f"{native}: not a native module name (_native.cpython-3XY-…so)")
        dst = os.path.join(out_dir, name)
        shutil.copyfile(native, dst)
        os.chmod(dst, 0o755)
        out = subprocess.run(["strip", "--strip-unneeded", dst], capture_output=True, text=True)
        if out.returncode != 0:
            raise PackagingError(f"strip {dst} failed: {out.stderr.strip()}")
        sizes[name] = os.path.getsize(dst)
        lines.append(f"module: {name}")
    with open(os.path.join(out_dir, BUILD_INFO), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return sizes


def main(argv):
    try:
        if argv[:1] == ["version"] and len(argv) == 2:
            print(addon_version(argv[1]))
        elif argv[:1] == ["stage"] and len(argv) >= 4:
            for name, size in stage(argv[1], argv[2], argv[3:]).items():
                print(f"  {name:44s} {size / 1e6:7.2f} MB")
        elif argv[:1] == ["check"] and len(argv) == 2:
            problems, report = check_tree(argv[1])
            for rel, r in sorted(report.items()):
                versions = ", ".join(f"{k}_{_fmt(v)}" for k, v in sorted(r["versions"].items()))
                print(f"  {rel}: needs {', '.join(r['needed'])}; highest versions {versions}")
            for p in problems:
                print("PROBLEM:", p, file=sys.stderr)
            return 1 if problems else 0
        elif argv[:1] == ["floor"] and len(argv) >= 2:
            for path in argv[1:]:
                versions = version_needs(path)
                print(f"{path}: " + (", ".join(f"{k}_{_fmt(v)}" for k, v in sorted(
                    versions.items())) or "no version needs"))
        else:
            print(__doc__, file=sys.stderr)
            return 2
    except PackagingError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
