"""Streaklines driven by a Blender Mantaflow cache, from Python (smoke_surfaces §3.2):
the grid's world placement, reading a fluid_data VDB (written here with pyopenvdb as Blender 3.4
lays it out, when pyopenvdb is installed), volume frames, the tracer and its errors."""
import numpy as np
import pytest

import _native

RES = (6, 8, 5)
ORIGIN = (-0.5, 1.0, 0.25)
CELL = (0.2, 0.15625, 0.24)  # Blender stretches the domain box over the cells: not cubic


def grid():
    return _native.MantaflowGrid(RES, ORIGIN, CELL)


def test_grid_places_cells_per_axis_and_validates():
    g = grid()
    assert g.resolution == RES
    assert g.vdb_voxel_size == pytest.approx(1.25 / 8)  # longest side (y) / its resolution
    corner = g.index_to_world(np.array([[0, 0, 0], [6, 8, 5]], np.float32))
    np.testing.assert_allclose(corner[0], ORIGIN)
    np.testing.assert_allclose(corner[1], np.add(ORIGIN, np.multiply(RES, CELL)), rtol=1e-6)
    p = np.array([[0.1, 1.6, 0.6]], np.float32)
    np.testing.assert_allclose(g.index_to_world(g.world_to_index(p)), p, rtol=1e-6)
    with pytest.raises(ValueError, match="cell_size"):
        _native.MantaflowGrid(RES, ORIGIN, (0.2, 0.0, 0.24))
    with pytest.raises(ValueError, match="resolution"):
        _native.MantaflowGrid((0, 8, 5), ORIGIN, CELL)


def test_tracer_in_a_still_cache_keeps_particles_at_their_sources(tmp_path):
    g = grid()
    tracer = _native.MantaflowTracer(g, emission_period=2)
    points = np.array([[0.1, 1.6, 0.6], [0.3, 1.2, 0.9]], np.float32)
    assert tracer.add_point_sources(points, [0, 1]) == 0
    with pytest.raises(ValueError, match="outside the Mantaflow domain"):
        _native.MantaflowTracer(g).add_point_sources(np.array([[5.0, 1.5, 0.5]], np.float32), [0])
    empty = _native.MantaflowFrame.empty(RES)
    assert tracer.advance_frame(empty, empty, 1 / 24) == 1
    assert tracer.advance_frame(empty, empty, 1 / 24) == 1
    assert (tracer.steps, tracer.particles_per_source) == (2, 2)  # emission every 2 substeps
    path = tmp_path / "streaks_0002.bin"
    tracer.write_snapshot(path)
    s = _native.read_streak_file(path)
    np.testing.assert_array_equal(s["counts"], [2, 2])
    np.testing.assert_allclose(s["positions"], np.repeat(points, 2, axis=0), atol=1e-6)
    # Figure 10: emission paused over instant 4, resumed for instant 6.
    tracer.emitting = False
    for _ in range(2):
        tracer.advance_frame(empty, empty, 1 / 24)
    assert not tracer.emitting and (tracer.steps, tracer.particles_per_source) == (4, 2)
    tracer.emitting = True
    for _ in range(2):
        tracer.advance_frame(empty, empty, 1 / 24)
    assert (tracer.steps, tracer.particles_per_source) == (6, 3)
    with pytest.raises(ValueError, match="frame_dt"):
        tracer.advance_frame(empty, empty, 0.0)
    with pytest.raises(ValueError, match="cfl"):
        _native.MantaflowTracer(g, cfl=0.0)


def test_volume_frames_are_not_mantaflow_caches(tmp_path):
    g = grid()
    path = tmp_path / "volume_0001.vdb"
    _native.write_mantaflow_volume(path, _native.MantaflowFrame.empty(RES), g, 1)
    assert set(_native.vdb_grid_names(path)) == {"density", "velocity"}
    # A Plume volume is placed in world space; a Mantaflow cache is not: refused, file named.
    with pytest.raises(RuntimeError, match="volume_0001.vdb"):
        _native.read_mantaflow_frame(path, g)
    with pytest.raises(RuntimeError, match="missing.vdb"):
        _native.read_mantaflow_frame(tmp_path / "missing.vdb", g)


def write_blender_like_frame(path, velocity_cells_per_unit):
    """A fluid_data frame as Blender 3.4 writes it: smoke in every cell, staggered velocity in
    cells per Mantaflow time unit, uniform voxel = longest side / resolution, no translation."""
    import pyopenvdb as vdb  # Debian package python3-openvdb (.ci/common.sh installs it)
    density = vdb.FloatGrid()
    density.copyFromArray(np.ones(RES, np.float32))
    density.name = "density"
    velocity = vdb.Vec3SGrid()
    velocity.copyFromArray(np.broadcast_to(np.float32(velocity_cells_per_unit), RES + (3,)).copy())
    velocity.name = "velocity"
    velocity.gridClass = vdb.GridClass.STAGGERED
    for g in (density, velocity):
        g.transform = vdb.createLinearTransform(voxelSize=1.25 / 8)
    vdb.write(str(path), grids=[density, velocity])


def test_reads_blender_frames_in_metres_per_second_and_traces_them(tmp_path):
    path = tmp_path / "fluid_data_0001.vdb"
    write_blender_like_frame(path, (1.0, 2.0, -1.0))
    g = grid()
    frame = _native.read_mantaflow_frame(path, g)
    u, v, w = frame.velocity()
    assert u.shape == (7, 8, 5) and v.shape == (6, 9, 5) and w.shape == (6, 8, 6)
    # value * cell size of its axis * 2.5 time units per second, every face (the top faces of
    # the last cells copy the faces below them).
    np.testing.assert_allclose(u, 1.0 * 0.2 * 2.5)
    np.testing.assert_allclose(v, 2.0 * 0.15625 * 2.5)
    np.testing.assert_allclose(w, -1.0 * 0.24 * 2.5)
    np.testing.assert_allclose(frame.density(), 1.0)
    tracer = _native.MantaflowTracer(g, interpolation=_native.Interpolation.LINEAR)
    start = np.array([[0.1, 1.6, 0.6]], np.float32)
    tracer.add_point_sources(start, [0])
    dt = 1 / 24
    tracer.advance_frame(frame, frame, dt)
    tracer.write_snapshot(tmp_path / "s.bin")
    oldest = _native.read_streak_file(tmp_path / "s.bin")["positions"][0]
    np.testing.assert_allclose(oldest, start[0] + dt * np.array([0.5, 0.78125, -0.6]), atol=1e-6)
    # Another domain's grid: the voxel size tells.
    with pytest.raises(RuntimeError, match="voxel size"):
        _native.read_mantaflow_frame(path, _native.MantaflowGrid((6, 8, 6), ORIGIN, CELL))
