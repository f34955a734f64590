"""Plume on a Slurm farm, on the single-node cluster `.ci/slurm` starts (Debian's slurm-wlm and
munge): a job is submitted from Scene › Plume Farm through the operators an artist clicks, as
job arrays with afterok dependencies, each task a Blender on a "node" running one step; then
- bad input is refused before anything is written or submitted: no Slurm, no Farm Folder, a
  folder outside the mapped storage, a path in the scene the farm cannot see, a wedge setting
  that does not exist, a Time Limit shorter than one measured frame;
- a 3-variant wedge: each variant's bake equals a local bake of its settings bit for bit, and the
  contact sheet holds the three stills;
- a task requeued in the middle of its bake (scontrol requeue) resumes from its last complete
  frame and ends bit-identical to an uninterrupted local bake;
- a failed task shows as FAILED with its log's last lines, its dependants do not run, and
  Resubmit Missing runs only them;
- the job's folder copied to another path runs there (every path in it is relative);
- a mapped path and the panel's background poll; the candle as a Flames job, then a Render job;
  Cancel Job (the flow-graph fire: test_farm_flowgraph.py);
- `python -m plume.farm status` says the same from a terminal.

Run: python3 blender_tests/run.py --blender 3.4 test_farm.py
"""

import json
import os
import shutil
import subprocess
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import (OUT_DIR, add_domain, add_sphere_source, assert_same_frames, enable_addon,  # noqa: E402
                     image_pixels, rmtree, run, select_only, skip_machine_lacks, temp_dir)

RESOLUTION, FRAMES = 16, 10
WAIT_S = 300
GRIDS = ("density", "velocity")


def cluster_up():
    """Starts the single-node cluster (idempotent) and points the Slurm commands at it; the
    reason it cannot, or None."""
    if shutil.which("slurmctld") is None or shutil.which("sbatch") is None:
        return "Slurm (apt-get install slurm-wlm munge)"
    out = subprocess.run(["bash", os.path.join(REPO, ".ci", "slurm"), "start"],
                         capture_output=True, text=True, timeout=120)
    if out.returncode != 0:
        raise RuntimeError(f".ci/slurm start failed: {out.stdout}{out.stderr}")
    env = subprocess.run(["bash", os.path.join(REPO, ".ci", "slurm"), "env"],
                         capture_output=True, text=True).stdout.strip()
    os.environ["SLURM_CONF"] = env.split("=", 1)[1]
    return None


def farm_modules():
    from plume.farm import slurm, status
    from plume.operators import farm as farm_ops
    return slurm, status, farm_ops


def shot(folder, resolution=RESOLUTION, frames=FRAMES):
    """A new scene: a sphere Source, a cube domain, a camera, a small Cycles render; saved as
    folder/shot.blend (a farm copies a saved shot). Returns the domain."""
    bpy.ops.wm.read_homefile(use_factory_startup=True)
    enable_addon()
    bpy.ops.object.select_all(action='SELECT')
    bpy.ops.object.delete()
    add_sphere_source()
    dom = add_domain(resolution=resolution, frame_end=frames, cache_directory="//plume_cache/")
    bpy.ops.object.camera_add(location=(0.0, -5.0, 1.0), rotation=(1.5708, 0.0, 0.0))
    scene = bpy.context.scene
    scene.camera = bpy.context.view_layer.objects.active
    scene.frame_end = frames
    scene.render.engine = 'CYCLES'
    scene.cycles.samples, scene.cycles.use_denoising = 4, False
    scene.render.resolution_x = scene.render.resolution_y = 64
    os.makedirs(folder, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(folder, "shot.blend"))
    farm = scene.plume_farm
    farm.folder = os.path.join(folder, "farm") + "/"
    farm.time_limit, farm.cpus = 10, 1
    return bpy.data.objects[dom.name]


