"""Scene › Plume Farm → a farm job (bpy side): the job's folder on the shared storage, the task
graph of what the artist asked for, and every check that must pass before anything is submitted
(Slurm found, a folder the farm can see, no path in the scene the farm cannot see, wedge
settings that exist, a time limit longer than one measured frame). Nothing here writes."""

import json
import math
import os
import sys
from dataclasses import dataclass, field

import bpy

from .. import cache
from ..farm import slurm
from ..farm.graph import FarmError, FarmGraph, Task
from .scene import absolute_folder, cache_folder_of

SHOT = "shot.blend"
PANEL = "Scene Properties › Plume Farm"


@dataclass
class FarmJob:
    folder: str          # the job's folder here: <Farm Folder>/<blend>_<job>_<NNN>/
    farm_folder: str     # the same folder as the farm's machines see it
    graph: FarmGraph
    wedge: dict = field(default_factory=dict)  # wedge.json: settings, count, frame


def to_farm(path, farm):
    """`path` as the farm sees it (Path Here → Path on Farm); unchanged without a mapping."""
    here = _dir(farm.path_here)
    if not here or not farm.path_farm:
        return path
    rel = os.path.relpath(path, here)
    return os.path.join(farm.path_farm, rel) if not rel.startswith("..") else path


def _dir(path):
    return os.path.join(os.path.abspath(bpy.path.abspath(path)), "") if path else ""


def farm_folder(farm):
    """The Farm Folder here, absolute; FarmError when unset, not writable, or outside the
    mapped storage."""
    if not farm.folder.strip():
        raise FarmError(f"Plume farm: set {PANEL} › Farm Folder to a folder every farm machine "
                        "sees (the shared project storage)")
    root = _dir(farm.folder)
    here = _dir(farm.path_here)
    if here and not root.startswith(here):
        raise FarmError(f"Plume farm: the Farm Folder {root} is not under Path Here ({here}), "
                        "so the farm cannot see it: choose a folder on the shared storage or "
                        f"correct {PANEL} › Path Here")
    if bool(farm.path_here.strip()) != bool(farm.path_farm.strip()):
        raise FarmError(f"Plume farm: set both {PANEL} › Path Here and Path on Farm (or neither, "
                        "when the farm sees the same paths)")
    os.makedirs(root, exist_ok=True)
    if not os.access(root, os.W_OK):
        raise FarmError(f"Plume farm: the Farm Folder {root} is not writable")
    return root


def unseen_paths(farm, root):
    """[(what, path)] of absolute file paths in the scene the farm cannot see: not under the
    Farm Folder nor the mapped storage. Relative ("//") paths travel with the shot's copy."""
    here = _dir(farm.path_here) or root
    found = []
    for ob in bpy.data.objects:
        p = getattr(ob, "plume", None)
        if p is not None and p.role == 'DOMAIN':
            found.append((f"object '{ob.name}' › Physics › Plume › Cache › Directory",
                          p.domain.cache_directory))
    found.append(("Scene › Plume Flames › Cache Directory",
                  bpy.context.scene.plume_flames.cache_directory))
    found += [("a file the scene uses", p) for p in bpy.utils.blend_paths(absolute=False)]
    return [(what, p) for what, p in found
            if p and not p.startswith("//") and os.path.isabs(p)
            and not os.path.join(os.path.abspath(p), "").startswith((here, root))]


def parse_wedge(text, domain):
    """{setting: [values]} of Wedge Settings ("vorticity = 0.1, 0.3; seed = 1, 2"), each a
    domain setting that exists, each value in its range, all lists of one length."""
    d = domain.plume.domain
    props = d.bl_rna.properties
    settings = {}
    for part in (p.strip() for p in text.split(";")):
        if not part:
            continue
        name, eq, values = part.partition("=")
        name = name.strip()
        if not eq or name not in props or name == "rna_type":
            raise FarmError(f"Plume farm: Wedge Settings: '{name}' is not a setting of a Plume "
                            "domain (use the Python name its tooltip shows, e.g. vorticity, "
                            f"seed, resolution) in {PANEL} › Wedge Settings")
        prop = props[name]
        if prop.type not in {'INT', 'FLOAT', 'BOOLEAN'} or getattr(prop, "array_length", 0):
            raise FarmError(f"Plume farm: Wedge Settings: '{prop.name}' ({name}) is not a "
                            "single number; a wedge varies numbers and on/off settings")
        try:
            cast = {'INT': int, 'FLOAT': float,
                    'BOOLEAN': lambda v: v.lower() in ("1", "true", "on", "yes")}[prop.type]
            vals = [cast(v.strip()) for v in values.split(",") if v.strip()]
        except ValueError:
            raise FarmError(f"Plume farm: Wedge Settings: the values of '{prop.name}' must be "
                            f"numbers separated by commas, not '{values.strip()}'") from None
        settings[name] = vals
    if not settings:
        raise FarmError(f"Plume farm: {PANEL} › Wedge Settings is empty: give at least one "
                        "'setting = value, value, …'")
    counts = {len(v) for v in settings.values()}
    if len(counts) != 1 or counts == {0}:
        raise FarmError("Plume farm: Wedge Settings: every setting needs the same number of "
                        f"values (one per variant); got {', '.join(f'{k} {len(v)}' for k, v in settings.items())}")
    return settings


