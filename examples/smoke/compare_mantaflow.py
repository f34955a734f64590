"""Bake time of Mantaflow vs Plume on the same smoke scene, in one Blender process.

    blender -b --factory-startup --python examples/smoke/compare_mantaflow.py -- [MODE] RES FRAMES
    blender_tests/run.py --blender 4.5 --script examples/smoke/compare_mantaflow.py -- RES FRAMES

Scene (built once per bake): a 2 m cube domain standing on the floor (z 0..2), a UV sphere of
radius 0.16 m at (0, 0, 0.3) emitting smoke (density 1, temperature 1), RES cells along every
axis, frames 1..FRAMES at the factory 24 fps, vorticity, alpha and beta equal in both, closed
floor and open sides/top in both. Mantaflow: Quick Smoke on the sphere, then the domain is
moved/scaled onto the cube; resolution_max RES, cache_type 'MODULAR', OpenVDB with full 32-bit
floats (Plume writes float32), noise, mesh and particles off, its default advection
(MacCormack), baked with bpy.ops.fluid.bake_data() into a temp folder. Plume: a new cube domain
per configuration with the same sphere as SOURCE, baked with bpy.ops.plume.bake().

MODE (the first Plume configuration of a mode is the one the last line's ratio is for):

* none, "matched numerics": one step per frame in both (Mantaflow's adaptive time steps off,
  timesteps_min = timesteps_max = 1; Plume substeps 1, no CFL steps), pressure tolerance 1e-3.
  a. "comparable": MacCormack advection, trilinear interpolation, Euler back-traces. These are
     the settings Mantaflow runs in Blender 3.4 (intern/mantaflow/intern/strings/smoke_script.h:
     advectSemiLagrange(..., order=2) for density, heat and velocity, i.e. MacCormack with
     strength 1 and the defaults orderSpace=1 (trilinear) and orderTrace=1: one Euler step
     back from each grid point with the velocity at that point, getCentered() for cells and
     getAtMACX/Y/Z() for faces, which are exact face averages; and solvePressure() with its
     multigrid-preconditioned CG to cgAccuracy 1e-3). Plume's Trace.EULER uses the same exact
     face averages, so both solvers do the same work per cell: two trilinear passes and a
     clamp per field, and an MGPCG solve to 1e-3. The one difference: Mantaflow's default
     limiter (clampMode 2) falls back to the forward value where the corrected one leaves the
     range, Plume clamps it (Selle et al. 2008 §4, the first limiter).
  b. Plume's default advection (BFECC + monotonic cubic + midpoint traces), one step per frame.
* --defaults, "defaults against defaults": Mantaflow as Quick Smoke makes it (adaptive time
  steps, CFL 4, 1..4 steps a frame), Plume with its domain defaults (BFECC, monotonic cubic,
  midpoint traces, tolerance 1e-4, CFL steps at 4). Then Plume again with Buoyancy Units
  'MANTAFLOW' (α and β read as Mantaflow reads them: the plume Mantaflow makes), with its
  defaults and with Mantaflow's numerics.
* --adaptive: as --defaults (the first two Plume bakes), with both adaptive domains on.

Every bake prints the height of its density centroid at frame min(20, FRAMES) and, for Plume,
its rise above the source centre relative to Mantaflow's (1.00 = the same plume height).

Each bake is timed with time.perf_counter() around the bake operator only (wall clock, VDB
writing included). Both caches are checked (one VDB per frame, smoke in the last frame; one
Mantaflow step per frame in the matched mode) and the script fails (exit code 1) otherwise. Peak
memory: ru_maxrss is the peak of the whole process and cannot be split between two bakes in one
process; on Linux the peak RSS (VmHWM) is reset through /proc/self/clear_refs before each bake
instead, and the cache sizes are printed too. Every Plume configuration is printed with its
ratio (Mantaflow s/frame / Plume s/frame); the last line printed is exactly ``ratio: X`` for
the mode's first configuration (2 decimals).

Needs the Plume add-on installed (BLENDER_USER_SCRIPTS/addons/plume or
~/.config/blender/3.4/scripts/addons/plume). Set PLUME_COMPARE_KEEP=1 to keep the cache folders.
"""

