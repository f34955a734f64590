"""Plume: small-scale smoke and fire for Blender, backed by the native module ``_native``.

Installed as the package ``plume`` with one native module per CPython beside this file
(``_native.cpython-311-x86_64-linux-gnu.so`` for Blender 3.4-5.0, ``…-313-…`` for 5.1+): Python
picks the one built for itself by its file name, and ``native.py`` explains a Python with none.
Only relative imports, so it also loads as a Blender 4.2+ extension (``bl_ext.*.plume``).
Importing the package needs no ``bpy``: the job command (``python -m plume.job``, jobs/child.py)
imports it in a plain Python; Blender's parts load in register() (registration.py)."""

bl_info = {
    "name": "Plume",
    "author": "Plume developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Physics",
    "description": "Smoke and fire simulation with streak surfaces, toon smoke, graph fire "
                   "and structural flames",
    "category": "Physics",
    # No doc_url: the manual ships inside the add-on (manual/), so its address depends on where
    # Blender installed it; Edit › Preferences › Add-ons › Plume lists its pages instead.
}



def register():
    from . import registration  # bpy, the native module (a clear message when it fails)
    registration.register()


def unregister():
    from . import registration
    registration.unregister()
