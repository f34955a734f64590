"""What the panels show of each domain's cache, held in memory so that draw() never reads the
disk: the manifest of every domain's cache folder, read when a job ends (jobs.registry's `ended`
listeners), when a file loads (a persistent load_post handler), when Free Bake deletes the
files, and, for a domain the panels have not seen yet or whose cache folder changed, once from a
timer that draw() schedules (the read happens outside draw, then the panels redraw)."""

import bpy

from . import cache
from .jobs import registry
from .snapshot import cache_folder_of

#: domain name -> (cache folder, its manifest or None)
_state = {}
#: domain names a timer will read (draw() asked for them)
_pending = set()


def refresh(domain):
    """Reads the domain's manifest now (main thread, outside draw)."""
    folder = cache_folder_of(domain)
    _state[domain.name] = (folder, cache.read_manifest(folder))


def refresh_all():
    _state.clear()
    for ob in bpy.data.objects:
        if getattr(ob, "plume", None) is not None and ob.plume.role == 'DOMAIN':
            refresh(ob)


def manifest(domain):
    """The domain's manifest as last read, or None; schedules a read when it was never read for
    its current cache folder. No disk access."""
    entry = _state.get(domain.name)
    if entry is None or entry[0] != cache_folder_of(domain):
        _request(domain.name)
        return None
    return entry[1]


def cache_status(domain):
    """(frames done, frames total) of the domain's cache, from the manifest held in memory."""
    d = domain.plume.domain
    total = max(0, d.frame_end - d.frame_start + 1)
    m = manifest(domain)
    if m is None or m.get("frame_start") != d.frame_start:
        return 0, total
    done = min(m.get("last_complete_frame", 0), d.frame_end) - d.frame_start + 1
    return max(0, done), total


def _request(name):
    if bpy.app.background:
        return  # no window shows the panels (and a pending timer would outlive the bpy module)
    if name in _pending:
        return
    _pending.add(name)
    if not bpy.app.timers.is_registered(_read_pending):
        bpy.app.timers.register(_read_pending, first_interval=0.0)


def _read_pending():
    names = list(_pending)
    _pending.clear()
    for name in names:
        ob = bpy.data.objects.get(name)
        if ob is not None and ob.plume.role == 'DOMAIN':
            refresh(ob)
    _redraw()
    return None  # once


def _redraw():
    wm = bpy.context.window_manager
    for window in wm.windows if wm is not None else ():
        for area in window.screen.areas:
            area.tag_redraw()


def _job_ended(runner):
    """A job freed its keys: read the manifests of the domains it worked on."""
    for key in runner.keys:
        if len(key) == 2 and key[0] == "domain":
            try:
                ob = bpy.data.objects.get(key[1])
                if ob is not None and ob.plume.role == 'DOMAIN':
                    refresh(ob)
            except (AttributeError, ReferenceError):
                pass  # quitting: Blender's data is gone, and so are the panels


@bpy.app.handlers.persistent
def _load_post(*_args):
    _pending.clear()
    refresh_all()


def register():
    if _job_ended not in registry.ended:
        registry.ended.append(_job_ended)
    if _load_post not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_load_post)


def unregister():
    while _job_ended in registry.ended:
        registry.ended.remove(_job_ended)
    while _load_post in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_load_post)
    if bpy.app.timers.is_registered(_read_pending):
        bpy.app.timers.unregister(_read_pending)
    _state.clear()
    _pending.clear()
