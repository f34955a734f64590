"""What Blender shows an artist about Plume's settings and buttons: every tooltip (property,
enum item, operator, panel) is written in artist words — none empty, none citing a file, none
naming a setting by its Python name. Where help opens is test_help.py's.

Run: BLENDER_USER_SCRIPTS=... blender -b --factory-startup --python-exit-code 1 \
         --python blender_tests/test_tooltips.py
"""

import os
import re
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from helpers import enable_addon, run  # noqa: E402

# A file name in a tooltip: "paper.txt", "notes.md", "smoke_script.h", ...
FILE_NAME = re.compile(r"\b[\w-]+\.(txt|md|pdf|py|json|toml|h|cpp)\b")
SNAKE = re.compile(r"\b[a-z][a-z0-9]*(?:_[a-z0-9]+)+\b")
CAPS = re.compile(r"\b[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)*\b")
#: What an artist never types: Python paths of Blender data and Plume's operators.
API = re.compile(r"\b(bpy|scene|obj|context|ob|self)\.[a-z_]|\bplume\.[a-z_]+\(|\.plume\b")


def python_names():
    """(snake_case names, enum identifiers) an artist's text must not show: every Plume
    setting's and operator option's Python name, Mantaflow's (Blender's Fluid settings; the
    tooltips compare with them) and the render engines'; each enum item's identifier in capitals
    unless it is also its shown name ('BFECC')."""
    groups, operators, _panels = plume_classes()
    rnas = [cls.bl_rna for cls in groups]
    for cls in operators:
        module, name = cls.bl_idname.split(".")
        rnas.append(getattr(getattr(bpy.ops, module), name).get_rna_type())
    rnas += [bpy.types.FluidDomainSettings.bl_rna, bpy.types.FluidFlowSettings.bl_rna,
             bpy.types.FluidEffectorSettings.bl_rna, bpy.types.RenderSettings.bl_rna]
    snake, enums = set(), set()
    for rna in rnas:
        for prop in rna.properties:
            if "_" in prop.identifier:
                snake.add(prop.identifier)
            if prop.type == 'ENUM':
                enums |= {i.identifier for i in prop.enum_items if i.identifier != i.name}
    enums |= {"CYCLES", "BLENDER_EEVEE", "BLENDER_EEVEE_NEXT", "BLENDER_WORKBENCH"}
    snake |= {cls.bl_idname.split(".")[1] for cls in operators if "_" in cls.bl_idname}
    return snake, enums


def python_words(text, names):
    """The Python names, API paths and enum identifiers in an artist's text (names: from
    python_names())."""
    snake, enums = names
    found = [w for w in SNAKE.findall(text) if w in snake]
    found += [w for w in CAPS.findall(text) if w in enums]
    found += [m.group(0) for m in API.finditer(text)]
    return found


def plume_classes():
    """The registered classes of the add-on: property groups, operators and panels."""
    enable_addon()
    from plume import operators, properties, ui
    return properties.classes, operators.classes, ui.classes


def texts_of_rna(rna, where, with_struct=True):
    """(where, text) of an RNA struct's description (with_struct) and of each shown property's
    name, description and enum items' names and descriptions."""
    if with_struct:
        yield where, rna.description
    for prop in rna.properties:
        if prop.identifier == "rna_type" or prop.is_hidden:
            continue
        at = f"{where}.{prop.identifier}"
        yield at + " (name)", prop.name
        yield at, prop.description
        if prop.type == 'ENUM':
            for item in prop.enum_items:
                yield f"{at}['{item.identifier}'] (name)", item.name
                yield f"{at}['{item.identifier}']", item.description


class TooltipTest(unittest.TestCase):
    def setUp(self):
        self.groups, self.operators, self.panels = plume_classes()

    def all_texts(self):
        for cls in self.groups:  # a group's own description is never shown
            yield from texts_of_rna(cls.bl_rna, cls.__name__, with_struct=False)
        for cls in self.operators:  # the button's tooltip: bl_description, else the docstring
            module, name = cls.bl_idname.split(".")
            rna = getattr(getattr(bpy.ops, module), name).get_rna_type()
            yield from texts_of_rna(rna, cls.bl_idname)
        for cls in self.panels:
            yield f"{cls.__name__} (label)", cls.bl_label
            description = getattr(cls, "bl_description", None)
            if description is not None:
                yield cls.__name__, description

    def test_found_every_kind(self):
        self.assertGreaterEqual(len(self.groups), 7)
        self.assertGreaterEqual(len(self.operators), 15)
        self.assertGreaterEqual(len(self.panels), 10)
        self.assertIn("PlumeDomainSettings", [c.__name__ for c in self.groups])
        self.assertTrue(all(c.__name__.startswith("PLUME_OT_") for c in self.operators))

    def test_no_tooltip_cites_a_file(self):
        bad = [f"{where}: {text!r}" for where, text in self.all_texts()
               if ".txt" in text or FILE_NAME.search(text)]
        self.assertEqual(bad, [], f"{len(bad)} tooltips cite a file:\n" + "\n".join(bad))

    def test_no_python_names(self):
        """No tooltip names a setting by its Python name (Plume's or Mantaflow's), an API path
        ("bpy.", "scene.") or an enum item by its identifier ('IMAGE'): an artist sees labels."""
        names = python_names()
        self.assertIn("depth_threshold", names[0])
        self.assertIn("use_adaptive_domain", names[0])  # Mantaflow's
        self.assertIn("BLENDER_EEVEE", names[1])
        bad = [f"{where}: {python_words(text, names)}: {text!r}"
               for where, text in self.all_texts() if python_words(text, names)]
        self.assertEqual(bad, [], f"{len(bad)} tooltips name Python:\n" + "\n".join(bad))

    def test_no_bare_section_sign(self):
        """A paper's section may stay in brackets after words, never as a tooltip's start."""
        bad = [f"{where}: {text!r}" for where, text in self.all_texts()
               if text.lstrip().startswith("§")]
        self.assertEqual(bad, [], "\n".join(bad))

    def test_no_tooltip_is_empty(self):
        """Every property, operator and panel says what it is (enum items may rely on their
        property's tooltip only when they have a name)."""
        groups = {cls.__name__ for cls in self.groups}  # nested groups are never drawn as one
        nested = {f"{cls.__name__}.{prop.identifier}" for cls in self.groups
                  for prop in cls.bl_rna.properties
                  if prop.type == 'POINTER' and prop.fixed_type.identifier in groups}
        bad = [where for where, text in self.all_texts()
               if not text.strip() and not where.endswith("]") and where not in nested]
        self.assertEqual(bad, [], "empty tooltips: " + ", ".join(bad))


if __name__ == "__main__":
    run(TooltipTest)
