"""A Plume farm job run by Open Job Description's own runner, `openjd` (the openjd-cli package,
the job format of AWS Deadline Cloud), with no Slurm: a 3-variant wedge (a job array, and the
contact sheet after it) made from Scene › Plume Farm, its template job.openjd.json written by
`python -m plume.farm openjd`, the job folder copied to another path and the original removed,
then `openjd check` and `openjd run` on the copy; then
- the template is valid for openjd-model (decoded, and a job created from it has one step per
  task, the dependencies of the graph and one task per index);
- every task ran (the markers and logs of the Slurm scripts, `status` says DONE);
- each variant's bake equals a local bake of its settings bit for bit, the contact sheet holds
  the stills.

openjd-cli lives in its own pinned venv, ~/.cache/plume/venvs/openjd (.ci/common.sh
setup_openjd, which .ci/test runs), or wherever $PLUME_OPENJD points.

Run: python3 blender_tests/run.py --blender 3.4 test_farm_openjd.py
"""

import json
import os
import shutil
import subprocess
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, assert_same_frames, image_pixels, native, rmtree, run,  # noqa: E402
                     temp_dir)
from test_farm import FRAMES, GRIDS, frame_of, local_bake, shot  # noqa: E402

WEDGE = "vorticity = 0.1, 0.35, 0.6"
VALUES = (0.1, 0.35, 0.6)
RUN_S = 240


def find_openjd():
    """The `openjd` command of openjd-cli; AssertionError saying how to install it."""
    path = os.environ.get("PLUME_OPENJD") or os.path.join(
        os.environ.get("PLUME_VENV_ROOT", os.path.expanduser("~/.cache/plume/venvs")),
        "openjd", "bin", "openjd")
    if not os.access(path, os.X_OK):
        raise AssertionError(
            f"openjd-cli's `openjd` is not at {path}: install it with "
            "`bash -c 'source .ci/common.sh && setup_openjd'` (a pinned venv under "
            "~/.cache/plume/venvs/openjd, as .ci/test does) or point $PLUME_OPENJD at one")
    return path


def python_of(script):
    """The Python an entry-point script (`openjd`) runs in: its #! line's."""
    with open(script, encoding="utf-8") as f:
        first = f.readline()
    return first[2:].strip() if first.startswith("#!") else sys.executable


#: Run in openjd-cli's Python: the template decoded by openjd-model and a job created from it
#: with its default job folder (resolved against the template's folder, the working directory
#: elsewhere); per step its name, dependencies and number of tasks (JSON on stdout).
DECODE = """
import json, os, sys
from pathlib import Path
from openjd.model import (create_job, decode_job_template, preprocess_job_parameters,
                          StepParameterSpaceIterator)
with open(sys.argv[1], encoding="utf-8") as f:
    template = decode_job_template(template=json.load(f))
values = preprocess_job_parameters(job_template=template, job_parameter_values={},
                                   job_template_dir=Path(os.path.dirname(sys.argv[1])),
                                   current_working_dir=Path(sys.argv[2]))
job = create_job(job_template=template, job_parameter_values=values)
print(json.dumps({"name": job.name, "folder": values["FarmFolder"].value, "steps": [
    [s.name, [d.dependsOn for d in (s.dependencies or [])],
     len(StepParameterSpaceIterator(space=s.parameterSpace))] for s in job.steps]}))
"""


class FarmOpenJDTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.tmp = temp_dir("plume_farm_openjd_")

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def test_a_wedge_job_runs_under_openjd_from_a_copy_and_equals_local_bakes(self):
        openjd_cli = find_openjd()
        from plume.farm import graph as farm_graph
        from plume.farm import slurm, status
        from plume.snapshot import farm as farm_snapshot
        base = os.path.join(self.tmp, "wedge")
        dom = shot(base)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, FRAMES
        farm.wedge_settings = WEDGE
        # The job folder as Submit makes it (every check, the shot's copy, wedge.json, the
        # graph) but for the Slurm check first and the sbatch calls last: no Slurm here.
        find_slurm = slurm.find_slurm
        slurm.find_slurm = lambda: None
        try:
            job = farm_snapshot.plan(bpy.context)
        finally:
            slurm.find_slurm = find_slurm
        farm_snapshot.write(job, bpy.context.scene)
        farm_graph.save(job.graph, job.folder)
        self.assertEqual([(t.name, t.count, t.after) for t in job.graph.tasks],
                         [("variants", 3, []), ("contact_sheet", 1, ["variants"])])
        package = os.path.dirname(os.path.dirname(slurm.__file__))
        cli = subprocess.run([sys.executable, "-m", "plume.farm", "openjd", job.folder],
                             capture_output=True, text=True,
                             env=dict(os.environ, PYTHONPATH=os.path.dirname(package)))
        self.assertEqual(cli.returncode, 0, cli.stdout + cli.stderr)
        print("  " + cli.stdout.replace("\n", "\n  ").rstrip())
        # Another path, the original gone: nothing in the job may point back at it.
        copy = os.path.join(self.tmp, "elsewhere", "copy_of_job")
        shutil.copytree(job.folder, copy)
        rmtree(job.folder)
        template = os.path.join(copy, "job.openjd.json")
        check = subprocess.run([openjd_cli, "check", template], capture_output=True, text=True,
                               timeout=60)
        print("  openjd check: " + check.stdout.strip())
        self.assertEqual(check.returncode, 0, check.stdout + check.stderr)
        self.assertIn("passes validation", check.stdout)
        decoded = subprocess.run([python_of(openjd_cli), "-c", DECODE, template, self.tmp],
                                 capture_output=True, text=True, timeout=60)
        self.assertEqual(decoded.returncode, 0, decoded.stderr)
        self.assertEqual(json.loads(decoded.stdout),
                         {"name": os.path.basename(job.folder), "folder": copy,
                          "steps": [["variants", [], 3], ["contact_sheet", ["variants"], 1]]})
        # The whole job, its steps in dependency order, from another working directory; the
        # job folder is the template's own by default.
        t0 = time.monotonic()
        ran = subprocess.run([openjd_cli, "run", template],
                             capture_output=True, text=True, timeout=RUN_S, cwd=self.tmp)
        seconds = time.monotonic() - t0
        self.assertEqual(ran.returncode, 0, ran.stdout[-4000:] + ran.stderr[-2000:])
        self.assertIn("Session ended successfully", ran.stdout)
        print(f"  openjd run: the wedge of {len(VALUES)} and its contact sheet in "
              f"{seconds:.1f} s")
        for name in ("variants.0", "variants.1", "variants.2", "contact_sheet.0"):
            self.assertTrue(os.path.isfile(os.path.join(copy, "state", f"{name}.ok")), name)
            with open(os.path.join(copy, "logs", f"{name}.log"), encoding="utf-8") as f:
                self.assertIn(f"in {copy}", f.read(), f"{name} did not run in the copy")
        self.assertEqual([(ts.name, ts.summary) for ts in status.read(copy)],
                         [("variants", status.DONE), ("contact_sheet", status.DONE)])
        caches = [os.path.join(copy, "plume_cache", f"{dom.name}_wedge_{i}")
                  for i in range(len(VALUES))]
        for i, v in enumerate(VALUES):
            here = os.path.join(base, f"local_{i}")
            local_bake(dom, here, vorticity=v)
            assert_same_frames(self, frame_of(dom.name), caches[i], here, range(1, FRAMES + 1),
                               GRIDS)
        first, last = (native().read_vdb_grid(frame_of(dom.name)(c, FRAMES), "velocity")
                       for c in (caches[0], caches[-1]))
        self.assertFalse(first["values"].shape == last["values"].shape
                         and np.array_equal(first["values"], last["values"]),
                         "the variants baked the same: the wedge's settings did not reach them")
        sheet = image_pixels(os.path.join(copy, "wedge", "contact_sheet.png"))[..., :3]
        stills = [image_pixels(os.path.join(copy, "wedge", f"{i}.png"))[..., :3]
                  for i in range(len(VALUES))]
        h, w = stills[0].shape[:2]
        self.assertEqual(sheet.shape[:2], (h, w * len(VALUES)))
        for i, still in enumerate(stills):
            np.testing.assert_allclose(sheet[:, i * w:(i + 1) * w], still, atol=1e-6)
        os.makedirs(OUT_DIR, exist_ok=True)
        shutil.copy(os.path.join(copy, "wedge", "contact_sheet.png"),
                    os.path.join(OUT_DIR, "farm_openjd_contact_sheet.png"))


if __name__ == "__main__":
    run(FarmOpenJDTest)
