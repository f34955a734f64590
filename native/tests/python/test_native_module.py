"""The plume._native module from Python: settings, arrays, emitters, VDB and state files, cancel."""
import math
import pathlib
import re
import threading
import time

import numpy as np
import pytest

import _native
from meshes import box_mesh


# --- helpers -----------------------------------------------------------------------------

def centres_inside(lo, hi, origin, cell_size, n):
    """Number of cell centres origin + (i + 0.5) * cell_size strictly inside (lo, hi)."""
    x = origin + (np.arange(n) + 0.5) * cell_size
    return int(np.count_nonzero((x > lo) & (x < hi)))


def small_params(**overrides):
    p = _native.SmokeParams()
    p.resolution = (12, 10, 8)
    p.cell_size = 0.05
    p.origin = (-0.3, 0.2, 1.0)
    for key, value in overrides.items():
        setattr(p, key, value)
    return p


def pattern(shape, seed):
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1.0, 1.0, size=shape).astype(np.float32)
    a[rng.uniform(size=shape) < 0.3] = 0.0  # zeros, so the VDB stores a sparse grid
    return a


def fill_state(solver, seed):
    nx, ny, nz = solver.params.resolution
    solver.set_density(np.abs(pattern((nx, ny, nz), seed)))
    solver.set_soot(np.abs(pattern((nx, ny, nz), seed + 1)) * 0.1)
    solver.set_temperature(pattern((nx, ny, nz), seed + 2))
    solver.set_fuel(np.abs(pattern((nx, ny, nz), seed + 3)))
    solver.set_flame(np.abs(pattern((nx, ny, nz), seed + 4)))
    solver.set_pressure(pattern((nx, ny, nz), seed + 5))
    solver.set_velocity(pattern((nx + 1, ny, nz), seed + 6), pattern((nx, ny + 1, nz), seed + 7),
                        pattern((nx, ny, nz + 1), seed + 8))
    solver.frame = 40 + seed


def all_arrays(solver):
    arrays = [solver.get_density(), solver.get_soot(), solver.get_temperature(), solver.get_fuel(),
              solver.get_flame(), solver.get_pressure()]
    return arrays + list(solver.get_velocity()) + [np.array(solver.frame)]


def assert_same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


# --- module and settings -----------------------------------------------------------------

def test_version_and_enums():
    assert _native.__version__ == "0.1.0"
    assert _native.Advection.SEMI_LAGRANGIAN != _native.Advection.BFECC
    assert _native.Interpolation.LINEAR != _native.Interpolation.MONOTONIC_CUBIC
    assert _native.Trace.MIDPOINT != _native.Trace.EULER
    assert _native.Boundary.OPEN != _native.Boundary.CLOSED
    assert _native.Slip.NO_SLIP != _native.Slip.FREE_SLIP


def test_params_defaults_and_fields():
    p = _native.SmokeParams()
    p.validate()
    assert p.resolution == (32, 32, 32)
    assert len(p.boundaries) == 6
    assert p.boundaries[4] == _native.Boundary.CLOSED
    for name in ["cell_size", "frame_dt", "substeps", "use_cfl", "cfl", "advection",
                 "interpolation", "trace", "gravity", "alpha", "beta", "ambient_temperature",
                 "wind", "wind_strength", "vorticity", "density_dissipation", "pressure_tolerance",
                 "max_pressure_iterations", "combustion", "burn_rate", "soot_yield", "heat_yield",
                 "conductivity", "cooling_rate", "max_temperature", "expansion", "seed",
                 "threads", "origin"]:
        assert hasattr(p, name), name
    p.gravity = [0.0, -9.8, 0.0]
    assert p.gravity == pytest.approx((0.0, -9.8, 0.0))
    p.boundaries = [_native.Boundary.CLOSED] * 6
    assert p.boundaries == [_native.Boundary.CLOSED] * 6
    q = _native.SmokeParams(cell_size=0.25, combustion=True)
    assert q.cell_size == 0.25 and q.combustion
    assert p.trace == _native.Trace.MIDPOINT  # RK2 stays the default
    assert _native.SmokeParams(trace=_native.Trace.EULER).trace == _native.Trace.EULER


