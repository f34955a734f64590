"""Scenes shared by the streak tests (test_streak.py, test_streak_clusters.py): a small domain
and a solver whose box source is filled with traced point sources."""
import numpy as np

import _native
from meshes import box_mesh


def small_params(**overrides):
    p = _native.SmokeParams(resolution=(16, 16, 20), cell_size=1.0 / 16)
    for key, value in overrides.items():
        setattr(p, key, value)
    return p


def streaking_solver(params, points_per_cell=3, emission_period=1):
    """Solver with a box source and a tracer whose point sources fill the source cells."""
    solver = _native.SmokeSolver(params)
    vertices, triangles = box_mesh((0.4, 0.4, 0.05), (0.6, 0.6, 0.2))
    settings = _native.SourceSettings()
    settings.velocity = (0.0, 0.0, 0.5)
    cells, motion = _native.source_cells(vertices, triangles, np.eye(4), np.eye(4), params, "src")
    assert solver.add_source(vertices, triangles, np.eye(4), np.eye(4), settings, "src") == len(cells)
    points = _native.random_points_in_cells(cells, params.resolution, params.cell_size,
                                            params.origin, points_per_cell, params.seed)
    velocities = np.repeat(motion, points_per_cell, axis=0) + np.asarray(settings.velocity)
    tracer = _native.StreakTracer(params, emission_period=emission_period)
    assert tracer.add_point_sources(points, np.zeros(len(points), int), velocities) == 0
    return solver, tracer, points
