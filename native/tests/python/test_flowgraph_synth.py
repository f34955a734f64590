"""Flow-graph fire data and synthesis from Python (graph_fire_synthesis §4.2, §5.2-5.3): a fire
bake recorded into a pathline file, lazy reads, the synthesizer with uniform and grid external
velocity, and frame VDBs of the rasterized particles."""
import os
import threading

import numpy as np
import pytest

import _native
from meshes import box_mesh


def fire_params():
    p = _native.SmokeParams(resolution=(16, 16, 24), cell_size=1.0 / 16)
    p.combustion = True
    return p


def recorded_bake(tmp_path, frames=14, float16=False):
    """A small fire whose burner box injects fuel, recorded at 2 nodes per frame for 0.25 s."""
    params = fire_params()
    solver = _native.SmokeSolver(params)
    vertices, triangles = box_mesh((0.4, 0.4, 0.05), (0.6, 0.6, 0.15))
    settings = _native.SourceSettings()
    settings.fuel = 1.0
    settings.velocity = (0.0, 0.0, 0.5)
    cells, _ = _native.source_cells(vertices, triangles, np.eye(4), np.eye(4), params, "burner")
    solver.add_source(vertices, triangles, np.eye(4), np.eye(4), settings, "burner")
    path = tmp_path / "pathlines.bin"
    recorder = _native.PathlineRecorder(_native.PathlineParams(nodes_per_frame=2, lifetime=0.25),
                                        params, cells, path, float16=float16)
    for _ in range(frames):
        assert recorder.advance_frame(solver)
    assert not path.exists()  # only the partial file until finish()
    assert os.path.exists(recorder.partial_path)
    recorder.finish()
    return path, recorder, cells


def test_recorded_file_reads_lazily(tmp_path):
    path, recorder, cells = recorded_bake(tmp_path)
    layout = recorder.layout
    assert layout.particles == 8 * len(cells)
    assert layout.samples == 12  # 0.25 s at 48 node steps per second
    f = _native.PathlineFile.open(path)
    assert f.node_count == recorder.groups_completed == 14 * 2 - 12 + 2
    assert f.layout == layout
    assert f.resolution == (16, 16, 24) and f.nodes_per_frame == 2
    g = f.read_group(3, state=1)
    assert (g.state, g.step) == (1, 3)
    assert g.velocity.shape == (layout.particles, layout.samples, 3)
    assert g.density.shape == (layout.particles, layout.samples)
    np.testing.assert_array_equal(g.start, recorder.seeds)
    assert not g.velocity.flags.writeable
    assert np.all(np.isfinite(g.temperature)) and g.temperature.max() > 0.0
    with pytest.raises(IndexError):
        f.read_group(f.node_count)


def test_bad_files_raise_naming_the_file(tmp_path):
    with pytest.raises(RuntimeError, match="missing.bin"):
        _native.PathlineFile.open(tmp_path / "missing.bin")
    path, _, _ = recorded_bake(tmp_path, frames=8)
    data = path.read_bytes()
    path.write_bytes(data[:-3])
    with pytest.raises(RuntimeError, match="truncated"):
        _native.PathlineFile.open(path)
    with pytest.raises(ValueError):
        _native.PathlineRecorder(_native.PathlineParams(), fire_params(), np.array([], int),
                                 tmp_path / "p.bin")
    with pytest.raises(ValueError, match="nodes_per_frame"):
        _native.PathlineParams(nodes_per_frame=0)


def test_temporal_walk_and_external_velocity(tmp_path):
    path, recorder, _ = recorded_bake(tmp_path)
    f = _native.PathlineFile.open(path)
    layout = f.layout
    still = _native.Synthesizer(layout, threads=1)
    windy = _native.Synthesizer(layout, threads=2)
    wind = (0.5, 0.0, 0.0)
    for k in range(f.node_count):
        still.step_node(f, k)
        windy.step(f.read_group(k), wind)
    a, b = still.particles(), windy.particles()
    assert still.particle_count == layout.samples * layout.particles == len(a["density"])
    # A uniform wind shifts each particle by wind × its age.
    ages = np.repeat(np.arange(layout.samples - 1, -1, -1), layout.particles) * layout.sample_dt
    np.testing.assert_allclose(b["positions"] - a["positions"], np.outer(ages, wind), atol=1e-5)
    np.testing.assert_array_equal(a["density"], b["density"])
    # The same wind as a VelocityField (Heun is exact for a constant field).
    field = _native.VelocityField(np.tile(np.float32(wind), (4, 4, 4, 1)), 0.25, (0.0, 0.0, 0.0))
    assert field.at((0.3, 0.9, 0.5)) == pytest.approx(wind)
    gridded = _native.Synthesizer(layout)
    for k in range(f.node_count):
        gridded.step_node(f, k, external_velocity=field)
    np.testing.assert_allclose(gridded.particles()["positions"], b["positions"], atol=1e-5)
    wrong = _native.PathlineGroup(np.zeros((2, 3)), np.zeros((2, 5, 3)), np.zeros((2, 5)),
                                  np.zeros((2, 5)), 0.1)
    with pytest.raises(ValueError, match="particles"):
        still.step(wrong)