def test_params_validate_messages():
    p = _native.SmokeParams()
    p.cell_size = -1
    with pytest.raises(ValueError, match=r"cell_size must be in \[1e-06, 1e\+06\] \(got -1\)"):
        p.validate()
    with pytest.raises(ValueError, match="cell_size"):
        _native.SmokeSolver(p)

    p = _native.SmokeParams()
    p.frame_dt = float("nan")
    with pytest.raises(ValueError, match="frame_dt must be a finite number"):
        p.validate()

    p = _native.SmokeParams()
    p.resolution = (0, 32, 32)
    with pytest.raises(ValueError, match=r"resolution must be in \[2, 1024\]"):
        p.validate()

    p = _native.SmokeParams()
    p.vorticity = -0.5
    with pytest.raises(ValueError, match="vorticity"):
        p.validate()


def test_params_ranges_are_what_validate_checks():
    """SmokeParams.ranges() is the one definition of each bound: values at the bounds are
    accepted, and a step past it is refused with a message naming the setting and that range."""
    ranges = _native.SmokeParams.ranges()
    assert ranges["resolution"] == (2, 1024)
    every = _native.setting_ranges()  # what the add-on reads: the solver's and the tracers'
    assert {k: every[k] for k in ranges} == ranges
    assert every["emission_period"][0] == every["point_sources"][0] == 1
    assert {"cfl", "vorticity", "threads", "substeps", "pressure_tolerance"} <= set(ranges)
    for name, (lo, hi) in ranges.items():
        whole = isinstance(getattr(_native.SmokeParams(), name), (int, tuple))
        # Float settings are float32 in the core: their bounds are tried a millionth inside.
        inside = 0 if whole else 1e-6 * (hi - lo)
        below = lo - (1 if whole else 1e-3 * max(1, abs(lo)))
        for value, ok in ((lo + inside, True), (hi - inside, True), (below, False)):
            p = _native.SmokeParams()
            if name == "resolution":
                p.resolution = (int(value), 8, 8)
            else:
                setattr(p, name, int(value) if whole else value)
            if name in ("alpha", "beta", "ambient_temperature") or ok:
                p.max_temperature = 2e6  # above any ambient temperature tried
            if ok:
                p.validate()
            else:
                message = re.escape(f"{name} must be in [{lo:g}, {hi:g}]")
                with pytest.raises(ValueError, match=message):
                    p.validate()


def test_params_setter_errors():
    p = _native.SmokeParams()
    with pytest.raises(ValueError, match="resolution"):
        p.resolution = (32, 32)
    with pytest.raises(ValueError, match="boundaries"):
        p.boundaries = [_native.Boundary.OPEN] * 5
    with pytest.raises(ValueError, match="origin"):
        p.origin = (1.0, 2.0)
    with pytest.raises(TypeError, match="no_such_setting"):
        _native.SmokeParams(no_such_setting=1)


def test_source_settings():
    s = _native.SourceSettings()
    s.density, s.temperature, s.fuel, s.motion_factor = 2.0, 3.0, 0.5, 0.0
    s.velocity = (0.0, 0.0, 1.5)
    assert s.velocity == pytest.approx((0.0, 0.0, 1.5))
    s.validate()
    s.density = -1.0
    with pytest.raises(ValueError, match="density"):
        s.validate()


# --- arrays ------------------------------------------------------------------------------

