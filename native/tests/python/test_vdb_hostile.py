"""Hostile VDB files from Python: a frame written by Plume, then truncated at every
length and given a grid type that is not UTF-8. Every reader raises RuntimeError naming the
file with a readable message (never MemoryError, an empty RuntimeError() or a crash)."""
import pytest

import _native

RES = (6, 8, 5)


def grid():
    return _native.MantaflowGrid(RES, (-0.5, 1.0, 0.25), (0.2, 0.15625, 0.24))


def readers(path):
    return [
        lambda: _native.vdb_grid_names(path),
        lambda: _native.read_vdb_grid(path, "density"),
        lambda: _native.read_vdb_grid(path, "velocity"),
        lambda: _native.read_mantaflow_frame(path, grid()),
    ]


def written(tmp_path):
    path = tmp_path / "volume_0001.vdb"
    _native.write_mantaflow_volume(path, _native.MantaflowFrame.empty(RES), grid(), 1)
    return path, path.read_bytes()


def test_truncated_files_raise_runtime_error_naming_the_file(tmp_path):
    path, data = written(tmp_path)
    assert _native.read_vdb_grid(path, "density")["values"].size == 0  # the file itself reads
    for size in range(0, len(data), 7):
        path.write_bytes(data[:size])
        for read in readers(path):
            with pytest.raises(RuntimeError, match="volume_0001.vdb"):
                read()


def test_a_grid_type_that_is_not_utf8_is_escaped_in_the_message(tmp_path):
    path, data = written(tmp_path)
    at = data.index(b"Tree_float_5_4_3")
    path.write_bytes(data[:at] + b"\xff" + data[at + 1:])
    with pytest.raises(RuntimeError, match=r"volume_0001\.vdb.*\\xffree_float_5_4_3"):
        _native.read_vdb_grid(path, "density")
    with pytest.raises(RuntimeError, match="volume_0001.vdb") as error:
        _native.read_mantaflow_frame(path, grid())
    assert str(error.value)


def test_a_size_field_claiming_gigabytes_is_refused_at_once(tmp_path):
    path, data = written(tmp_path)
    # After the 57-byte header and the metadata count: the first metadata name's length.
    at = 57 + 4
    path.write_bytes(data[:at] + b"\xff\xff\xff\x7f" + data[at + 4:])
    for read in readers(path):
        with pytest.raises(RuntimeError, match="volume_0001.vdb"):
            read()