def wait_done(test, folder, timeout=WAIT_S):
    _slurm, status, _ops = farm_modules()
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        states = status.read(folder)
        summary = {ts.name: ts.summary for ts in states}
        if set(summary.values()) <= {status.DONE, status.FAILED, status.MISSING}:
            return states
        time.sleep(0.5)
    test.fail(f"the farm job in {folder} did not end in {timeout} s: {summary}")


def local_bake(domain, cache_root, **settings):
    """The same domain baked here with `settings`, into cache_root (its own folder)."""
    d = domain.plume.domain
    kept = {k: getattr(d, k) for k in settings} | {"cache_directory": d.cache_directory}
    for k, v in settings.items():
        setattr(d, k, v)
    d.cache_directory = cache_root + "/"
    select_only(domain)
    try:
        assert bpy.ops.plume.bake() == {'FINISHED'}
    finally:
        for k, v in kept.items():
            setattr(d, k, v)


def frame_of(name):
    return lambda folder, f: os.path.join(folder, name, f"volume_{f:04d}.vdb")


class ClusterTest(unittest.TestCase):
    """Tests on the single-node cluster (started once), each class in a folder of its own."""
    TMP_PREFIX = "plume_farm_"

    @classmethod
    def setUpClass(cls):
        cls.lacks = cluster_up()
        cls.tmp = temp_dir(cls.TMP_PREFIX)

    @classmethod
    def tearDownClass(cls):
        rmtree(cls.tmp)

    def setUp(self):
        if self.lacks:
            skip_machine_lacks(self, self.lacks)

    def submit(self):
        """Submit; the job's folder."""
        self.assertEqual(bpy.ops.plume.farm_submit(), {'FINISHED'})
        return bpy.context.scene.plume_farm.last_job


