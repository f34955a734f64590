"""The manuals' panel pictures (`ui_*.png`) cannot fall behind the UI: this runs the one command
that remakes them all (`bash .ci/screenshots OUT`: every recipe's steps in a real Blender 3.4.1
window under Xvfb, examples/ui_screenshots.py) and checks that
- it makes every ui_*.png a manual or the README shows, and nothing else;
- each is a drawn editor (panels, text), never a blank or black frame;
- each equals the picture in the repository (the UI or a recipe changed? run the command and
  commit its pictures);
- each caption says which Blender drew it.

Run (needs xvfb-run and the add-on installed where Blender finds user add-ons):
    python3 blender_tests/run.py --blender 3.4 test_ui_screenshots.py
"""

import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402

from helpers import image_pixels, run  # noqa: E402

#: A picture "equals" the repository's when under 1 % of its pixels differ by more than 0.1 in
#: a channel. Measured between two runs: 0 pixels; a setting renamed or moved changes a row of
#: text (1-3 % of an editor).
CHANGED_MAX = 0.01
#: A drawn editor: light text on grey panels. Share of bright (> 0.6) pixels, measured 0.9-4 %
#: on the Properties editor; a blank or black frame has none.
TEXT_MIN = 0.003
_PICTURE = re.compile(r"!\[[^\]]*\]\(((?:[\w./-]*/)?images/(ui_[\w-]+\.png))\)")


def shown_pictures():
    """{(pipeline folder, file name): (manual, the caption after it)} of every ui_*.png shown."""
    shown = {}
    for manual in [os.path.join(REPO, "README.md"),
                   *glob.glob(os.path.join(REPO, "examples", "*", "README.md"))]:
        with open(manual, encoding="utf-8") as f:
            text = f.read()
        for m in _PICTURE.finditer(text):
            path = os.path.normpath(os.path.join(os.path.dirname(manual), m.group(1)))
            folder = os.path.basename(os.path.dirname(os.path.dirname(path)))
            caption = text[m.end():m.end() + 400].strip().split("\n\n")[0]
            shown[(folder, m.group(2))] = (os.path.relpath(manual, REPO), caption)
    return shown


class ScreenshotsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        if shutil.which("xvfb-run") is None:
            raise RuntimeError("xvfb-run is missing: install the 'xvfb' package (.ci/common.sh)")
        cls.out = tempfile.mkdtemp(prefix="plume_ui_screenshots_")
        proc = subprocess.run(["bash", os.path.join(REPO, ".ci", "screenshots"), cls.out],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=900)
        cls.rc, cls.log = proc.returncode, proc.stdout
        print("\n".join("  " + line for line in cls.log.splitlines()
                        if line.startswith("ui_screenshots")), flush=True)
        cls.made = {(os.path.basename(os.path.dirname(os.path.dirname(p))), os.path.basename(p)): p
                    for p in glob.glob(os.path.join(cls.out, "*", "images", "ui_*.png"))}
        cls.shown = shown_pictures()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_command_makes_every_picture_shown(self):
        self.assertEqual(self.rc, 0, self.log[-3000:])
        print(f"  {len(self.made)} pictures made, {len(self.shown)} shown in the manuals")
        self.assertGreaterEqual(len(self.shown), 5)  # candle, sheets (3), toon puff at least
        self.assertEqual(sorted(set(self.shown) - set(self.made)), [], "shown, not made")
        self.assertEqual(sorted(set(self.made) - set(self.shown)), [], "made, shown nowhere")

    def test_pictures_are_drawn_editors(self):
        for key, path in sorted(self.made.items()):
            px = image_pixels(path)[..., :3]
            bright = float((px.max(axis=2) > 0.6).mean())
            print(f"  {key[0]}/{key[1]}: {px.shape[1]} x {px.shape[0]}, text {bright:.2%}")
            self.assertGreater(bright, TEXT_MIN, key)
            self.assertGreater(float(px.std()), 0.05, key)

    def test_pictures_equal_the_repository_ones(self):
        stale = []
        for key, path in sorted(self.made.items()):
            kept = os.path.join(REPO, "examples", key[0], "images", key[1])
            if not os.path.isfile(kept):
                stale.append(f"{key[1]} (missing)")
                continue
            a, b = image_pixels(path)[..., :3], image_pixels(kept)[..., :3]
            if a.shape != b.shape:
                stale.append(f"{key[1]} ({b.shape[1]} x {b.shape[0]} kept, "
                             f"{a.shape[1]} x {a.shape[0]} made)")
                continue
            changed = float((np.abs(a - b).max(axis=2) > 0.1).mean())
            print(f"  {key[1]}: {changed:.2%} of the pixels changed")
            if changed > CHANGED_MAX:
                stale.append(f"{key[1]} ({changed:.1%} changed)")
        self.assertEqual(stale, [], "run `bash .ci/screenshots` and commit its pictures")

    def test_captions_name_the_blender(self):
        for key, (manual, caption) in sorted(self.shown.items()):
            self.assertIn("Blender 3.4.1", caption, f"{manual}: {key[1]}")


if __name__ == "__main__":
    run(ScreenshotsTest)
