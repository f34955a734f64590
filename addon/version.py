"""The add-on's version as "x.y.z" (recorded in every cache manifest). bl_info in the package's
__init__.py is the one place it is written; it is read here the way Blender reads it (the literal,
without importing the package), so no module imports the package's __init__."""

import ast
import os


def _bl_info_version():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "__init__.py")
    with open(path, "r", encoding="utf-8") as f:
        tree = ast.parse(f.read())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "bl_info"
                                                for t in node.targets):
            return ast.literal_eval(node.value)["version"]
    raise ImportError("Plume: no bl_info in __init__.py", name=__package__)


#: "0.1.0": kept apart from bl_info, which Blender 4.2+ deletes from an extension's module.
VERSION = ".".join(str(v) for v in _bl_info_version())
