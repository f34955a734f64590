"""Where the toon particles are introduced on each frame ([Cartoon Smoke] §2.1: "introducing
massless marker particles periodically at the smoke source"), no ``bpy``: the cells of the
domain's Sources on the toon grid, frame by frame, following the sources' motion (their matrix
at that frame, as the bake placed their smoke) and their keyed settings (a Source whose Density
is 0 or whose Emit Particles is off on a frame introduces nothing on it).

    sources = ToonSourceCells(native, grid, emitters, frame_start)  # emitter snapshots
    sources.check()                      # BakeError now for a mesh that cannot be voxelized
    cells = sources.cells_at(frame)      # (N, 3) int32 (i, j, k), or None: no emission

A source is voxelized once per distinct matrix: a static source once for the whole build, an
animated one once per frame (its matrices per frame come from snapshot.emitter_snapshots).
"""

import numpy as np

from .settings import BakeError


def emits(source):
    """Whether a Source's settings of a frame introduce particles (§2.1): smoke to follow
    (Density > 0) and Emit Particles on."""
    return source is not None and source.density > 0.0 and bool(source.emit_particles)


class ToonSourceCells:
    """The Source emitters' cells per frame on a toon.ToonGrid (see the module comment)."""

    def __init__(self, native, grid, emitters, frame_start):
        self.native = native
        self.grid = grid
        self.frame_start = int(frame_start)
        self.sources = [e for e in emitters if e.role == "SOURCE"]
        #: (source index, matrix index) -> (N, 3) int32 cells: each matrix is voxelized once.
        self._cells = {}
        #: The last frame's key and cells: consecutive frames alike share one array.
        self._last = (None, None)
        self.voxelizations = 0  # how many meshes were voxelized so far (static sources: one)

    def __bool__(self):
        return bool(self.sources)

    def _params(self):
        p = self.native.SmokeParams()
        p.resolution = self.grid.resolution
        p.cell_size = self.grid.cell_size
        p.origin = self.grid.origin
        return p

    def _voxelize(self, n, m):
        """Cells (i, j, k) of source n at matrix index m; BakeError naming it when its mesh
        cannot be voxelized."""
        key = (n, m)
        if key not in self._cells:
            e = self.sources[n]
            try:
                linear, _motion = self.native.source_cells(
                    e.vertices, e.triangles, e.matrices[m], e.matrix_at(m + 1), self._params(),
                    e.name)
            except ValueError as err:
                raise BakeError(f"Plume: source '{e.name}': {err}") from None
            self.voxelizations += 1
            nx, ny, _nz = self.grid.resolution
            linear = np.asarray(linear, dtype=np.int64)
            self._cells[key] = np.stack([linear % nx, (linear // nx) % ny, linear // (nx * ny)],
                                        axis=1).astype(np.int32)
        return self._cells[key]

    def key_at(self, frame):
        """(source index, matrix index) of every Source emitting on `frame`."""
        index = frame - self.frame_start
        return tuple((n, min(max(index, 0), len(e.matrices) - 1))
                     for n, e in enumerate(self.sources) if emits(e.source_at(max(index, 0))))

    def cells_at(self, frame):
        """(N, 3) int32 cells of the Sources emitting on `frame` (the bake's frame numbering),
        at their place on that frame; None when none emits there."""
        key = self.key_at(frame)
        if key == self._last[0]:
            return self._last[1]
        parts = [self._voxelize(n, m) for n, m in key]
        cells = np.ascontiguousarray(np.concatenate(parts)) if parts else None
        if cells is not None and len(cells) == 0:
            cells = None
        self._last = (key, cells)
        return cells

    def check(self):
        """Voxelizes every Source at the first frame, so that a mesh that cannot be voxelized is
        reported (BakeError) before anything is written."""
        for n, e in enumerate(self.sources):
            self._voxelize(n, 0)
