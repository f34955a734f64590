"""What Blender shows an artist about Plume's settings and buttons: every tooltip (property,
enum item, operator, panel) is written in artist words — none empty, none citing a file. Where
help opens is test_help.py's.

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

# A file name in a tooltip: "[Smoke Surfaces]", "notes.md", ...
FILE_NAME = re.compile(r"\b[\w-]+\.(txt|md|pdf|py|json|toml)\b")


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