def test_scalar_round_trip_and_layout():
    solver = _native.SmokeSolver(small_params())
    nx, ny, nz = 12, 10, 8
    density = pattern((nx, ny, nz), 1)
    solver.set_density(density)
    out = solver.get_density()
    assert out.shape == (nx, ny, nz) and out.dtype == np.float32
    np.testing.assert_array_equal(out, density)
    # Any memory order and dtype is accepted; the copy is independent of the solver.
    solver.set_temperature(np.ascontiguousarray(density.astype(np.float64)) * 2)
    np.testing.assert_array_equal(solver.get_temperature(), density * 2)
    out[0, 0, 0] = 123.0
    assert solver.get_density()[0, 0, 0] == density[0, 0, 0]


def test_array_shape_errors():
    solver = _native.SmokeSolver(small_params())
    with pytest.raises(ValueError, match=r"must have shape \(12, 10, 8\)"):
        solver.set_density(np.zeros((10, 12, 8), np.float32))
    with pytest.raises(ValueError):
        solver.set_fuel(np.zeros((12, 10), np.float32))
    with pytest.raises(ValueError, match="NaN"):
        solver.set_soot(np.full((12, 10, 8), np.nan, np.float32))
    u, v, w = solver.get_velocity()
    assert u.shape == (13, 10, 8) and v.shape == (12, 11, 8) and w.shape == (12, 10, 9)
    with pytest.raises(ValueError, match="w must have shape"):
        solver.set_velocity(u + 1, v + 1, np.zeros((12, 10, 8), np.float32))
    # A rejected call changes nothing.
    np.testing.assert_array_equal(solver.get_velocity()[0], u)
    solver.set_velocity(u + 1, v + 2, w + 3)
    u2, v2, w2 = solver.get_velocity()
    np.testing.assert_array_equal(u2, u + 1)
    np.testing.assert_array_equal(w2, w + 3)
    types = solver.get_cell_types()
    assert types.dtype == np.uint8 and types.shape == (12, 10, 8)


# --- emitters ----------------------------------------------------------------------------

def test_open_obstacle_raises_naming_it():
    solver = _native.SmokeSolver(small_params())
    vertices, triangles = box_mesh((-0.2, 0.3, 1.1), (0.1, 0.5, 1.3))
    with pytest.raises(ValueError, match=r"obstacle 'Open Box' is not a closed manifold mesh: 3 open"):
        solver.add_obstacle(vertices, triangles[:-1], np.eye(4), np.eye(4),
                            _native.Slip.NO_SLIP, "Open Box")
    with pytest.raises(ValueError, match="'Nothing'"):
        solver.add_obstacle(np.zeros((0, 3)), np.zeros((0, 3), int), np.eye(4), np.eye(4),
                            _native.Slip.FREE_SLIP, "Nothing")
    with pytest.raises(ValueError, match="4x4"):
        solver.add_obstacle(vertices, triangles, np.eye(3), np.eye(4), _native.Slip.NO_SLIP, "m")
    with pytest.raises(ValueError, match="'bad index'"):
        solver.add_source(vertices, triangles + 8, np.eye(4), np.eye(4),
                          _native.SourceSettings(), "bad index")


def test_closed_cube_obstacle_cell_count():
    p = _native.SmokeParams(resolution=(24, 24, 24), cell_size=1.0 / 24)
    solver = _native.SmokeSolver(p)
    # Unit cube around its origin, scaled and moved by the object matrix (row-major, like
    # numpy.array(obj.matrix_world)).
    vertices, triangles = box_mesh((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))
    matrix = np.diag([0.43, 0.31, 0.52, 1.0])
    matrix[:3, 3] = (0.5, 0.45, 0.4)
    count = solver.add_obstacle(vertices, triangles, matrix, matrix, _native.Slip.NO_SLIP, "Cube")
    lo = matrix[:3, 3] - 0.5 * np.diag(matrix)[:3]
    hi = matrix[:3, 3] + 0.5 * np.diag(matrix)[:3]
    expected = 1
    for a in range(3):
        expected *= centres_inside(lo[a], hi[a], 0.0, p.cell_size, 24)
    # Exact here; the contract is "within one layer of cells".
    layer = 2 * sum(centres_inside(lo[a], hi[a], 0.0, p.cell_size, 24) *
                    centres_inside(lo[b], hi[b], 0.0, p.cell_size, 24)
                    for a, b in ((0, 1), (1, 2), (0, 2)))
    assert abs(count - expected) <= layer
    assert count == expected
    solver.step(1e-3)  # the solver marks solid cells when a step starts
    assert int(solver.get_cell_types().sum()) == count