def check_bakes(context, domain, settings=None):
    """The bake's own checks on the domain, before anything is submitted (a node would only
    fail later); with wedge `settings` on each variant, tried on the domain and undone.
    FarmError naming the variant, the setting and its range."""
    from .. import bake_runner, setting_paths
    from ..native import _native
    from ..settings import BakeError
    from .smoke import take_snapshot
    d = domain.plume.domain
    settings = settings or {}
    kept = {name: getattr(d, name) for name in settings}
    variants = len(next(iter(settings.values()))) if settings else 1
    try:
        for i in range(variants):
            for name, values in settings.items():
                setattr(d, name, values[i])
            try:
                with context.temp_override(active_object=domain, object=domain):
                    bake_runner.check_input(take_snapshot(bpy.context), _native)
            except BakeError as e:
                why = setting_paths.in_ui_words(str(e)).removeprefix("Plume: ")
                where = f"Wedge Settings, variant {i}" if settings else f"domain '{domain.name}'"
                raise FarmError(f"Plume farm: {where}: {why}") from None
    finally:
        for name, value in kept.items():
            setattr(d, name, value)


def seconds_per_frame(domain):
    """The last local bake's measured seconds per frame of a domain, or None."""
    m = cache.read_manifest(cache_folder_of(domain))
    run = (m or {}).get("last_run") or {}
    frames = len(run.get("computed_frames") or ())
    return float(run["seconds"]) / frames if frames and run.get("seconds") else None


def check_time_limit(farm, domains):
    for dom in domains:
        cost = seconds_per_frame(dom)
        if cost is not None and cost > 60.0 * farm.time_limit:
            raise FarmError(f"Plume farm: {PANEL} › Time Limit ({farm.time_limit} min) is shorter "
                            f"than one frame of domain '{dom.name}' ({cost / 60:.1f} min per "
                            "frame in its last bake here): raise it")


def blender_command(farm):
    """How a task starts this Blender on a node, with node_task.py: the real executable
    headless, or the Python of a `bpy` wheel."""
    task = to_farm(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "farm", "node_task.py"), farm)
    if bpy.app.binary_path:
        return [to_farm(bpy.app.binary_path, farm), "-b", "--python-exit-code", "1",
                "--python", task, "--", SHOT]
    return [to_farm(sys.executable, farm), task, SHOT]


def _domains_with_pathlines():
    return sorted((o for o in bpy.data.objects if getattr(o, "plume", None) is not None
                   and o.plume.role == 'DOMAIN' and o.plume.domain.pathlines),
                  key=lambda o: o.name)


def _render_task(scene, farm, run, after):
    frames = scene.frame_end - scene.frame_start + 1
    return Task("render", run + ["render", str(farm.chunk), "{index}"],
                count=max(1, math.ceil(frames / farm.chunk)), after=after, cpus=farm.cpus,
                label=f"render frames {scene.frame_start}-{scene.frame_end}, {farm.chunk} a task")


def _synthesis_task(owner, farm, run):
    """Synthesize Fire in chunks of Frames per Task, side by side: each replays the walk from
    the first frame and writes its own frames (flowgraph_chunks.py)."""
    g = owner.plume.domain.flowgraph
    frames = g.frame_end - g.frame_start + 1
    return Task("synthesis", run + ["synthesize_chunk", owner.name, str(farm.chunk), "{index}"],
                count=max(1, math.ceil(frames / farm.chunk)), after=["graph"], cpus=farm.cpus,
                label=f"Synthesize Fire frames {g.frame_start}-{g.frame_end}, {farm.chunk} a task")