import gzip
import os
import shutil
import struct
import sys
import tempfile
import time
import traceback

import addon_utils
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_measures import (MIB, CompareError, check_vdb_frames, density_centroid_z,  # noqa: E402
                              folder_bytes, peak_rss_since_reset, report, reset_peak_rss)

USAGE = ("usage: blender -b --factory-startup --python "
         "examples/smoke/compare_mantaflow.py -- [--defaults | --adaptive] RES FRAMES\n"
         "  --defaults  each tool's own defaults: Mantaflow's Quick Smoke (adaptive time steps)\n"
         "              against Plume's defaults (BFECC, cubic, midpoint, 1e-4, CFL steps)\n"
         "  --adaptive  as --defaults, with both tools' adaptive domains on\n"
         "              (without either: Mantaflow's numerics in both, one step per frame)\n"
         "  RES     cells along each axis of the 2 m cube domain, integer in [8, 1024]\n"
         "  FRAMES  frames to bake (1..FRAMES), integer >= 1")

#: The modes: the Plume configurations each bakes (the first is the one the last line's ratio is
#: for) and whether Mantaflow keeps its own defaults.
MODES = ("matched", "defaults", "adaptive")

# Shared scene and physics settings (same value in both solvers).
DOMAIN_SIZE = 2.0                  # m, cube standing on the floor
DOMAIN_CENTER = (0.0, 0.0, 1.0)
SOURCE_RADIUS = 0.16
SOURCE_CENTER = (0.0, 0.0, 0.3)
SOURCE_DENSITY = 1.0
SOURCE_TEMPERATURE = 1.0           # temperature difference to the ambient air
VORTICITY = 0.2                    # Plume's default ε
ALPHA = 1.0                        # density buoyancy (both: > 0 makes dense smoke rise)
BETA = 1.0                         # heat buoyancy
PRESSURE_TOLERANCE = 1e-3          # Plume; Mantaflow's fixed gas cgAccuracy is also 1e-3

#: Plume's settings per configuration and mode (see the docstring); the first of a mode is the
#: one the last line's ratio is for. "matched": Mantaflow's numerics, one step per frame;
#: "defaults": the domain's defaults (CFL steps, tolerance 1e-4); "+ Mantaflow buoyancy": the
#: same with α and β read in Mantaflow's units (Buoyancy Units), the plume Mantaflow makes.
MATCHED = dict(advection='MACCORMACK', interpolation='LINEAR', trace='EULER',
               pressure_tolerance=PRESSURE_TOLERANCE, substeps=1, use_cfl=False)
PLUME_DEFAULTS = dict(advection='BFECC', interpolation='MONOTONIC_CUBIC', trace='MIDPOINT',
                      linear_velocity=True)
#: The defaults with Advection > Fast Velocity off: the velocity carried by cubic samples too.
CUBIC = dict(PLUME_DEFAULTS, linear_velocity=False)
PLUME_CONFIGS = {
    "matched": (("comparable", MATCHED),
                ("defaults, one step per frame",
                 dict(PLUME_DEFAULTS, pressure_tolerance=PRESSURE_TOLERANCE, substeps=1, use_cfl=False))),
    "defaults": (("defaults", dict(PLUME_DEFAULTS)),
                 ("defaults, cubic velocity", dict(CUBIC)),
                 ("defaults + Mantaflow buoyancy", dict(PLUME_DEFAULTS,
                                                        buoyancy_units='MANTAFLOW')),
                 ("defaults, cubic velocity + Mantaflow buoyancy",
                  dict(CUBIC, buoyancy_units='MANTAFLOW')),
                 ("comparable + Mantaflow buoyancy", dict(MATCHED, buoyancy_units='MANTAFLOW'))),
    "adaptive": (("defaults, adaptive domain", dict(PLUME_DEFAULTS, adaptive_domain=True)),
                 ("defaults, cubic velocity, adaptive domain", dict(CUBIC, adaptive_domain=True)),
                 ("defaults + Mantaflow buoyancy, adaptive domain",
                  dict(PLUME_DEFAULTS, buoyancy_units='MANTAFLOW', adaptive_domain=True))),
}
#: Frame whose density centroid is compared (the issue's "after 20 frames"), or the last one.
CENTROID_FRAME = 20

