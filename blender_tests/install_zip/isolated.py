"""The isolated Blender of test_install_zip.py: this Blender (``blender -b`` or the bpy venv's
Python) started again with BLENDER_USER_RESOURCES/SCRIPTS/CONFIG/EXTENSIONS/DATAFILES pointing at
new empty folders, so the add-on installed by .ci/common.sh is invisible and the zip is installed
as an artist installs it. The parent starts it (IsolatedRun) and reads back the outcome of each
test it ran (run_isolated writes them); what the process maps is read from /proc/self/maps."""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import bpy

import plume_zip

#: Set (to the results file) in the re-launched, isolated Blender.
ISOLATED_ENV = "PLUME_ZIP_ISOLATED"
VERSION = "%d.%d.%d" % bpy.app.version[:3]
OUT_DIR = os.environ.get("PLUME_TEST_OUT", "/tmp/plume_test_out")
#: Libraries whose Debian system copies must not be the ones _native uses when Blender does not
#: already hold that soname (the bpy builds).
KEY_LIBS = ("libopenvdb.so.10.0", "libosdCPU.so.3.5.0", "libblosc.so.1", "liblog4cplus-2.0.so.3")
#: Removed from a copy of the package to check the error a missing library gives.
MISSING_LIB = "libblosc.so.1"
#: The script the isolated Blender runs.
CASES_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                            "installed_cases.py")


def debian_blender():
    """Debian's packaged Blender executable (links the system OpenVDB, TBB, OpenSubdiv...)."""
    return bool(bpy.app.binary_path) and bpy.app.version < (4, 2, 0)



def mapped_files():
    """Real paths of every file mapped into this process."""
    with open("/proc/self/maps") as f:
        return {parts[5] for parts in (line.rstrip("\n").split(None, 5) for line in f)
                if len(parts) == 6 and parts[5].startswith("/")}


_soname_cache = {}


def soname_of(path):
    if path not in _soname_cache:
        try:
            _soname_cache[path] = plume_zip.elf_dynamic(path)["soname"]
        except plume_zip.PackagingError:
            _soname_cache[path] = None
    return _soname_cache[path]


def mapped_by_soname(files, sonames):
    """{soname: sorted paths} of the mapped files that carry one of `sonames`."""
    out = {s: [] for s in sonames}
    for path in sorted(files):
        base = os.path.basename(path)
        for s in sonames:
            if base.startswith(s.split(".so")[0] + ".so") and soname_of(path) == s:
                out[s].append(path)
    return out


class _Recorder(unittest.TextTestResult):
    """Also keeps {test method name: (outcome, details)} for the parent process."""

    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.outcomes = {}

    def addSuccess(self, test):
        super().addSuccess(test)
        self.outcomes[test._testMethodName] = ("pass", "")

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.outcomes[test._testMethodName] = ("fail", self.failures[-1][1])

    def addError(self, test, err):
        super().addError(test, err)
        if isinstance(test, unittest.TestCase):
            self.outcomes[test._testMethodName] = ("error", self.errors[-1][1])
        else:  # setUpClass
            self.outcomes["setUpClass"] = ("error", self.errors[-1][1])


def run_isolated(results_file, case):
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(case)
    runner = unittest.TextTestRunner(stream=sys.stdout, verbosity=2, resultclass=_Recorder)
    result = runner.run(suite)
    with open(results_file, "w") as f:
        json.dump(result.outcomes, f, indent=1)
    failed = len(result.failures) + len(result.errors)
    print(f"[isolated Blender {VERSION}] {result.testsRun - failed} of {result.testsRun} "
          "passed", flush=True)
    sys.exit(0 if failed == 0 else 1)


def isolated_command(script):
    """This Blender, headless and with factory settings, running `script`."""
    if bpy.app.binary_path and os.path.basename(bpy.app.binary_path).startswith("blender"):
        return [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                "--python", script]
    boot = ("import runpy, sys, bpy; sys.argv = sys.argv[1:]; "
            "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [sys.executable, "-c", boot, script]


class IsolatedRun:
    """installed_cases.py run in this Blender with new empty user folders under `root`, installing
    `zip_file` and running the TestCase named `case`: (return code, outcomes by test name)."""

    def __init__(self, zip_file, case):
        self.root = tempfile.mkdtemp(prefix="plume_zip_install_")
        env = {k: v for k, v in os.environ.items() if not k.startswith("BLENDER_USER_")
               and k not in ("LD_LIBRARY_PATH", "PYTHONPATH")}
        for var, sub in (("BLENDER_USER_RESOURCES", "resources"), ("BLENDER_USER_CONFIG", "config"),
                         ("BLENDER_USER_SCRIPTS", "scripts"), ("BLENDER_USER_DATAFILES", "datafiles"),
                         ("BLENDER_USER_EXTENSIONS", "extensions")):
            env[var] = os.path.join(self.root, sub)
            os.makedirs(env[var])  # a missing folder makes Blender fall back to ~/.config/blender
        results = os.path.join(self.root, "results.json")
        env.update({ISOLATED_ENV: results, "PLUME_ZIP_CASE": case, "PLUME_ZIP_ROOT": self.root,
                    "PLUME_ZIP_UNDER_TEST": os.path.abspath(zip_file), "PLUME_TEST_OUT": OUT_DIR})
        t0 = time.perf_counter()
        try:
            proc = subprocess.run(isolated_command(CASES_SCRIPT), env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  timeout=900)
            output, self.rc = proc.stdout, proc.returncode
        except subprocess.TimeoutExpired as e:
            output, self.rc = str(e.stdout or ""), "timeout"
        print(f"  ---- isolated Blender {VERSION}, {case} (rc {self.rc}, "
              f"{time.perf_counter() - t0:.1f} s) ----")
        for line in output.splitlines():
            if not line.startswith("Fra:"):  # Cycles progress lines
                print("  | " + line)
        self.outcomes = {}
        if os.path.exists(results):
            with open(results) as f:
                self.outcomes = json.load(f)

    def check(self, test, name):
        if "setUpClass" in self.outcomes:
            test.fail("isolated setUpClass failed:\n" + self.outcomes["setUpClass"][1])
        if name not in self.outcomes:
            test.fail(f"isolated Blender did not report {name} (rc {self.rc}); its output is "
                      "above")
        outcome, details = self.outcomes[name]
        if outcome != "pass":
            test.fail(f"isolated {name}: {outcome}\n{details}")

    def cleanup(self):
        shutil.rmtree(self.root, ignore_errors=True)