def plan(context):
    """The FarmJob of Scene › Plume Farm; FarmError (the artist's words) on anything that
    would fail on the farm."""
    scene, farm = context.scene, context.scene.plume_farm
    slurm.find_slurm()
    root = farm_folder(farm)
    unseen = unseen_paths(farm, root)
    if unseen:
        what, path = unseen[0]
        raise FarmError(f"Plume farm: {what} is {path}, which the farm cannot see: make it "
                        "relative to the .blend (//…) or put it on the shared storage under "
                        f"{PANEL} › Path Here ({len(unseen)} such path(s))")
    run = blender_command(farm)
    cpus, wedge = farm.cpus, {}
    if farm.job == 'FLOWGRAPH':
        owner = farm.flowgraph_domain
        if owner is None:
            raise FarmError(f"Plume farm: choose the domain of the flow graph in {PANEL} › "
                            "Graph Domain")
        states = _domains_with_pathlines()
        if owner not in states:
            raise FarmError(f"Plume farm: domain '{owner.name}' does not record pathlines: tick "
                            "Physics › Plume › Flow-Graph Fire › Record Pathlines on it and on "
                            "each state")
        check_time_limit(farm, states)
        for dom in states:
            check_bakes(context, dom)
        names = [o.name for o in states]
        tasks = [Task("states", run + ["bake_one", "{index}", *names], count=len(names),
                      cpus=cpus, label=f"bake the {len(names)} states"),
                 Task("graph", run + ["flowgraph", owner.name, *names], after=["states"],
                      cpus=cpus, label="Build Flow Graph"),
                 _synthesis_task(owner, farm, run),
                 Task("fire", run + ["synthesize_gather", owner.name], after=["synthesis"],
                      label="the synthesized fire's Volume")]
        tasks.append(_render_task(scene, farm, run, ["fire"]))
    elif farm.job == 'WEDGE':
        dom = farm.wedge_domain
        if dom is None:
            raise FarmError(f"Plume farm: choose the domain to vary in {PANEL} › Domain")
        check_time_limit(farm, [dom])
        settings = parse_wedge(farm.wedge_settings, dom)
        check_bakes(context, dom, settings)
        count = len(next(iter(settings.values())))
        wedge = {"settings": settings, "count": count, "frame": int(farm.wedge_frame),
                 "domain": dom.name}
        tasks = [Task("variants", run + ["wedge", dom.name, "{index}"], count=count, cpus=cpus,
                      label=f"bake and render {count} variants of '{dom.name}'"),
                 Task("contact_sheet", run + ["contact_sheet"], after=["variants"],
                      label="contact sheet")]
    elif farm.job == 'FLAMES':
        tasks = [Task("flames", run + ["flames"], cpus=cpus, label="Bake Flames")]
        tasks.append(_render_task(scene, farm, run, ["flames"]))
    else:
        tasks = [_render_task(scene, farm, run, [])]
    stem = bpy.path.display_name_from_filepath(bpy.data.filepath) or "untitled"
    folder = _new_job_folder(root, f"{bpy.path.clean_name(stem)}_{farm.job.lower()}")
    return FarmJob(folder, to_farm(folder, farm), FarmGraph(tasks).validate(), wedge)


def _new_job_folder(root, name):
    n = 1
    while os.path.exists(os.path.join(root, f"{name}_{n:03d}")):
        n += 1
    return os.path.join(root, f"{name}_{n:03d}")


def write(job, scene):
    """The job's folder: the shot's copy and wedge.json. The copy's Blender paths are remapped
    to stay valid from the folder; Plume's cache folders stay "//" (inside the job's folder),
    except for a Render job, which renders the caches as they are: they are written into the
    copy as the farm sees them."""
    os.makedirs(job.folder, exist_ok=True)
    farm, kept = scene.plume_farm, []
    if farm.job == 'RENDER':
        for ob in bpy.data.objects:
            p = getattr(ob, "plume", None)
            if p is not None and p.role == 'DOMAIN':
                kept.append((p.domain, p.domain.cache_directory))
                p.domain.cache_directory = to_farm(
                    _dir(absolute_folder(p.domain.cache_directory or "//plume_cache/")), farm)
        fl = scene.plume_flames
        kept.append((fl, fl.cache_directory))
        fl.cache_directory = to_farm(_dir(absolute_folder(fl.cache_directory
                                                          or "//plume_cache/flames/")), farm)
    try:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(job.folder, SHOT), copy=True,
                                    relative_remap=True)
    finally:
        for owner, value in kept:
            owner.cache_directory = value
    if job.wedge:
        with open(os.path.join(job.folder, "wedge.json"), "w", encoding="utf-8") as f:
            json.dump(job.wedge, f, indent=1)