def test_moving_source_velocity_is_rigid_motion():
    p = _native.SmokeParams(resolution=(16, 16, 16), cell_size=1.0 / 16, frame_dt=1.0 / 24)
    p.gravity = (0.0, 0.0, 0.0)
    p.vorticity = 0.0
    solver = _native.SmokeSolver(p)
    h = p.cell_size
    # A box smaller than a cell around the centre of cell (5, 9, 7): exactly that cell emits.
    ijk = np.array([5, 9, 7])
    centre = (ijk + 0.5) * h
    vertices, triangles = box_mesh(-0.2 * h * np.ones(3), 0.2 * h * np.ones(3))
    matrix = np.eye(4)
    matrix[:3, 3] = centre
    # Next frame: rotated by 0.2 rad about the z axis through `pivot`.
    pivot = np.array([0.5, 0.5, 0.3])
    c, s = math.cos(0.2), math.sin(0.2)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    motion = np.eye(4)
    motion[:3, :3] = rot
    motion[:3, 3] = pivot - rot @ pivot
    settings = _native.SourceSettings()
    settings.motion_factor = 1.0
    assert solver.add_source(vertices, triangles, matrix, motion @ matrix, settings, "spinner") == 1
    solver.apply_sources(p.frame_dt)
    expected = (rot @ (centre - pivot) + pivot - centre) / p.frame_dt
    u, v, w = solver.get_velocity()
    i, j, k = ijk
    assert u[i, j, k] == pytest.approx(expected[0], rel=1e-4)
    assert u[i + 1, j, k] == pytest.approx(expected[0], rel=1e-4)
    assert v[i, j, k] == pytest.approx(expected[1], rel=1e-4)
    assert w[i, j, k + 1] == pytest.approx(expected[2], abs=1e-5)
    density = solver.get_density()
    assert density[i, j, k] == 1.0 and density.sum() == 1.0


# --- VDB files ---------------------------------------------------------------------------

def test_write_vdb_grids_values_and_transform(tmp_path):
    p = small_params()
    solver = _native.SmokeSolver(p)
    fill_state(solver, 3)
    path = tmp_path / "density_0001.vdb"
    solver.write_vdb(str(path))
    assert sorted(_native.vdb_grid_names(str(path))) == ["density", "temperature", "velocity"]
    assert not list(tmp_path.glob("*.tmp"))

    grid = _native.read_vdb_grid(str(path), "density")
    assert grid["voxel_size"] == pytest.approx(p.cell_size)
    expected_zero = np.array(p.origin) + 0.5 * p.cell_size
    np.testing.assert_allclose(grid["world_of_voxel_zero"], expected_zero, atol=1e-6)
    full = np.zeros(p.resolution, np.float32)
    mi = grid["min"]
    values = grid["values"]
    full[mi[0]:mi[0] + values.shape[0], mi[1]:mi[1] + values.shape[1],
         mi[2]:mi[2] + values.shape[2]] = values
    np.testing.assert_array_equal(full, solver.get_density() + solver.get_soot())

    vel = _native.read_vdb_grid(path, "velocity")  # os.PathLike works too
    assert vel["values"].shape[3] == 3
    u, v, w = solver.get_velocity()
    centre = np.stack([0.5 * (u[1:] + u[:-1]), 0.5 * (v[:, 1:] + v[:, :-1]),
                       0.5 * (w[:, :, 1:] + w[:, :, :-1])], axis=-1)
    mi, vals = vel["min"], vel["values"]
    full = np.zeros(centre.shape, np.float32)
    full[mi[0]:mi[0] + vals.shape[0], mi[1]:mi[1] + vals.shape[1], mi[2]:mi[2] + vals.shape[2]] = vals
    # Velocity is stored only where there is smoke (density + soot), or flame when burning.
    centre[(solver.get_density() + solver.get_soot()) == 0] = 0.0
    np.testing.assert_allclose(full, centre, rtol=1e-6, atol=1e-7)