MANTA_DOMAIN = "MantaDomain"
PLUME_DOMAIN = "PlumeDomain"


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    flags = [a for a in argv if a.startswith("--")]
    argv = [a for a in argv if not a.startswith("--")]
    mode = "matched"
    for flag in flags:
        if flag not in ("--defaults", "--adaptive") or mode != "matched":
            sys.exit(f"{USAGE}\nerror: unknown or second mode flag {flag!r}")
        mode = flag[2:]
    if len(argv) != 2:
        sys.exit(f"{USAGE}\nerror: expected RES and FRAMES after '--', got {argv}")
    values = []
    for name, text in zip(("RES", "FRAMES"), argv):
        try:
            values.append(int(text))
        except ValueError:
            sys.exit(f"{USAGE}\nerror: {name} must be an integer (got {text!r})")
    res, frames = values
    if not 8 <= res <= 1024:
        sys.exit(f"{USAGE}\nerror: RES must be in [8, 1024] (got {res})")
    if frames < 1:
        sys.exit(f"{USAGE}\nerror: FRAMES must be at least 1 (got {frames})")
    return mode, res, frames


# --- helpers ------------------------------------------------------------------------------------

def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)


def select_only(obj):
    vl = bpy.context.view_layer
    for o in vl.objects:
        o.select_set(False)
    obj.select_set(True)
    vl.objects.active = obj


def manta_centroid_z(cache_dir, frame, native, res):
    """density_centroid_z() of a Mantaflow frame, its adaptive box read from its config."""
    from plume import mantaflow_cache
    config = mantaflow_cache.read_config(
        os.path.join(cache_dir, "config", f"config_{frame:04d}.uni"))
    return density_centroid_z(manta_frame(cache_dir, frame), native, DOMAIN_SIZE / res,
                              config.res_min[2])


# --- Mantaflow ----------------------------------------------------------------------------------

