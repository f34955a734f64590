"""Scene -> toon.ToonSettings ([Cartoon Smoke] §2): a domain's toon settings."""

import bpy

from .. import toon


def toon_settings(d):
    """toon.ToonSettings of a domain's obj.plume.domain.toon (image path made absolute)."""
    t = d.toon
    s = toon.ToonSettings()
    for name in toon.PARAM_FIELDS + ('depth_threshold', 'stencil', 'ignore_background'):
        if name != 'threads':
            setattr(s, name, type(getattr(s, name))(getattr(t, name)))
    s.threads = int(d.threads)  # the domain's worker threads (results do not depend on it)
    s.stencil_image = bpy.path.abspath(t.stencil_image) if t.stencil_image else ""
    return s
