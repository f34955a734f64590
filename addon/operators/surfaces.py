"""plume.surfaces_build on the active baked domain (smoke_surfaces.txt §3.3-3.4): streak files ->
h per candidate group -> clusters (h0) -> greedy order -> one SURFACE object per cluster with
per-frame control points and a density-map material. Everything is computed and checked before
the scene is touched, so bad input changes nothing."""

import os
import time

import bpy
import numpy as np

from .. import _native, cache
from .. import streak_surfaces as ss
from ..build import surfaces as build
from ..settings import BakeError
from ..snapshot import active_domain, cache_folder_of

#: h per candidate group, cached in memory for the panel's live count (never computed in draw):
#: domain name -> (key of the cache state, {group: GroupDistances})
_distances = {}


def _cache_key(folder, manifest):
    run = manifest.get("last_run", {})
    return (folder, manifest.get("last_complete_frame"), manifest.get("frames_computed_total"),
            run.get("seconds"))


def cached_distances(domain):
    """The h matrices of the domain's last computation if they match its cache, else None."""
    hit = _distances.get(domain.name)
    if hit is None:
        return None
    folder = cache_folder_of(domain)
    m = cache.read_manifest(folder)
    if m is None or _cache_key(folder, m) != hit[0]:
        return None
    return hit[1]


def live_summary(domain):
    """(surfaces, streaklines) for the domain's current h0 from cached h, or None."""
    groups = cached_distances(domain)
    h0 = domain.plume.domain.streak_threshold
    if groups is None or not np.isfinite(h0) or h0 < 0:
        return None
    try:
        return ss.summary(_native, groups, h0)
    except ValueError:
        return None


def compute_distances(domain):
    """Reads the streak files and computes h per group (BakeError on bad input); cached."""
    folder = cache_folder_of(domain)
    m = ss.streak_manifest(folder, domain.name)
    frame_start, last = int(m["frame_start"]), int(m["last_complete_frame"])
    frames = ss.load_frames(_native, folder, frame_start, last)
    groups = ss.group_distances(_native, frames)
    _distances[domain.name] = (_cache_key(folder, m), groups)
    return folder, m, frames, groups


def _settings_of(d):
    for name in ("density_k_u", "density_k_v"):
        k = getattr(d, name)
        if k < 0:
            raise BakeError(f"Plume: {name} must be >= 0 (samples between particles, §3.4; "
                            f"got {k})")
    return {"k_u": int(d.density_k_u), "k_v": int(d.density_k_v), "falloff": d.sheet_falloff,
            "color": tuple(d.sheet_color), "brightness": float(d.sheet_brightness),
            "opacity": float(d.sheet_opacity)}


class PLUME_OT_surfaces_build(bpy.types.Operator):
    """Build streak surfaces (NURBS smoke sheets) from the active domain's streak bake"""

    bl_idname = "plume.surfaces_build"
    bl_label = "Build Surfaces"
    bl_options = {'REGISTER'}  # writes cache files, which undo would not restore

    def execute(self, context):
        t0 = time.perf_counter()
        try:
            domain = active_domain(context)
            d = domain.plume.domain
            settings = _settings_of(d)
            ss.check_threshold(d.streak_threshold, domain.name)
            folder, m, frames, groups = compute_distances(domain)
            plans = ss.plan_surfaces(_native, groups, d.streak_threshold)
            if not plans:
                raise BakeError(f"Plume: threshold h0 = {d.streak_threshold} joins no two "
                                "streaklines: raise streak_threshold (0 = the default mean of h)")
            anims = [ss.surface_animation(_native, frames, p) for p in plans]
            frame_start = int(m["frame_start"])
            maps = self._density_maps(folder, m, anims, settings)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        except (ValueError, RuntimeError) as e:
            self.report({'ERROR'}, f"Plume: surfaces of '{context.active_object.name}': {e}")
            return {'CANCELLED'}
        # Nothing above touched the scene; now the files, then the objects.
        for path in cache.surface_files(folder):
            os.remove(path)
        sheets = []
        for i, (anim, images) in enumerate(zip(anims, maps)):
            tmp = cache.surface_path(folder, i) + ".tmp.npz"
            np.savez(tmp, control_points=anim.control_points, frame_start=frame_start,
                     nu=anim.nu, nv=anim.nv, order_u=anim.order_u, order_v=anim.order_v)
            os.replace(tmp, cache.surface_path(folder, i))
            first = build.write_sheet_images(folder, i, frame_start, images)
            sheets.append((first, images[0].shape[1], images[0].shape[0], len(images)))
        objs = build.build_surfaces(context, domain, folder, frame_start, anims, sheets, settings)
        lines = sum(len(p.sources) for p in plans)
        self.report({'INFO'}, f"Plume: {len(objs)} surfaces from {lines} streaklines "
                              f"({time.perf_counter() - t0:.1f} s)")
        return {'FINISHED'}

    @staticmethod
    def _density_maps(folder, m, anims, settings):
        """§3.4 density map of every surface at every frame (from the VDB density grids)."""
        res = tuple(m["resolution"])
        origin, cell = tuple(m["origin"]), float(m["cell_size"])
        interp = getattr(_native.Interpolation, m["settings"]["solver"]["interpolation"])
        frame_start = int(m["frame_start"])
        maps = [[] for _ in anims]
        for n in range(len(anims[0].surfaces)):
            path = cache.volume_path(folder, frame_start + n)
            if not os.path.isfile(path):
                raise BakeError(f"Plume: volume file {path} is missing: bake the domain again")
            density = ss.dense_density(_native, path, res)
            for i, anim in enumerate(anims):
                maps[i].append(ss.density_image(
                    _native, anim.surfaces[n], density, origin, cell, settings["k_u"],
                    settings["k_v"], interp, anim.particles, anim.nv))
        return maps


class PLUME_OT_surfaces_pick_threshold(bpy.types.Operator):
    """Set h0 to the threshold giving the most surfaces (the peak of the paper's Figure 4 curve)"""

    bl_idname = "plume.surfaces_pick_threshold"
    bl_label = "Most Surfaces"
    bl_options = {'REGISTER', 'UNDO'}  # changes one property, nothing on disk

    def execute(self, context):
        try:
            domain = active_domain(context)
            _folder, _m, _frames, groups = compute_distances(domain)
            h0 = ss.most_surfaces_threshold(_native, groups)
        except BakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        domain.plume.domain.streak_threshold = h0
        surfaces, lines = ss.summary(_native, groups, h0)
        self.report({'INFO'}, f"Plume: h0 = {h0:.4g} gives {surfaces} surfaces from {lines} "
                              "streaklines")
        return {'FINISHED'}


classes = (PLUME_OT_surfaces_build, PLUME_OT_surfaces_pick_threshold)