def test_flame_grid_only_with_combustion(tmp_path):
    fire = _native.SmokeSolver(small_params(combustion=True))
    fill_state(fire, 1)
    fire.write_vdb(str(tmp_path / "fire.vdb"))
    assert "flame" in _native.vdb_grid_names(str(tmp_path / "fire.vdb"))
    flame = _native.read_vdb_grid(str(tmp_path / "fire.vdb"), "flame")
    assert flame["values"].max() == pytest.approx(fire.get_flame().max())
    smoke = _native.SmokeSolver(small_params())
    smoke.write_vdb(str(tmp_path / "smoke.vdb"))
    assert "flame" not in _native.vdb_grid_names(str(tmp_path / "smoke.vdb"))
    with pytest.raises(RuntimeError, match="flame"):
        _native.read_vdb_grid(str(tmp_path / "smoke.vdb"), "flame")


def test_write_vdb_into_missing_directory_raises(tmp_path):
    solver = _native.SmokeSolver(small_params())
    path = tmp_path / "missing" / "frame.vdb"
    with pytest.raises(RuntimeError, match="frame.vdb"):
        solver.write_vdb(str(path))
    assert not (tmp_path / "missing").exists()
    with pytest.raises(RuntimeError):
        _native.vdb_grid_names(str(path))


# --- state files -------------------------------------------------------------------------

def test_state_round_trip(tmp_path):
    a = _native.SmokeSolver(small_params(combustion=True))
    fill_state(a, 7)
    path = tmp_path / "state_0047.bin"
    a.save_state(str(path))
    assert not list(tmp_path.glob("*.tmp"))
    b = _native.SmokeSolver(small_params(combustion=True))
    b.load_state(str(path))
    assert_same(all_arrays(a), all_arrays(b))
    assert b.frame == 47


