"""One farm task inside Blender on a node (the one module of plume.farm that imports ``bpy``: it
is the script a task runs, `blender -b --python node_task.py -- <shot.blend> <step> [args]`, or
under a `bpy` wheel `python node_task.py <shot.blend> <step> [args]`). It opens the farm's copy
of the shot, enables Plume and performs one step through the same operators an artist clicks,
so a farm's result is a local run's: every path it writes is inside the farm folder (the
current directory, the copy's `//`).

Steps (made by plan.py):
    bake_one <index> <domain> [<domain> …] the bake of the index-th domain (a requeued task
                                           resumes it from its last complete frame)
    flames                                 Bake Flames (every Flame Source), the shot saved
    flowgraph <owner> <state> [<state> …]  Build Flow Graph of the states into the owner
    synthesize <owner>                     Synthesize Fire on the owner's graph, the shot saved
                                           (the render tasks open it with its fire Volume)
    synthesize_chunk <owner> <size> <index>
                                           frames of chunk <index> of that synthesis, into their
                                           chunk folder (flowgraph_chunks.py)
    synthesize_gather <owner>              the chunks' frames committed as one Synthesize Fire
                                           (its fire Volume), the shot saved
    wedge <domain> <index>                 variant <index> of wedge.json: bake, render a still
    contact_sheet                          the wedge's stills side by side (wedge/contact_sheet.png)
    render <chunk size> <index>            frames of chunk <index> into render/####.png
Exit status 0 when the step finished, 1 otherwise (the operator's report is printed)."""

import json
import os
import sys

import bpy

WEDGE_NAME = "wedge.json"


def _args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    return argv[0], argv[1], argv[2:]


def _enable():
    """Plume enabled: already, by the node's preferences, or as the package this file is in
    ("plume", or "bl_ext.<repository>.plume" as an extension)."""
    if hasattr(bpy.types.Scene, "plume_farm"):
        return
    import addon_utils
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    name = os.path.basename(package)
    parent = os.path.dirname(package)
    if os.path.basename(os.path.dirname(parent)) == "extensions":
        name = f"bl_ext.{os.path.basename(parent)}.{name}"
    if addon_utils.enable(name, default_set=False) is None:
        raise SystemExit(f"plume farm: the Plume add-on ({name}) could not be enabled on this "
                         "node: install it in the node's Blender")


def _press(op, **props):
    result = op(**props)
    if result != {'FINISHED'}:
        raise SystemExit(f"plume farm: {op.idname_py()} ended {result}")


def _select(*names):
    """Selects the named objects, the first one active (as an artist's clicks would)."""
    layer = bpy.context.view_layer
    for ob in layer.objects:
        ob.select_set(ob.name in names)
    missing = [n for n in names if n not in bpy.data.objects]
    if missing:
        raise SystemExit(f"plume farm: the shot has no object {missing}")
    layer.objects.active = bpy.data.objects[names[0]]


def bake(domain):
    _select(domain)
    _press(bpy.ops.plume.bake)


def wedge(domain, index):
    """Variant `index`: the wedge's values set on the domain, its own cache folder, bake, a
    still of the wedge's frame into wedge/<index>.png."""
    with open(WEDGE_NAME, encoding="utf-8") as f:
        plan = json.load(f)
    d = bpy.data.objects[domain].plume.domain
    for name, values in plan["settings"].items():
        setattr(d, name, values[int(index)])
    d.cache_directory = f"//plume_cache/{domain}_wedge_{int(index)}/"
    bake(domain)
    scene = bpy.context.scene
    scene.frame_set(int(plan["frame"]))
    scene.render.filepath = os.path.abspath(os.path.join("wedge", f"{int(index)}.png"))
    scene.render.image_settings.file_format = 'PNG'
    _press(bpy.ops.render.render, write_still=True)


def contact_sheet():
    """The wedge's stills in one row per `columns`, in index order (wedge/contact_sheet.png)."""
    import numpy as np
    with open(WEDGE_NAME, encoding="utf-8") as f:
        plan = json.load(f)
    images = []
    for i in range(int(plan["count"])):
        img = bpy.data.images.load(os.path.abspath(os.path.join("wedge", f"{i}.png")))
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        images.append(px.reshape(h, w, 4))
        bpy.data.images.remove(img)
    h, w = images[0].shape[:2]
    cols = min(len(images), int(plan.get("columns", 4)))
    rows = (len(images) + cols - 1) // cols
    sheet = np.zeros((rows * h, cols * w, 4), np.float32)
    sheet[..., 3] = 1.0
    for i, px in enumerate(images):
        r, c = rows - 1 - i // cols, i % cols  # Blender's rows start at the bottom
        sheet[r * h:(r + 1) * h, c * w:(c + 1) * w] = px[:h, :w]
    out = bpy.data.images.new("contact_sheet", cols * w, rows * h, alpha=True)
    out.pixels.foreach_set(sheet.ravel())
    out.filepath_raw = os.path.abspath(os.path.join("wedge", "contact_sheet.png"))
    out.file_format = 'PNG'
    out.save()


def synthesize_chunk(owner, size, index):
    """Frames start + index·size … of the owner's synthesis range (Synthesize Fire refuses a
    chunk outside it)."""
    _select(owner)
    g = bpy.data.objects[owner].plume.domain.flowgraph
    first = int(g.frame_start) + int(index) * int(size)
    _press(bpy.ops.plume.fire_synthesize,
           farm_chunk=(first, min(int(g.frame_end), first + int(size) - 1)))


def render(chunk, index):
    scene = bpy.context.scene
    first = scene.frame_start + int(index) * int(chunk)
    last = min(scene.frame_end, first + int(chunk) - 1)
    scene.frame_start, scene.frame_end = first, last
    scene.render.filepath = os.path.abspath(os.path.join("render", "")) + os.sep
    _press(bpy.ops.render.render, animation=True)


def main():
    blend, step, args = _args()
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(blend))
    _enable()
    if step == "bake_one":
        bake(args[1 + int(args[0])])
    elif step == "flames":
        _press(bpy.ops.plume.flames_bake)
        bpy.ops.wm.save_mainfile()
    elif step == "flowgraph":
        _select(*args)
        _press(bpy.ops.plume.flowgraph_build)
    elif step == "synthesize":
        _select(*args)
        _press(bpy.ops.plume.fire_synthesize)
        bpy.ops.wm.save_mainfile()
    elif step == "synthesize_chunk":
        synthesize_chunk(*args)
    elif step == "synthesize_gather":
        _select(*args)
        _press(bpy.ops.plume.fire_synthesize, farm_gather=True)
        bpy.ops.wm.save_mainfile()
    elif step == "wedge":
        wedge(*args)
    elif step == "contact_sheet":
        contact_sheet()
    elif step == "render":
        render(*args)
    else:
        raise SystemExit(f"plume farm: unknown step '{step}'")
    print(f"plume farm: {step} {' '.join(args)}: done", flush=True)


if __name__ == "__main__":
    main()
