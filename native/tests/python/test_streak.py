"""Streaklines from Python (smoke_surfaces §3.2): point sources, the tracer driven by the solver
and streak files. Distances h, threshold h0, clusters and ordering are in test_streak_clusters.py."""
import threading
import time

import numpy as np
import pytest

import _native
from streak_scenes import small_params, streaking_solver


# --- point sources ---------------------------------------------------------------------------

def test_random_points_lie_in_their_cells_and_are_deterministic():
    res, h, origin = (6, 5, 4), 0.2, (-1.0, 0.5, 2.0)
    cells = np.array([0, 13, 119], dtype=np.uint32)
    p = _native.random_points_in_cells(cells, res, h, origin, 12, seed=5, stream=2)
    assert p.shape == (36, 3) and p.dtype == np.float32
    c = np.repeat(cells, 12)
    corner = np.stack([c % 6, (c // 6) % 5, c // 30], axis=1) * h + np.asarray(origin)
    local = (p - corner) / h
    assert local.min() >= -1e-5 and local.max() <= 1 + 1e-5
    np.testing.assert_array_equal(p, _native.random_points_in_cells(cells, res, h, origin, 12, 5, 2))
    assert not np.array_equal(p, _native.random_points_in_cells(cells, res, h, origin, 12, 5, 3))
    with pytest.raises(ValueError, match="point_sources"):
        _native.random_points_in_cells(cells, res, h, origin, 0, 5)
    with pytest.raises(ValueError, match="outside the grid"):
        _native.random_points_in_cells([120], res, h, origin, 3, 5)


# --- tracer ----------------------------------------------------------------------------------

def uniform_velocity(n, v):
    nx, ny, nz = n
    return (np.full((nx + 1, ny, nz), v[0], np.float32), np.full((nx, ny + 1, nz), v[1], np.float32),
            np.full((nx, ny, nz + 1), v[2], np.float32))


def test_tracer_step_moves_particles_exactly_in_a_uniform_field():
    p = small_params(interpolation=_native.Interpolation.LINEAR)
    tracer = _native.StreakTracer(p, emission_period=2)
    assert tracer.interpolation == _native.Interpolation.LINEAR
    assert tracer.emission_period == 2
    source = np.array([[0.3, 0.5, 0.2], [0.6, 0.4, 0.3]], np.float32)
    tracer.add_point_sources(source, [0, 1])
    v = (0.2, -0.1, 0.4)
    vel = uniform_velocity(p.resolution, v)
    density = np.full(p.resolution, 0.25, np.float32)
    dt = 0.05
    for _ in range(5):
        tracer.step(vel, vel, density, dt)
    snap = tracer.snapshot()
    assert tracer.steps == 5 and tracer.particles_per_source == 5 // 2 + 1
    np.testing.assert_array_equal(snap["counts"], [3, 3])
    np.testing.assert_array_equal(snap["groups"], [0, 1])
    assert snap["positions"].shape == (6, 3) and snap["density"].shape == (6,)
    # Emitted at steps 0, 2, 4: travelled 5, 3, 1 steps.
    for s in range(2):
        for e, travelled in enumerate([5, 3, 1]):
            expected = source[s] + np.asarray(v) * dt * travelled
            np.testing.assert_allclose(snap["positions"][3 * s + e], expected, atol=1e-5)
    np.testing.assert_allclose(snap["density"], 0.25)
    assert not snap["outside"].any()


def test_tracer_rejects_bad_input():
    p = small_params()
    with pytest.raises(ValueError, match="emission_period"):
        _native.StreakTracer(p, emission_period=0)
    tracer = _native.StreakTracer(p)
    with pytest.raises(ValueError, match="outside the domain"):
        tracer.add_point_sources([[5.0, 0.5, 0.5]], [0])
    with pytest.raises(ValueError):
        tracer.add_point_sources([[0.5, 0.5, 0.5]], [0, 1])
    tracer.add_point_sources([[0.5, 0.5, 0.5]], [0])
    vel = uniform_velocity(p.resolution, (0, 0, 0))
    with pytest.raises(ValueError, match="density must have shape"):
        tracer.step(vel, vel, np.zeros((3, 3, 3), np.float32), 0.1)
    tracer.step(vel, vel, np.zeros(p.resolution, np.float32), 0.1)
    with pytest.raises(ValueError, match="before the first step"):
        tracer.add_point_sources([[0.5, 0.5, 0.5]], [0])


def test_advance_frame_with_tracers_matches_advance_frame():
    p = small_params()
    plain, _, _ = streaking_solver(p)
    solver, tracer, points = streaking_solver(p)
    for frame in range(3):
        assert plain.advance_frame() is True
        assert _native.advance_frame_with_tracers(solver, tracer) is True
    assert solver.frame == 3
    np.testing.assert_array_equal(plain.get_density(), solver.get_density())
    snap = tracer.snapshot()
    n = len(points)
    assert snap["counts"].tolist() == [tracer.steps + 1] * n
    assert snap["positions"].shape == (n * (tracer.steps + 1), 3)
    # Youngest particle of each streakline sits at its source; the oldest has risen.
    per = tracer.steps + 1
    np.testing.assert_array_equal(snap["positions"][per - 1::per], points)
    assert (snap["positions"][0::per, 2] - points[:, 2]).mean() > 0.03
    assert snap["density"].max() > 0


def test_tracer_cancel_and_gil_release():
    p = small_params(resolution=(32, 32, 32), cell_size=1.0 / 32, substeps=400)
    solver, tracer, _ = streaking_solver(p)
    tracer.cancel()
    assert _native.advance_frame_with_tracers(solver, tracer) is False
    assert solver.frame == 0
    result = {}
    worker = threading.Thread(
        target=lambda: result.setdefault("ok", _native.advance_frame_with_tracers(solver, tracer)))
    start = time.monotonic()
    worker.start()
    ticks = 0
    # The GIL is released: this thread keeps running and cancels through the tracer.
    while worker.is_alive():
        ticks += 1
        tracer.cancel()
        worker.join(0.01)
    assert result["ok"] is False
    assert time.monotonic() - start < 30.0
    solver.cancel()  # the solver's own cancel stops a traced frame too
    assert _native.advance_frame_with_tracers(solver, tracer) is False


def test_tracer_checkpoint_resumes_bit_for_bit_with_the_solver(tmp_path):
    p = small_params()
    solver, tracer, _ = streaking_solver(p, emission_period=2)
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver, tracer)
    solver.save_state(tmp_path / "state.bin")
    tracer.save_state(tmp_path / "tracer_state.bin", frame=2)
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver, tracer)
    straight = tracer.snapshot()

    solver2, tracer2, _ = streaking_solver(p, emission_period=2)
    solver2.load_state(tmp_path / "state.bin")
    assert tracer2.load_state(tmp_path / "tracer_state.bin") == 2
    for _ in range(2):
        assert _native.advance_frame_with_tracers(solver2, tracer2)
    resumed = tracer2.snapshot()
    assert tracer2.steps == tracer.steps
    for key in ("counts", "positions", "density", "groups", "outside"):
        assert resumed[key].tobytes() == straight[key].tobytes(), key

    # Bad files raise RuntimeError naming the path and leave the tracer as it was.
    data = (tmp_path / "tracer_state.bin").read_bytes()
    bad = tmp_path / "bad.bin"
    before = tracer2.snapshot()
    for content in (data[:len(data) // 2], data[:-1] + bytes([data[-1] ^ 1]), b""):
        bad.write_bytes(content)
        with pytest.raises(RuntimeError, match="bad.bin"):
            tracer2.load_state(bad)
        assert tracer2.snapshot()["positions"].tobytes() == before["positions"].tobytes()
    with pytest.raises(RuntimeError, match="emission_period 2"):
        _native.StreakTracer(p, emission_period=1).load_state(tmp_path / "tracer_state.bin")
    with pytest.raises(RuntimeError, match="cannot be written"):
        tracer.save_state(tmp_path / "missing" / "t.bin", frame=1)


def test_tracer_emission_pause_with_the_solver(tmp_path):
    # Figure 10: emission off for some frames leaves a gap; the particles already out keep moving.
    p = small_params()
    solver, tracer, _ = streaking_solver(p)
    assert tracer.emitting
    assert _native.advance_frame_with_tracers(solver, tracer)
    rows = tracer.particles_per_source
    assert rows == tracer.steps + 1  # one row per step, and the first
    tracer.emitting = False
    before, steps = tracer.snapshot()["positions"], tracer.steps
    assert _native.advance_frame_with_tracers(solver, tracer)
    assert tracer.steps > steps and tracer.particles_per_source == rows
    assert not np.array_equal(tracer.snapshot()["positions"], before)  # they moved
    tracer.save_state(tmp_path / "paused.bin", frame=2)
    _, restored, _ = streaking_solver(p)
    restored.load_state(tmp_path / "paused.bin")
    assert not restored.emitting  # the switch is part of the checkpoint
    tracer.emitting = True
    paused_steps = tracer.steps
    assert _native.advance_frame_with_tracers(solver, tracer)
    assert tracer.particles_per_source == rows + (tracer.steps - paused_steps)


# --- streak files ----------------------------------------------------------------------------

def test_streak_file_round_trip_and_errors(tmp_path):
    p = small_params()
    solver, tracer, _ = streaking_solver(p, points_per_cell=1)
    assert _native.advance_frame_with_tracers(solver, tracer)
    snap = tracer.snapshot()
    path = tmp_path / _native.streak_file_name(1)
    assert path.name == "streaks_0001.bin"
    _native.write_streak_file(path, snap)
    back = _native.read_streak_file(path)
    for key in ("counts", "positions", "density", "groups", "outside"):
        np.testing.assert_array_equal(back[key], snap[key])
    # Truncated and corrupt files raise RuntimeError naming the path.
    data = path.read_bytes()
    bad = tmp_path / "streaks_0002.bin"
    bad.write_bytes(data[:-3])
    with pytest.raises(RuntimeError, match="streaks_0002.bin"):
        _native.read_streak_file(bad)
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 1
    bad.write_bytes(bytes(flipped))
    with pytest.raises(RuntimeError, match="corrupt"):
        _native.read_streak_file(bad)
    with pytest.raises(RuntimeError, match="cannot be written"):
        _native.write_streak_file(tmp_path / "missing" / "s.bin", snap)
    with pytest.raises(ValueError):
        _native.write_streak_file(path, {"counts": [2], "positions": np.zeros((3, 3)),
                                         "density": np.zeros(3)})
    with pytest.raises(ValueError, match="density"):
        _native.write_streak_file(path, {"counts": [1], "positions": np.zeros((1, 3))})
