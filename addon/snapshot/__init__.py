"""Scene -> plain settings (bpy side, main thread, before a job starts): one module per pipeline
(smoke: a domain's grid bake; streaks; toon; flowgraph; flames) and the scene reading they share
(scene). What a job's child process gets from here (its job file) holds no bpy data."""

from .scene import (NOT_A_DOMAIN, EMITTER_ROLES, absolute_folder, active_domain,
                    blend_relative, cache_folder_of, domain_bbox, emitter_snapshots,
                    flames_cache_folder, from_properties, mesh_arrays, point_source_vertices,
                    scene_emitters, source_params, vertex_group_of_vertices)
from .smoke import flame_smoke_settings, mantaflow_source, solver_settings, take_snapshot

__all__ = ["NOT_A_DOMAIN", "EMITTER_ROLES", "absolute_folder", "active_domain", "blend_relative",
           "cache_folder_of", "domain_bbox", "emitter_snapshots", "flame_smoke_settings",
           "flames_cache_folder", "from_properties", "mantaflow_source", "mesh_arrays",
           "point_source_vertices", "scene_emitters", "solver_settings", "source_params",
           "take_snapshot", "vertex_group_of_vertices"]