class FarmTest(ClusterTest):

    def refused(self, *words):
        """Submit is refused with a message holding `words`, and nothing is written."""
        farm = bpy.context.scene.plume_farm
        root = bpy.path.abspath(farm.folder) if farm.folder else None
        before = sorted(os.listdir(root)) if root and os.path.isdir(root) else []
        with self.assertRaises(RuntimeError) as cm:
            bpy.ops.plume.farm_submit()
        text = str(cm.exception)
        print(f"  refused: {text.strip()}")
        for w in words:
            self.assertIn(w, text)
        self.assertEqual(farm.last_job, "")
        after = sorted(os.listdir(root)) if root and os.path.isdir(root) else []
        self.assertEqual(after, before, "a refused submission wrote into the Farm Folder")

    def test_bad_input_is_refused_before_anything_is_submitted(self):
        base = os.path.join(self.tmp, "bad")
        dom = shot(base)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain = 'WEDGE', dom
        path = os.environ["PATH"]
        os.environ["PATH"] = os.pathsep.join(p for p in path.split(os.pathsep)
                                             if not os.path.exists(os.path.join(p, "sbatch")))
        try:
            self.refused("sbatch", "Slurm")
        finally:
            os.environ["PATH"] = path
        folder = farm.folder
        farm.folder = ""
        self.refused("Scene Properties › Plume Farm › Farm Folder")
        farm.folder = folder
        farm.path_here, farm.path_farm = os.path.join(self.tmp, "elsewhere") + "/", "/mnt/x/"
        self.refused("cannot see", "Path Here")
        farm.path_here = farm.path_farm = ""
        dom.plume.domain.cache_directory = "/var/tmp/plume_outside/"
        self.refused("Cache › Directory", "/var/tmp/plume_outside/", "cannot see")
        dom.plume.domain.cache_directory = "//plume_cache/"
        farm.wedge_settings = "vortex = 0.1, 0.2"
        self.refused("'vortex' is not a setting")
        farm.wedge_settings = "vorticity = 0.1, 0.2; seed = 1"
        self.refused("same number of values")
        farm.wedge_settings = "vorticity = 0.1, -5"
        self.refused("variant 1", "Vorticity")
        self.assertAlmostEqual(dom.plume.domain.vorticity, 0.2)  # the trial is undone
        farm.wedge_settings = "vorticity = 0.1, 0.2"
        # A slow machine's record: the domain's last bake here took 2 hours a frame.
        local_bake(dom, os.path.join(base, "plume_cache"))
        manifest = os.path.join(base, "plume_cache", dom.name, "manifest.json")
        with open(manifest, encoding="utf-8") as f:
            m = json.load(f)
        m["last_run"]["seconds"] = 7200.0 * len(m["last_run"]["computed_frames"])
        with open(manifest, "w", encoding="utf-8") as f:
            json.dump(m, f)
        self.refused("Time Limit (10 min)", "120.0 min per frame")

    def test_wedge_equals_local_bakes_and_makes_a_contact_sheet(self):
        """The smoke manual's recipe "a wedge on the farm" (recipe_farm_wedge.py), then
        Submit."""
        sys.path[:0] = [os.path.join(REPO, "examples"), os.path.join(REPO, "examples", "smoke")]
        import recipe_farm_wedge as recipe
        import recipe_kit
        base = os.path.join(self.tmp, "wedge")
        dom = recipe_kit.run(recipe.steps(base))
        farm = bpy.context.scene.plume_farm
        farm.time_limit, farm.cpus = 10, 1  # this machine's 2 cores: tasks side by side
        values = tuple(float(v) for v in recipe.WEDGE.split("=")[1].split(","))
        t0 = time.monotonic()
        folder = self.submit()
        states = wait_done(self, folder)
        print(f"  wedge of {len(values)} on the farm: {time.monotonic() - t0:.1f} s")
        self.assertEqual([(ts.name, ts.summary) for ts in states],
                         [("variants", "DONE"), ("contact_sheet", "DONE")])
        with open(os.path.join(folder, "job.openjd.json"), encoding="utf-8") as f:
            steps = json.load(f)["steps"]  # the same job for OpenJD (test_farm_openjd runs one)
        self.assertEqual([(s["name"], [d["dependsOn"] for d in s.get("dependencies", ())])
                          for s in steps], [("variants", []), ("contact_sheet", ["variants"])])
        for i, v in enumerate(values):
            here = os.path.join(base, f"local_{i}")
            local_bake(dom, here, turbulence=v)
            farm_cache = os.path.join(folder, "plume_cache", f"{dom.name}_wedge_{i}")
            assert_same_frames(self, frame_of(dom.name), farm_cache, here,
                               range(1, recipe.FRAME_END + 1), GRIDS)
        sheet = image_pixels(os.path.join(folder, "wedge", "contact_sheet.png"))[..., :3]
        stills = [image_pixels(os.path.join(folder, "wedge", f"{i}.png"))[..., :3]
                  for i in range(len(values))]
        h, w = stills[0].shape[:2]
        self.assertEqual(sheet.shape[:2], (h, w * len(values)))
        for i, still in enumerate(stills):
            np.testing.assert_allclose(sheet[:, i * w:(i + 1) * w], still, atol=1e-6)
            value = still.max(axis=2)
            smoke = float((np.abs(value - np.median(value)) > 0.05).mean())
            print(f"  variant {i} (turbulence {values[i]}): smoke covers {smoke:.1%} of its still")
            self.assertGreater(smoke, 0.01, f"variant {i}'s still shows no smoke")
        self.assertFalse(np.array_equal(stills[0], stills[-1]), "the variants look the same")
        os.makedirs(OUT_DIR, exist_ok=True)
        shutil.copy(os.path.join(folder, "wedge", "contact_sheet.png"),
                    os.path.join(OUT_DIR, "farm_wedge_contact_sheet.png"))
        self.__class__.wedge_folder, self.__class__.wedge_domain = folder, dom.name
        # The terminal says the same.
        package = os.path.dirname(os.path.dirname(farm_modules()[0].__file__))
        cli = subprocess.run([sys.executable, "-m", "plume.farm", "status", folder],
                             capture_output=True, text=True,
                             env=dict(os.environ, PYTHONPATH=os.path.dirname(package)))
        print("  " + cli.stdout.replace("\n", "\n  ").rstrip())
        self.assertEqual(cli.returncode, 0, cli.stderr)
        self.assertIn("variants", cli.stdout)
        self.assertIn("DONE", cli.stdout)

    def test_a_requeued_task_resumes_bit_identical(self):
        base = os.path.join(self.tmp, "requeue")
        frames = 24
        dom = shot(base, frames=frames)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, frames
        farm.wedge_settings = "vorticity = 0.3"
        gate = os.path.join(base, "gate")
        os.environ["PLUME_JOB_GATE"] = f"{gate}@8"  # the bake holds at frame 8 for a moment
        try:
            folder = self.submit()
        finally:
            del os.environ["PLUME_JOB_GATE"]
        job = json.load(open(os.path.join(folder, "farm.json")))["variants"]["0"]
        manifest = os.path.join(folder, "plume_cache", f"{dom.name}_wedge_0", dom.name,
                                "manifest.json")
        end = time.monotonic() + WAIT_S
        last = 0
        while time.monotonic() < end and last < 6:
            try:
                with open(manifest, encoding="utf-8") as f:
                    last = json.load(f)["last_complete_frame"]
            except (OSError, ValueError, KeyError):
                pass
            time.sleep(0.1)
        self.assertGreaterEqual(last, 6, "the farm's bake did not reach frame 6")
        subprocess.run(["scontrol", "requeue", f"{job}_0"], check=True, timeout=30)
        t_requeue = time.monotonic()
        # Slurm holds a requeued task about two minutes (its begin time); on this one-node
        # cluster the test lets it start as soon as it is pending again.
        while time.monotonic() - t_requeue < 60:
            st = subprocess.run(["squeue", "-h", "-r", "-j", f"{job}_0", "-o", "%T"],
                                capture_output=True, text=True).stdout.strip()
            if st == "PENDING":
                subprocess.run(["scontrol", "update", f"JobId={job}_0", "StartTime=now"],
                               timeout=30)
                break
            time.sleep(0.2)
        open(gate, "w").close()  # the restarted task runs through
        # Right after `scontrol update`, squeue has been seen not to list the task for a moment
        # (2 of ~10 runs: read as MISSING); the state is read once the restarted task has begun.
        log_path = os.path.join(folder, "logs", "variants.0.log")
        while time.monotonic() - t_requeue < 90:
            with open(log_path, encoding="utf-8") as f:
                if "restart 1" in f.read():
                    break
            time.sleep(0.2)
        states = wait_done(self, folder)
        print(f"  requeued task done {time.monotonic() - t_requeue:.1f} s after the requeue")
        self.assertEqual(states[0].summary, "DONE")
        with open(os.path.join(folder, "logs", "variants.0.log"), encoding="utf-8") as f:
            log = f.read()
        print(f"  requeued at frame {last}; " +
              "; ".join(line for line in log.splitlines() if "plume farm: variants" in line))
        self.assertIn("restart 1", log)
        with open(manifest, encoding="utf-8") as f:
            run_info = json.load(f)["last_run"]
        self.assertTrue(run_info["resumed"], run_info)
        self.assertGreater(run_info["computed_frames"][0], 1)
        here = os.path.join(base, "local")
        local_bake(dom, here, vorticity=0.3)
        assert_same_frames(self, frame_of(dom.name),
                           os.path.dirname(os.path.dirname(manifest)), here,
                           range(1, frames + 1), GRIDS)

    def test_a_failed_task_stops_its_dependants_and_resubmit_runs_only_the_rest(self):
        base = os.path.join(self.tmp, "failed")
        dom = shot(base)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, FRAMES
        farm.wedge_settings = "vorticity = 0.2, 0.5"
        os.environ["PLUME_JOB_FAULT"] = "exit@3"  # every bake's child exits 7 at frame 3
        try:
            folder = self.submit()
        finally:
            del os.environ["PLUME_JOB_FAULT"]
        states = wait_done(self, folder)
        self.assertEqual([ts.summary for ts in states], ["FAILED", "MISSING"])
        tail = "\n".join(states[0].failures[0])
        print("  a failed variant's log ends: " + states[0].failures[0][-1])
        self.assertIn("Error", tail)
        self.assertFalse(os.path.exists(os.path.join(folder, "wedge", "contact_sheet.png")))
        self.assertEqual(bpy.ops.plume.farm_refresh(), {'FINISHED'})
        _slurm, _status, farm_ops = farm_modules()
        self.assertEqual(farm_ops.LAST["states"][0].summary, "FAILED")  # what the panel shows
        self.assertEqual(bpy.ops.plume.farm_resubmit(), {'FINISHED'})
        states = wait_done(self, folder)
        self.assertEqual([ts.summary for ts in states], ["DONE", "DONE"])
        record = json.load(open(os.path.join(folder, "farm.json")))
        self.assertEqual(sorted(record), ["contact_sheet", "variants"])

    def test_the_job_folder_runs_from_another_path(self):
        if not hasattr(self, "wedge_folder"):
            self.test_wedge_equals_local_bakes_and_makes_a_contact_sheet()
        src = self.wedge_folder
        copy = os.path.join(self.tmp, "elsewhere", "copy_of_job")
        shutil.copytree(src, copy, ignore=shutil.ignore_patterns(
            "plume_cache", "wedge", "state", "logs", "*.blend1"))
        out = subprocess.run(["bash", os.path.join("scripts", "variants.sh")], cwd=copy,
                             capture_output=True, text=True, timeout=WAIT_S,
                             env=dict(os.environ, PLUME_TASK_INDEX="0"))
        self.assertEqual(out.returncode, 0, out.stdout[-3000:] + out.stderr[-3000:])
        self.assertTrue(os.path.exists(os.path.join(copy, "state", "variants.0.ok")))
        name = f"{self.wedge_domain}_wedge_0"
        assert_same_frames(self, frame_of(self.wedge_domain),
                           os.path.join(copy, "plume_cache", name),
                           os.path.join(src, "plume_cache", name), range(1, 41), GRIDS)

    def test_path_mapping_and_the_panels_background_poll(self):
        """The farm sees the storage at another path (a symbolic link stands for the farm's
        mount): the tasks run there, every file lands in the folder the artist sees, and the
        panel's background poll reads the same states as the terminal."""
        base = os.path.join(self.tmp, "mapped")
        here = os.path.join(base, "projects")
        mount = os.path.join(base, "mnt_projects")
        dom = shot(os.path.join(here, "shotA"))
        os.symlink(here, mount)
        farm = bpy.context.scene.plume_farm
        farm.path_here, farm.path_farm = here + "/", mount + "/"
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, FRAMES
        farm.wedge_settings = "seed = 3"
        folder = self.submit()
        with open(os.path.join(folder, "scripts", "variants.sh"), encoding="utf-8") as f:
            script = f.read()
        self.assertNotIn(here + "/", script.replace(mount, ""), "a path only this machine sees")
        states = wait_done(self, folder)
        self.assertEqual([ts.summary for ts in states], ["DONE", "DONE"])
        with open(os.path.join(folder, "cluster.json"), encoding="utf-8") as f:
            farm_root = json.load(f)["farm_root"]  # where sbatch was told to run the tasks
        self.assertEqual(farm_root, os.path.join(mount, os.path.relpath(folder, here)))
        self.assertTrue(os.path.isfile(os.path.join(folder, "wedge", "contact_sheet.png")))
        _slurm, status, _ops = farm_modules()
        poll, end = status.Poll(folder), time.monotonic() + 30
        polled = poll.result()
        while polled is None and time.monotonic() < end:
            time.sleep(0.05)
            polled = poll.result()
        self.assertEqual([(ts.name, ts.states) for ts in polled],
                         [(ts.name, ts.states) for ts in status.read(folder)])

    def test_flames_then_render_and_a_render_of_existing_caches(self):
        """The README's candle (recipe_candle.py) as a Flames job: Bake Flames on the farm,
        then its frames rendered in two chunks; the farm's flames equal a local bake. Then a
        Render job of the local bake: the copy renders the caches where they are."""
        sys.path[:0] = [os.path.join(REPO, "examples"), os.path.join(REPO, "examples", "flames")]
        import recipe_candle
        import recipe_kit
        base = os.path.join(self.tmp, "candle")
        recipe_kit.run(recipe_candle.steps(os.path.join(base, "plume_cache", "flames") + "/"))
        scene = bpy.context.scene
        scene.plume_flames.cache_directory = "//plume_cache/flames/"  # the same, once saved
        scene.frame_start, scene.frame_end = 1, recipe_candle.FRAME_END
        scene.render.resolution_x, scene.render.resolution_y = 96, 54
        scene.cycles.samples, scene.cycles.use_denoising = 8, False
        os.makedirs(base, exist_ok=True)
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(base, "candle.blend"))
        farm = scene.plume_farm
        farm.folder, farm.time_limit, farm.cpus = os.path.join(base, "farm") + "/", 10, 1
        farm.job, farm.chunk = 'FLAMES', recipe_candle.FRAME_END // 2
        folder = self.submit()
        states = wait_done(self, folder)
        self.assertEqual([(ts.name, ts.summary) for ts in states],
                         [("flames", "DONE"), ("render", "DONE")], [ts.failures for ts in states])
        self.assertEqual(len(states[1].states), 2)

        def flame_frame(root, f):
            return os.path.join(root, f"flames_{f:04d}.vdb")
        local = os.path.join(base, "plume_cache", "flames")
        self.assertEqual(bpy.ops.plume.flames_bake(), {'FINISHED'})  # here, into //plume_cache
        assert_same_frames(self, flame_frame, os.path.join(folder, "plume_cache", "flames"),
                           local, range(1, recipe_candle.FRAME_END + 1), ("density",))

        def lit(folder_, frame):
            px = image_pixels(os.path.join(folder_, "render", f"{frame:04d}.png"))[..., :3]
            return float((px.max(axis=2) > 0.3).mean())
        farm_lit = lit(folder, recipe_candle.FRAME_END)
        farm.job = 'RENDER'
        render_job = self.submit()
        with open(os.path.join(render_job, "graph.json"), encoding="utf-8") as f:
            self.assertEqual([t["name"] for t in json.load(f)["tasks"]], ["render"])
        states = wait_done(self, render_job)
        self.assertEqual([ts.summary for ts in states], ["DONE"], [ts.failures for ts in states])
        self.assertFalse(os.path.exists(os.path.join(render_job, "plume_cache")))
        render_lit = lit(render_job, recipe_candle.FRAME_END)
        print(f"  candle on the farm: frame 48 lit {farm_lit:.1%} (Flames job), "
              f"{render_lit:.1%} (Render job of the local caches)")
        self.assertGreater(farm_lit, 0.005)
        self.assertAlmostEqual(render_lit, farm_lit, delta=0.01)

    def test_cancel_job_stops_what_is_queued_and_running(self):
        base = os.path.join(self.tmp, "cancel")
        dom = shot(base, frames=24)
        farm = bpy.context.scene.plume_farm
        farm.job, farm.wedge_domain, farm.wedge_frame = 'WEDGE', dom, 24
        farm.wedge_settings = "seed = 1, 2, 3"
        os.environ["PLUME_JOB_GATE"] = os.path.join(base, "never") + "@4"  # held at frame 4
        try:
            folder = self.submit()
        finally:
            del os.environ["PLUME_JOB_GATE"]
        self.assertEqual(bpy.ops.plume.farm_cancel(), {'FINISHED'})
        states = wait_done(self, folder, timeout=60)
        print("  after Cancel Job: " + ", ".join(f"{ts.name} {ts.summary}" for ts in states))
        self.assertEqual([ts.summary for ts in states], ["MISSING", "MISSING"])
        self.assertFalse(os.path.exists(os.path.join(folder, "wedge", "contact_sheet.png")))


if __name__ == "__main__":
    run(FarmTest)
