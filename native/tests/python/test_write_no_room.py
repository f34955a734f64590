"""Every native cache writer when the file does not fit (disk full; here the file size limit,
RLIMIT_FSIZE with SIGXFSZ ignored, which fails write(2) with EFBIG the same way): a RuntimeError
naming the file and the reason, the file written before at that path left byte for byte, no
temporary or partial file left, and the same write succeeds once there is room."""
import contextlib
import os
import resource
import signal

import numpy as np
import pytest

import _native
from streak_scenes import small_params, streaking_solver


@contextlib.contextmanager
def file_size_limit(limit):
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        signal.signal(signal.SIGXFSZ, handler)


def assert_write_refused(path, write):
    """write() succeeds, then fails under a limit of half the file's size, leaving the first
    file as it was and nothing else; then succeeds again."""
    write()
    with open(path, "rb") as f:
        before = f.read()
    with file_size_limit(len(before) // 2):
        with pytest.raises(RuntimeError) as info:
            write()
    msg = str(info.value)
    assert str(path) in msg and "the file size limit is reached (File too large)" in msg, msg
    with open(path, "rb") as f:
        assert f.read() == before
    assert sorted(os.listdir(os.path.dirname(path))) == [os.path.basename(path)]
    write()
    return msg


@pytest.fixture
def traced():
    params = small_params()
    solver, tracer, _ = streaking_solver(params)
    for _ in range(3):
        assert _native.advance_frame_with_tracers(solver, tracer)
    return solver, tracer


def test_vdb_frame(tmp_path, traced):
    solver, _ = traced
    path = tmp_path / "volume_0003.vdb"
    assert_write_refused(path, lambda: solver.write_vdb(str(path)))


def test_solver_state(tmp_path, traced):
    solver, _ = traced
    path = tmp_path / "state.bin"
    assert_write_refused(path, lambda: solver.save_state(str(path)))


def test_tracer_state_and_streak_file(tmp_path, traced):
    _, tracer = traced
    path = tmp_path / "tracer_state.bin"
    assert_write_refused(path, lambda: tracer.save_state(str(path), frame=3))
    streak_dir = tmp_path / "streaks"
    streak_dir.mkdir()
    path = streak_dir / "streaks_0003.bin"
    assert_write_refused(path, lambda: _native.write_streak_file(str(path), tracer.snapshot()))


def test_pathline_file_leaves_no_partial(tmp_path):
    params = small_params()
    solver = _native.SmokeSolver(params)
    cells = np.arange(16 * 16 + 100, 16 * 16 + 104)
    path = tmp_path / "pathlines.bin"
    recorder = _native.PathlineRecorder(_native.PathlineParams(nodes_per_frame=2), params, cells,
                                        str(path))
    with file_size_limit(4096):
        with pytest.raises(RuntimeError) as info:
            for _ in range(200):  # appends node groups until one passes the limit
                recorder.advance_frame(solver)
    msg = str(info.value)
    assert str(path) in msg and "the file size limit is reached" in msg, msg
    recorder.discard()
    assert os.listdir(tmp_path) == []