def build_mantaflow(res, frames, cache_dir, mode):
    """Quick Smoke on a small sphere, domain moved onto the shared 2 m cube. Returns (domain, sphere).
    "matched": one step per frame; "defaults" keeps Quick Smoke's adaptive time steps (CFL 4,
    1 to 4 steps a frame); "adaptive" also turns its adaptive domain on (its default margin and
    threshold)."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=SOURCE_RADIUS, location=SOURCE_CENTER)
    sphere = bpy.context.active_object
    sphere.name = "SmokeSource"
    select_only(sphere)
    from plume import blender_compat
    blender_compat.repair_mantaflow_bindings()  # the bpy wheels' Mantaflow cannot bake without
    if bpy.ops.object.quick_smoke(style='SMOKE') != {'FINISHED'}:
        raise CompareError("bpy.ops.object.quick_smoke() failed")
    dom = bpy.context.active_object
    dom.name = MANTA_DOMAIN
    # Quick Smoke sizes the domain around the sphere (+1 m, +2 m up): put it on the shared cube.
    # The default cube has size 2, so scale 1 = the 2 m cube.
    dom.location = DOMAIN_CENTER
    dom.scale = (DOMAIN_SIZE / 2.0,) * 3

    ds = next(m for m in dom.modifiers if m.type == 'FLUID').domain_settings
    ds.domain_type = 'GAS'
    ds.resolution_max = res
    if mode == "matched":
        ds.use_adaptive_timesteps = False
        ds.timesteps_min = 1
        ds.timesteps_max = 1
    ds.time_scale = 1.0
    ds.use_adaptive_domain = mode == "adaptive"
    ds.use_noise = False
    ds.use_dissolve_smoke = False
    ds.use_guide = False
    ds.vorticity = VORTICITY
    ds.alpha = ALPHA
    ds.beta = BETA
    ds.gravity = (0.0, 0.0, -9.81)  # used when the scene has no gravity; the scene's is the same
    # Plume's default boundaries: closed floor, open elsewhere.
    ds.use_collision_border_bottom = True
    for side in ("top", "front", "back", "left", "right"):
        setattr(ds, "use_collision_border_" + side, False)
    ds.cache_type = 'MODULAR'
    ds.cache_data_format = 'OPENVDB'
    ds.openvdb_data_depth = '32'            # full floats, like Plume's float32 grids
    # Plume writes Blosc too; Blender 5.0 offers only Zip or none, and none is the faster
    compress = ds.bl_rna.properties["openvdb_cache_compress_type"].enum_items.keys()
    ds.openvdb_cache_compress_type = 'BLOSC' if 'BLOSC' in compress else 'NONE'
    ds.cache_resumable = False
    ds.cache_directory = cache_dir
    ds.cache_frame_start = 1
    ds.cache_frame_end = frames
    # (Mesh, particles and noise are liquid/upres options and stay off for a gas domain.)

    fs = next(m for m in sphere.modifiers if m.type == 'FLUID').flow_settings
    fs.flow_type = 'SMOKE'
    fs.flow_behavior = 'INFLOW'
    fs.flow_source = 'MESH'
    fs.density = SOURCE_DENSITY
    fs.temperature = SOURCE_TEMPERATURE
    fs.volume_density = 1.0   # fill the sphere like Plume's voxelized source (Quick Smoke: 0, shell only)
    fs.use_initial_velocity = False
    fs.subframes = 0
    return dom, sphere


def bake_mantaflow(dom):
    select_only(dom)
    with bpy.context.temp_override(object=dom, active_object=dom, selected_objects=[dom]):
        t0 = time.perf_counter()
        result = bpy.ops.fluid.bake_data()
        seconds = time.perf_counter() - t0
    if result != {'FINISHED'}:
        raise CompareError(f"bpy.ops.fluid.bake_data() returned {result}")
    return seconds


def read_manta_config(path):
    """(res, dt, time_total) from Mantaflow's config_####.uni (fluid.c manta_write_config, cache
    version C01), or None if the layout is not the expected one."""
    try:
        with gzip.open(path, "rb") as f:
            b = f.read()
    except OSError:
        return None
    if len(b) < 32 or b[-4:] != b"C01\x00":
        return None
    res = struct.unpack_from("<3i", b, 4)
    dt = struct.unpack_from("<f", b, 20)[0]
    time_total = struct.unpack_from("<f", b, len(b) - 8)[0]
    return res, dt, time_total


def manta_frame(cache_dir, frame):
    return os.path.join(cache_dir, "data", f"fluid_data_{frame:04d}.vdb")


def check_mantaflow(cache_dir, res, frames, native, mode):
    data = [manta_frame(cache_dir, f) for f in range(1, frames + 1)]
    peak = check_vdb_frames("Mantaflow", data, native)
    if mode != "matched":
        return peak, None  # its own adaptive time steps: no step count to check
    # One step per frame: dt must be the whole frame and the simulated time frames * dt.
    fps = bpy.context.scene.render.fps / bpy.context.scene.render.fps_base
    frame_length = 0.1 * (25.0 / fps)  # fluid.c: DT_DEFAULT * (25 / fps) * time_scale
    cfg = read_manta_config(os.path.join(cache_dir, "config", f"config_{frames:04d}.uni"))
    if cfg is None:
        print("compare_mantaflow: warning: cannot read Mantaflow's config file; "
              "one step per frame not verified", flush=True)
        return peak, None
    grid_res, dt, time_total = cfg
    if tuple(grid_res) != (res, res, res):
        raise CompareError(f"Mantaflow grid is {grid_res}, expected {(res, res, res)}")
    if abs(dt - frame_length) > 1e-5 * frame_length or \
            abs(time_total - frames * frame_length) > 1e-3 * frames * frame_length:
        raise CompareError(f"Mantaflow did not take one step per frame: dt {dt:.6g}, simulated "
                           f"time {time_total:.6g}, frame length {frame_length:.6g}")
    return peak, grid_res


def remove_mantaflow(dom, sphere):
    """Frees the Mantaflow domain (and its solver memory) and the sphere's flow modifier."""
    for m in [m for m in sphere.modifiers if m.type == 'FLUID']:
        sphere.modifiers.remove(m)
    mesh = dom.data
    bpy.data.objects.remove(dom, do_unlink=True)
    if mesh.users == 0:
        bpy.data.meshes.remove(mesh)