@pytest.mark.parametrize("damage", ["truncate", "flip", "empty", "magic"])
def test_bad_state_file_raises_and_leaves_solver_unchanged(tmp_path, damage):
    a = _native.SmokeSolver(small_params())
    fill_state(a, 2)
    path = tmp_path / "state.bin"
    a.save_state(str(path))
    data = bytearray(path.read_bytes())
    if damage == "truncate":
        data = data[:len(data) - 100]
    elif damage == "flip":
        data[len(data) // 2] ^= 0x01
    elif damage == "empty":
        data = bytearray()
    else:
        data[:5] = b"HELLO"
    path.write_bytes(bytes(data))

    b = _native.SmokeSolver(small_params())
    fill_state(b, 9)
    before = all_arrays(b)
    with pytest.raises(RuntimeError, match="state.bin"):
        b.load_state(str(path))
    assert_same(before, all_arrays(b))


def test_state_of_other_resolution_and_missing_file(tmp_path):
    a = _native.SmokeSolver(small_params())
    a.save_state(str(tmp_path / "s.bin"))
    other = _native.SmokeSolver(small_params(resolution=(8, 8, 8)))
    with pytest.raises(RuntimeError, match="resolution"):
        other.load_state(str(tmp_path / "s.bin"))
    with pytest.raises(RuntimeError):
        other.load_state(str(tmp_path / "nothing.bin"))
    with pytest.raises(RuntimeError):
        a.save_state(str(tmp_path / "missing" / "s.bin"))


# --- stepping and cancel -----------------------------------------------------------------

def test_cancel_from_another_thread():
    p = _native.SmokeParams(resolution=(40, 40, 40), cell_size=1.0 / 40, substeps=1000)
    solver = _native.SmokeSolver(p)
    vertices, triangles = box_mesh((0.4, 0.4, 0.05), (0.6, 0.6, 0.2))
    solver.add_source(vertices, triangles, np.eye(4), np.eye(4), _native.SourceSettings(), "src")
    result = {}

    def run():
        result["ok"] = solver.advance_frame()

    worker = threading.Thread(target=run)
    start = time.monotonic()
    worker.start()
    # advance_frame released the GIL, so this thread runs meanwhile; keep cancelling until the
    # worker notices (the flag is consumed by the step that sees it).
    while worker.is_alive():
        solver.cancel()
        worker.join(0.01)
    assert result["ok"] is False
    assert time.monotonic() - start < 30.0


def test_advance_frame_updates_frame_and_stats():
    p = _native.SmokeParams(resolution=(16, 16, 16), cell_size=1.0 / 16)
    solver = _native.SmokeSolver(p)
    vertices, triangles = box_mesh((0.4, 0.4, 0.05), (0.6, 0.6, 0.2))
    assert solver.add_source(vertices, triangles, np.eye(4), np.eye(4),
                             _native.SourceSettings(), "src") > 0
    solver.frame = 10
    assert solver.advance_frame() is True
    assert solver.frame == 11
    stats = solver.last_stats
    assert set(stats) == {"substeps", "pressure_iterations", "pressure_residual", "max_speed"}
    assert stats["substeps"] >= 1
    assert solver.get_density().max() > 0
    assert math.isfinite(solver.max_speed()) and math.isfinite(solver.max_divergence())


def _bake_vdbs(folder, threads, frames=6):
    """A small fire bake (source mesh, moving obstacle, combustion) written as VDB frames."""
    p = _native.SmokeParams(resolution=(20, 16, 24), cell_size=0.05, threads=threads)
    p.combustion = True
    p.conductivity = 1e-3
    solver = _native.SmokeSolver(p)
    src_v, src_t = box_mesh((0.35, 0.3, 0.1), (0.65, 0.5, 0.3))
    obs_v, obs_t = box_mesh((0.3, 0.25, 0.6), (0.6, 0.55, 0.75))
    settings = _native.SourceSettings()
    settings.fuel = 1.0
    paths = []
    for f in range(frames):
        here, there = np.eye(4), np.eye(4)
        here[0, 3], there[0, 3] = 0.02 * f, 0.02 * (f + 1)  # the obstacle slides along x
        solver.clear_emitters()
        solver.add_source(src_v, src_t, np.eye(4), np.eye(4), settings, "burner")
        solver.add_obstacle(obs_v, obs_t, here, there, _native.Slip.NO_SLIP, "slab")
        assert solver.advance_frame()
        path = folder / f"volume_{f + 1:04d}.vdb"
        solver.write_vdb(str(path))
        paths.append(path)
    return paths


def test_bakes_with_one_and_two_threads_write_identical_vdb_grids(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir()
    two.mkdir()
    for a, b in zip(_bake_vdbs(one, threads=1), _bake_vdbs(two, threads=2)):
        names = _native.vdb_grid_names(str(a))
        assert sorted(names) == ["density", "flame", "temperature", "velocity"]
        assert names == _native.vdb_grid_names(str(b))
        for name in names:
            ga, gb = _native.read_vdb_grid(str(a), name), _native.read_vdb_grid(str(b), name)
            assert ga["min"] == gb["min"]
            np.testing.assert_array_equal(ga["values"], gb["values"])
    last = _native.read_vdb_grid(str(a), "density")["values"]
    assert last.max() > 0.05  # the bake made smoke: the comparison is not of empty grids