def test_step_node_cache_only_saves_reads(tmp_path):
    """step_node() through the cache of prepared groups: the same particles as step() with each
    group read anew, hits and misses counted, the cache within its budget."""
    path, _, _ = recorded_bake(tmp_path)
    f = _native.PathlineFile.open(path)
    walk = [0, 1, 2, 3, 1, 2, 3, 4, 5, 2, 2, 6]  # revisits, one within a lifetime of L steps
    group_bytes = f.layout.particles * f.layout.samples * 32  # path, velocity 12 B, density, temperature
    cached = _native.Synthesizer(f.layout, cache_bytes=3 * group_bytes)
    copies = _native.Synthesizer(f.layout)
    for n, k in enumerate(walk):
        wind = (0.1 * n, 0.0, 0.0)
        cached.step_node(f, k, 0, wind)
        copies.step(f.read_group(k), wind)
        assert cached.cache_bytes <= cached.cache_budget == 3 * group_bytes
    a, b = cached.particles(), copies.particles()
    for name in ("positions", "density", "temperature"):
        np.testing.assert_array_equal(a[name], b[name])
    assert cached.cache_hits + cached.cache_misses == len(walk)
    assert cached.cache_hits == 4 and cached.cache_misses == 8  # LRU of 3: 1, 2, 3, 2 hit
    assert cached.cached_groups == 3
    assert copies.cache_misses == 0  # step() does not use the cache
    with pytest.raises(IndexError):
        cached.step_node(f, f.node_count)


def test_shared_cache_between_syntheses(tmp_path):
    """A PreparedGroupCache shared by two synthesizers (the add-on keeps one per graph for the
    session): the second synthesis of the same walk reads nothing and gives the same particles."""
    path, _, _ = recorded_bake(tmp_path)
    f = _native.PathlineFile.open(path)
    walk = [0, 1, 2, 3, 1, 2, 3, 4]
    shared = _native.PreparedGroupCache(1 << 30)
    results = []
    for _ in range(2):
        syn = _native.Synthesizer(f.layout, 0, shared)
        for k in walk:
            syn.step_node(f, k, 0, (0.2, 0.0, 0.0))
        results.append(syn.particles())
    assert shared.misses == 5 and shared.hits == 11  # nodes 0-4 read once, all of run 2 hits
    assert shared.size == 5 and shared.bytes <= shared.budget
    for name in ("positions", "density", "temperature"):
        np.testing.assert_array_equal(results[0][name], results[1][name])
    with pytest.raises(ValueError, match="cache"):
        _native.Synthesizer(f.layout, 0, None)


def test_rasterized_frame_vdb(tmp_path):
    path, _, _ = recorded_bake(tmp_path)
    f = _native.PathlineFile.open(path)
    synth = _native.Synthesizer(f.layout)
    for k in range(f.node_count):
        synth.step_node(f, k)
    params = _native.FireRasterParams(voxel_size=f.cell_size, origin=f.origin)
    out = tmp_path / "fire_0001.vdb"
    stats = synth.write_vdb(out, params, 1)
    assert stats["voxels"] > 0
    assert sorted(_native.vdb_grid_names(str(out))) == ["density", "flame", "temperature", "velocity"]
    p = synth.particles()
    # Mass: Σ ρ Δx³ = Σ R (Δx/2)³.
    density = _native.read_vdb_grid(str(out), "density")
    h = f.cell_size
    assert np.sum(density["values"]) * h ** 3 == pytest.approx(np.sum(p["density"]) * (h / 2) ** 3,
                                                              rel=1e-4)
    stats2 = _native.write_fire_vdb(tmp_path / "direct.vdb", p["positions"], p["density"],
                                    p["temperature"], params, frame=1)
    assert stats2 == stats
    with pytest.raises(ValueError, match="max_temperature"):
        _native.FireRasterParams(voxel_size=0.1, ignition_temperature=5.0, max_temperature=4.0)


def test_recorder_cancelled_before_a_frame_records_nothing(tmp_path):
    """A cancelled recorder's frame (advanced from another thread) returns False, and discard()
    leaves no partial file."""
    params = fire_params()
    solver = _native.SmokeSolver(params)
    cells = np.arange(16 * 16 + 100, 16 * 16 + 104)
    recorder = _native.PathlineRecorder(_native.PathlineParams(), params, cells,
                                        tmp_path / "pathlines.bin")
    recorder.cancel()
    done = []
    t = threading.Thread(target=lambda: done.append(recorder.advance_frame(solver)))
    t.start()
    t.join()
    assert done == [False]
    recorder.discard()
    assert not os.path.exists(recorder.partial_path)