# --- Plume --------------------------------------------------------------------------------------

def build_plume(res, frames, cache_dir, sphere, name, config):
    """A Plume domain on the shared cube; `config` sets domain properties over their defaults."""
    bpy.ops.mesh.primitive_cube_add(size=DOMAIN_SIZE, location=DOMAIN_CENTER)
    dom = bpy.context.active_object
    dom.name = name
    select_only(dom)
    bpy.ops.plume.role_set(role='DOMAIN')
    d = dom.plume.domain
    d.resolution = res
    d.frame_start, d.frame_end = 1, frames
    d.time_scale = 1.0
    d.cache_directory = cache_dir
    d.vorticity = VORTICITY
    d.turbulence = 0.0  # Mantaflow's air has no turbulence force: the same air in both
    d.alpha = ALPHA
    d.beta = BETA
    d.gravity = (0.0, 0.0, -9.81)
    d.threads = 0
    d.combustion = False
    d.density_dissipation = 0.0
    d.wind_strength = 0.0
    for side in ("neg_x", "pos_x", "neg_y", "pos_y", "pos_z"):
        setattr(d, "boundary_" + side, 'OPEN')
    d.boundary_neg_z = 'CLOSED'
    for key, value in config.items():
        if not hasattr(d, key):
            raise CompareError(f"this Plume has no domain setting {key!r}")
        setattr(d, key, value)

    select_only(sphere)
    bpy.ops.plume.role_set(role='SOURCE')
    s = sphere.plume.source
    s.density = SOURCE_DENSITY
    s.temperature = SOURCE_TEMPERATURE
    s.velocity = (0.0, 0.0, 0.0)
    s.smoke_noise = 0.0  # an even source, as Mantaflow's
    if dom.plume.role != 'DOMAIN' or sphere.plume.role != 'SOURCE':
        raise CompareError("plume.role_set did not set the domain/source roles")
    return dom


def bake_plume(dom):
    select_only(dom)
    t0 = time.perf_counter()
    result = bpy.ops.plume.bake()  # RuntimeError with Plume's message on failure
    seconds = time.perf_counter() - t0
    if result != {'FINISHED'}:
        raise CompareError(f"bpy.ops.plume.bake() returned {result}")
    return seconds


def check_plume(folder, frames, native):
    vdbs = [os.path.join(folder, f"volume_{f:04d}.vdb") for f in range(1, frames + 1)]
    return check_vdb_frames("Plume", vdbs, native)


# --- main ---------------------------------------------------------------------------------------

