"""The flow-graph fire on the single-node Slurm cluster (test_farm.py's cluster and helpers):
two states baked side by side, Build Flow Graph, Synthesize Fire in two chunks side by side, the
chunks gathered into the fire Volume, the render in two chunks, each after the one before. The
synthesized fire equals the same pipeline run here frame by frame, bit for bit; so does a local
synthesis in chunks, which refuses to gather while a chunk is missing.

Run: python3 blender_tests/run.py --blender 3.4 test_farm_flowgraph.py
"""

import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

from helpers import assert_same_frames, image_pixels, run, select_only  # noqa: E402
from test_farm import ClusterTest, shot, wait_done  # noqa: E402

#: Two states of 24 frames at 16³, 20 frames synthesized.
GRAPH_RESOLUTION, GRAPH_BAKE, GRAPH_FRAMES = 16, 24, 20


class FarmFlowGraphTest(ClusterTest):
    TMP_PREFIX = "plume_farm_flowgraph_"

    def test_flow_graph_fire_on_the_farm_equals_a_local_run(self):
        """States side by side, then Build Flow Graph, Synthesize Fire in two chunks side by
        side, the chunks gathered into the fire Volume, and the render in two chunks, each after
        the one before; the synthesized fire equals the same pipeline run here, frame by frame,
        bit for bit (and so does a local synthesis in chunks, which refuses to gather while a
        chunk is missing)."""
        sys.path.insert(0, os.path.join(REPO, "examples", "flowgraph_fire"))
        sys.path.insert(0, os.path.join(REPO, "examples"))
        import flowgraph_kit
        base = os.path.join(self.tmp, "graph")
        shot(base)  # a saved file with a camera; its smoke domain goes
        bpy.context.scene.camera.location = (0.0, -3.0, 0.8)
        for ob in list(bpy.data.objects):
            if ob.type == 'MESH':
                bpy.data.objects.remove(ob)
        states = flowgraph_kit.fire_states((("FireA", 0.4), ("FireB", 1.2)), (1.0, 1.0, 1.6),
                                           (0.0, 0.0, 0.8), GRAPH_RESOLUTION, GRAPH_BAKE, 2,
                                           0.4, 30.0)
        flowgraph_kit.fuel_source("Fuel", bpy.ops.mesh.primitive_cylinder_add,
                                  (0.0, 0.0, 0.12), (0.3, 0.3, 0.08))
        for dom in states:
            dom.hide_render = True  # the fire renders, not the boxes
        owner = states[0]
        g = owner.plume.domain.flowgraph
        g.block_size, g.min_node_gap, g.epsilon = 8, 2, 0.0
        g.frame_start, g.frame_end = 1, GRAPH_FRAMES
        g.transition_hold, g.transition_hold_frames = 'CUSTOM', 2.0  # states of 24 frames
        scene = bpy.context.scene
        scene.frame_start, scene.frame_end = 1, GRAPH_FRAMES
        farm = scene.plume_farm
        farm.job, farm.flowgraph_domain, farm.chunk = 'FLOWGRAPH', owner, GRAPH_FRAMES // 2
        bpy.ops.wm.save_mainfile()
        t0 = time.monotonic()
        folder = self.submit()
        done = wait_done(self, folder)
        print(f"  flow-graph fire on the farm: {time.monotonic() - t0:.1f} s: " +
              ", ".join(f"{ts.name} {ts.summary}" for ts in done))
        self.assertEqual([(ts.name, ts.summary) for ts in done],
                         [("states", "DONE"), ("graph", "DONE"), ("synthesis", "DONE"),
                          ("fire", "DONE"), ("render", "DONE")], [ts.failures for ts in done])
        self.assertEqual(len(done[2].states), 2)  # two synthesis chunks
        self.assertEqual(len(done[4].states), 2)  # two render chunks
        self.assertFalse(os.path.exists(os.path.join(folder, "plume_cache", owner.name,
                                                     "farm_synthesis")),
                         "the gathered chunks are left behind")
        renders = sorted(os.listdir(os.path.join(folder, "render")))
        self.assertEqual(renders, [f"{f:04d}.png" for f in range(1, GRAPH_FRAMES + 1)])
        last = image_pixels(os.path.join(folder, "render", renders[-1]))[..., :3].max(axis=2)
        lit = float((last > np.median(last) + 0.1).mean())
        print(f"  the last rendered frame: {lit:.1%} of it is fire")
        self.assertGreater(lit, 0.01, "no fire in the farm's render")
        # The same pipeline here, through the same operators.
        for dom in states:
            select_only(dom)
            self.assertEqual(bpy.ops.plume.bake(), {'FINISHED'})
        select_only(owner)
        for dom in states:
            dom.select_set(True)
        self.assertEqual(bpy.ops.plume.flowgraph_build(), {'FINISHED'})
        select_only(owner)
        self.assertEqual(bpy.ops.plume.fire_synthesize(), {'FINISHED'})

        def fire(folder_, f):
            return os.path.join(folder_, owner.name, "fire", f"fire_{f:04d}.vdb")
        assert_same_frames(self, fire, os.path.join(folder, "plume_cache"),
                           os.path.join(base, "plume_cache"), range(1, GRAPH_FRAMES + 1),
                           ("density", "temperature"))
        # The farm's tasks here, last chunk first: gathering refuses while a chunk is missing.
        whole = os.path.join(self.tmp, "graph_whole")
        shutil.copytree(os.path.join(base, "plume_cache", owner.name, "fire"), whole)
        half = GRAPH_FRAMES // 2
        self.assertEqual(bpy.ops.plume.fire_synthesize(farm_chunk=(half + 1, GRAPH_FRAMES)),
                         {'FINISHED'})
        with self.assertRaises(RuntimeError) as refused:
            bpy.ops.plume.fire_synthesize(farm_gather=True)
        self.assertIn(f"miss frames 1-{half}", str(refused.exception))
        self.assertIn("Plume Farm › Resubmit Missing", str(refused.exception))
        self.assertEqual(bpy.ops.plume.fire_synthesize(farm_chunk=(1, half)), {'FINISHED'})
        self.assertEqual(bpy.ops.plume.fire_synthesize(farm_gather=True), {'FINISHED'})
        assert_same_frames(self, lambda folder_, f: os.path.join(folder_, f"fire_{f:04d}.vdb"),
                           os.path.join(base, "plume_cache", owner.name, "fire"), whole,
                           range(1, GRAPH_FRAMES + 1), ("density", "temperature"))
        self.assertEqual(np.load(os.path.join(whole, "walk.npz"))["nodes"].tolist(),
                         np.load(os.path.join(base, "plume_cache", owner.name, "fire",
                                              "walk.npz"))["nodes"].tolist())


if __name__ == "__main__":
    run(FarmFlowGraphTest)
