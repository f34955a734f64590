"""What the paper's Table 1 grids would cost here: each flow-graph example's first state baked
(with Record Pathlines) at two small resolutions, the cost per frame fitted as a power of the
resolution and extrapolated to Table 1's grid ([Graph Fire Synthesis], Table 1).

    blender -b --factory-startup --python examples/flowgraph_fire/table1_cost.py -- OUT_DIR [N1 N2 ...]

For each example (campfire.py, firewall.py, fire_blade.py) the scene is built as the example
builds it, with RESOLUTION (cells along x; the box and every setting as the example's) set to
N1, N2, ... (default 64 and 128), and its first state is baked for the example's whole bake. Printed per bake: wall and CPU seconds per frame (CPU of the job process
the bake runs in included), the pathline groups (|Ω|, L, bytes per node). Then per example the
exponent p of CPU/frame ∝ N^p between the two largest N (at small N the per-frame costs that
do not grow with the grid flatten it), and the extrapolation to Table 1's grid of the same case: cost
per frame ∝ cells · (1/Δx)^(p - 3), and with p = 4 as a bound from above (a frame's substeps
grow as 1/Δx at the same speeds, and the pressure solve's iterations grow too), |Ω| ∝ Δx^-q as
measured. Table 1's output steps are taken as the case's nodes over all its states (the
campfire's 868 against the example's 777): each state bakes steps/states + L node steps (its
start-up left out of the graph) at 3 per frame. Build Flow Graph, C of eq. 9 over those groups,
costs N² |Ω| L: scaled from the campfire example's build (777 groups of 3,360 pathlines x 43
samples, 10.3 s on the idle machine, README). The paper's case without an example here (Fire
Plume, 200 x 400 x 200) is extrapolated from the campfire's law.
"""

import math
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.dirname(HERE)]  # this pipeline's examples, then examples/ (the kits)
import campfire  # noqa: E402
import fire_blade  # noqa: E402
import firewall  # noqa: E402
import scene_kit  # noqa: E402

USAGE = ("usage: blender -b --factory-startup --python examples/flowgraph_fire/table1_cost.py "
         "-- OUT_DIR [N1 N2 ...]")
#: Table 1 as (case, states, grid as x, up, depth cells, output steps), and which example
#: stands for it (None: extrapolated from the campfire's law).
TABLE1 = (("Campfire", 3, (128, 64, 64), 868, campfire),
          ("Firewall", 2, (400, 200, 100), 356, firewall),
          ("Fire Blade", 1, (200, 200, 150), 300, fire_blade),
          ("Fire Plume", 3, (200, 400, 200), 300, None))


#: Build Flow Graph of the campfire example on the idle machine: (groups, |Ω|, L, seconds).
GRAPH_REFERENCE = (777, 3360, 43, 10.3)


def grid(module, n):
    """Cells (x, y, z) of the example's box at n cells along x (Plume: cubic cells, the
    longest axis gets n)."""
    box = module.BOX
    h = max(box) / n
    return tuple(max(1, round(b / h)) for b in box), h


def bake_state0(module, n, frames, out_dir):
    """Builds `module`'s scene at resolution n, bakes its first state for `frames` frames:
    (wall s/frame, CPU s/frame, |Ω|, L, nodes)."""
    scene = scene_kit.new_scene()
    module.RESOLUTION = n
    domains = (module.setup(scene, frames) if module is fire_blade else module.setup(scene))
    dom = domains[0]
    for other in domains[1:]:
        bpy.data.objects.remove(other, do_unlink=True)
    dom.plume.domain.frame_end = frames
    scene_kit.save_blend(out_dir, f"{module.TAG}_{n}")
    scene_kit.select([dom], dom)
    wall, cpu = scene_kit.run_op_cpu(bpy.ops.plume.bake, module.TAG, "the bake")
    native, cache, snapshot = (scene_kit.addon_module(m) for m in ("_native", "cache", "snapshot"))
    f = native.PathlineFile.open(cache.pathlines_path(snapshot.cache_folder_of(dom)))
    return wall / frames, cpu / frames, f.layout.particles, f.layout.samples, f.node_count


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv:
        sys.exit(USAGE)
    out_dir = os.path.abspath(argv[0])
    sizes = tuple(int(v) for v in argv[1:]) if len(argv) > 2 else (64, 128)
    laws = {}
    for case, states, table_grid, steps, module in TABLE1:
        if module is None:
            continue
        frames = module.BAKE_FRAMES
        rows = []
        for n in sizes:
            folder = os.path.join(out_dir, f"{module.TAG}_{n}")
            os.makedirs(folder, exist_ok=True)
            t0 = time.perf_counter()
            wall, cpu, omega, samples, nodes = bake_state0(module, n, frames, folder)
            cells, h = grid(module, n)
            rows.append((n, cpu, omega, samples))
            print(f"table1: {module.TAG} at {cells[0]}x{cells[1]}x{cells[2]} (Δx {h * 1e3:.1f} mm), "
                  f"{frames} frames: {wall:.3f} s/frame wall, {cpu:.3f} CPU-s/frame; |Ω| = "
                  f"{omega}, L = {samples}, {omega * samples * 20 / 1e6:.2f} MB/node in RAM, "
                  f"{nodes} nodes ({time.perf_counter() - t0:.0f} s in all)", flush=True)
        (n1, c1, o1, _), (n2, c2, o2, samples) = rows[-2:]
        p = math.log(c2 / c1) / math.log(n2 / n1)
        q = math.log(o2 / o1) / math.log(n2 / n1)
        laws[module] = (p, q, n2, c2, o2, samples)
        print(f"table1: {module.TAG}: CPU/frame ∝ N^{p:.2f}, |Ω| ∝ N^{q:.2f} "
              f"(N = cells along x, {n1} -> {n2})", flush=True)
    for case, states, table_grid, steps, module in TABLE1:
        law_of = module if module is not None else campfire
        p, q, n2, c2, o2, samples = laws[law_of]
        cells2, h2 = grid(law_of, n2)
        # The Table 1 grid's cell size: the paper's boxes are unknown, so its cell is taken as
        # the example's box over Table 1's cells along x (x is the first dimension in both).
        _, h = grid(law_of, table_grid[0])
        ratio_cells = (table_grid[0] * table_grid[1] * table_grid[2]) / math.prod(cells2)
        cpu = c2 * ratio_cells * (h2 / h) ** (p - 3.0)
        cpu4 = c2 * ratio_cells * (h2 / h)
        omega = o2 * (h2 / h) ** q
        node_mb = omega * samples * 20 / 1e6
        frames = (steps / states + samples) / 3.0  # per state, its start-up included
        bake_h = cpu * frames * states / 3600.0
        bake4_h = cpu4 * frames * states / 3600.0
        groups = steps + states * samples
        n0, o0, l0, s0 = GRAPH_REFERENCE
        graph_s = s0 * (groups / n0) ** 2 * (omega * samples) / (o0 * l0)
        print(f"table1: {case} ({states} states, {'x'.join(map(str, table_grid))}, {steps} nodes: "
              f"{frames:.0f} frames per state), from {law_of.TAG}'s law: {cpu:.1f} CPU-s/frame "
              f"(p = 4: {cpu4:.1f}), {bake_h:.1f} CPU-hours of bakes (p = 4: {bake4_h:.1f}); "
              f"|Ω| ≈ {omega:.0f}, {node_mb:.1f} MB per node, {node_mb * groups / 1e3:.1f} GB of "
              f"groups; Build Flow Graph ≈ {graph_s:.0f} s", flush=True)

if __name__ == "__main__":
    main()