def run(mode, res, frames, work):
    mod = addon_utils.enable("plume", default_set=True)
    if mod is None or not hasattr(bpy.ops.plume, "bake"):
        raise CompareError("the plume add-on is not installed (see README: install_addon)")
    from plume import _native  # the add-on's native module (VDB reading for the checks)

    if not bpy.app.build_options.fluid or not bpy.app.build_options.openvdb:
        raise CompareError("this Blender is built without Mantaflow (fluid) or OpenVDB")

    scene = bpy.context.scene
    clear_scene()
    scene.frame_start, scene.frame_end = 1, frames
    scene.frame_set(1)
    manta_dir = os.path.join(work, "mantaflow")
    plume_dir = os.path.join(work, "plume")
    os.makedirs(manta_dir)
    os.makedirs(plume_dir)
    centroid_frame = min(CENTROID_FRAME, frames)
    print(f"compare_mantaflow: Blender {bpy.app.version_string}, mode {mode}, {res}^3 cells, "
          f"{frames} frames at {scene.render.fps} fps, caches in {work}", flush=True)

    # 1. Mantaflow
    manta_dom, sphere = build_mantaflow(res, frames, manta_dir, mode)
    rss0 = reset_peak_rss()
    manta_s = bake_mantaflow(manta_dom)
    manta_peak = peak_rss_since_reset() if rss0 is not None else None
    manta_rss0 = rss0
    manta_density, _ = check_mantaflow(manta_dir, res, frames, _native, mode)
    manta_z = manta_centroid_z(manta_dir, centroid_frame, _native, res)
    manta_cache = folder_bytes(manta_dir)
    manta_vdb = folder_bytes(os.path.join(manta_dir, "data"), r"fluid_data_\d+\.vdb")
    remove_mantaflow(manta_dom, sphere)
    scene.frame_set(1)

    report("mantaflow", manta_s, frames, manta_cache, manta_vdb, manta_rss0, manta_peak,
           f", max density {manta_density:.3g}, density centroid at frame {centroid_frame} "
           f"{manta_z:.3f} m")

    # 2. Plume, once per configuration, each on its own domain (removed after its bake)
    ratios = []
    for config, settings in PLUME_CONFIGS[mode]:
        name = f"{PLUME_DOMAIN}_{len(ratios)}"
        plume_dom = build_plume(res, frames, plume_dir + os.sep, sphere, name, settings)
        rss0 = reset_peak_rss()
        plume_s = bake_plume(plume_dom)
        plume_peak = peak_rss_since_reset() if rss0 is not None else None
        plume_folder = os.path.join(plume_dir, plume_dom.name)
        plume_density = check_plume(plume_folder, frames, _native)
        plume_z = density_centroid_z(os.path.join(plume_folder, f"volume_{centroid_frame:04d}.vdb"),
                                     _native, DOMAIN_SIZE / res)
        plume_cache = folder_bytes(plume_folder)
        plume_vdb = folder_bytes(plume_folder, r"volume_\d+\.vdb")
        state_bytes = folder_bytes(plume_folder, r"state\.bin")
        ratio = (manta_s / frames) / (plume_s / frames)
        rise = (plume_z - SOURCE_CENTER[2]) / (manta_z - SOURCE_CENTER[2])
        described = ", ".join(f"{k} {v}" for k, v in settings.items())
        report(f"plume {config} ({described})", plume_s, frames, plume_cache, plume_vdb, rss0,
               plume_peak, f", max density {plume_density:.3g}, density centroid at frame "
               f"{centroid_frame} {plume_z:.3f} m (rise above the source {rise:.2f}x "
               f"Mantaflow's), incl. state.bin checkpoint {state_bytes / MIB:.1f} MiB; "
               f"ratio {ratio:.2f}")
        ratios.append(ratio)
        mesh = plume_dom.data
        bpy.data.objects.remove(plume_dom, do_unlink=True)
        if mesh.users == 0:
            bpy.data.meshes.remove(mesh)
        scene.frame_set(1)
    if rss0 is None:
        print("note: ru_maxrss is the peak of the whole process and cannot be split between "
              "the bakes; compare the cache sizes instead", flush=True)
    return ratios[0]


def main():
    mode, res, frames = parse_args()
    work = tempfile.mkdtemp(prefix="plume_vs_mantaflow_")
    keep = os.environ.get("PLUME_COMPARE_KEEP", "") not in ("", "0")
    try:
        ratio = run(mode, res, frames, work)
    except Exception as e:  # noqa: BLE001 - any failure must end the run with exit code 1
        traceback.print_exc()
        print(f"compare_mantaflow: FAILED: {e}", file=sys.stderr, flush=True)
        sys.exit(1)
    finally:
        # Free the Mantaflow domain while Python runs (the bpy module aborts freeing it at exit).
        bpy.ops.wm.read_homefile(use_factory_startup=True)
        if keep:
            print(f"compare_mantaflow: caches kept in {work}", flush=True)
        else:
            shutil.rmtree(work, ignore_errors=True)
    print(f"ratio: {ratio:.2f}", flush=True)
    sys.exit(0)  # skip Blender's own "Blender quit" line: "ratio" stays the last line


if __name__ == "__main__":
    main()
