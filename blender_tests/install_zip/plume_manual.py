#!/usr/bin/env python3
"""The manual that ships inside the add-on: the README and the five pipeline manuals as HTML
pages in `plume/manual/`, so that Plume's help (right click › Online Manual, the Help buttons,
Preferences › Add-ons › Plume › Manual) opens offline, on a workstation or a farm node without
internet, and matches the installed version.

    plume_manual.py REPO_ROOT OUT_DIR      # writes OUT_DIR/index.html, smoke.html, ... images/

Markdown by Python-Markdown (Debian's python3-markdown; tables, fenced code, heading ids).
Links between the manuals become links between the pages; links to other files of the
repository (example scripts, tests) stay as their names in code type, since the add-on does not
carry them. Every heading and every paragraph that opens with a bold lead ("**Recipe: a
torch**") gets an id, so help can open a section. Pictures are copied resized to at most
MAX_WIDTH pixels wide, JPEG unless they have transparency, and the page fails to build if one is
missing. Standard library, markdown and Pillow (Debian's python3-pil); runs under
/usr/bin/python3.
"""

import html
import os
import posixpath
import re
import shutil
import sys

import markdown

#: (source in the repository, page in the manual folder), the README first.
PAGES = (
    ("README.md", "index.html"),
    ("examples/smoke/README.md", "smoke.html"),
    ("examples/streak_surfaces/README.md", "streak_surfaces.html"),
    ("examples/toon/README.md", "toon.html"),
    ("examples/flowgraph_fire/README.md", "flowgraph_fire.html"),
    ("examples/flames/README.md", "flames.html"),
)
MAX_WIDTH = 1280
JPEG_QUALITY = 88

_LINK = re.compile(r'(<(?:a|img)\b[^>]*?\b(?:href|src)=")([^"]+)(")')
_BOLD_LEAD = re.compile(r"<p><strong>(.+?)</strong>")
_HEADING_ID = re.compile(r'<h[1-6] id="([^"]+)"')
_TAG = re.compile(r"<[^>]+>")

STYLE = """
body { font: 16px/1.55 system-ui, sans-serif; max-width: 58rem; margin: 2rem auto;
       padding: 0 1.2rem; color: #1d1d1f; background: #fafafa; }
img { max-width: 100%; height: auto; }
code, pre { font: 14px/1.45 ui-monospace, monospace; background: #eee; }
pre { padding: .7rem; overflow-x: auto; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: .2rem .5rem; }
nav { font-size: 14px; border-bottom: 1px solid #ccc; padding-bottom: .5rem; }
:target { background: #fff3c4; }
"""


class ManualError(Exception):
    pass


def slug(text):
    """The id of a section title, as Python-Markdown's toc extension makes it."""
    from markdown.extensions.toc import slugify
    return slugify(html.unescape(_TAG.sub("", text)), "-")


def _bold_lead_ids(body, taken):
    """Gives each paragraph that opens with a bold lead an id of its words (the manuals' minor
    sections), unless a heading has it already."""
    def add(m):
        ident = slug(m.group(1).rstrip(":. "))
        if not ident or ident in taken:
            return m.group(0)
        taken.add(ident)
        return f'<p id="{ident}"><strong>{m.group(1)}</strong>'
    return _BOLD_LEAD.sub(add, body)


def _picture(src_path, out_dir, rel_name):
    """Copies one picture, resized, into out_dir/images/; returns its path in the manual."""
    from PIL import Image
    if not os.path.isfile(src_path):
        raise ManualError(f"{src_path}: a manual shows this picture, and it is missing")
    stem = os.path.splitext(rel_name.replace("examples/", "").replace("/images/", "_")
                            .replace("/", "_"))[0]
    with Image.open(src_path) as im:
        alpha = im.mode in ("RGBA", "LA") or "transparency" in im.info
        if alpha and im.getchannel("A").getextrema()[0] == 255:
            alpha = False
        im = im.convert("RGBA" if alpha else "RGB")
        if im.width > MAX_WIDTH:
            im = im.resize((MAX_WIDTH, round(im.height * MAX_WIDTH / im.width)), Image.LANCZOS)
        name = f"images/{stem}.{'png' if alpha else 'jpg'}"
        os.makedirs(os.path.join(out_dir, "images"), exist_ok=True)
        if alpha:
            im.save(os.path.join(out_dir, name), optimize=True)
        else:
            im.save(os.path.join(out_dir, name), quality=JPEG_QUALITY, optimize=True)
    return name


def _rewrite_links(body, source, repo, out_dir):
    """Links between manuals → pages; pictures → copied; other repository files → their names."""
    pages = {src: page for src, page in PAGES}
    src_dir = posixpath.dirname(source)

    def fix(m):
        target = html.unescape(m.group(2))
        if re.match(r"^[a-z]+:", target) or target.startswith("#"):
            return m.group(0)  # a web address or a section of this page
        path, _, anchor = target.partition("#")
        rel = posixpath.normpath(posixpath.join(src_dir, path))
        if m.group(1).startswith("<img"):
            return m.group(1) + _picture(os.path.join(repo, rel), out_dir, rel) + m.group(3)
        if rel in pages:
            return m.group(1) + pages[rel] + (f"#{anchor}" if anchor else "") + m.group(3)
        return m.group(0).replace(m.group(1), m.group(1).replace("href=", "data-file="))
    body = _LINK.sub(fix, body)
    # <a data-file="…">text</a>: a file the add-on does not carry; its name stays, as code.
    return re.sub(r'<a\b[^>]*\bdata-file="([^"]+)"[^>]*>(.*?)</a>',
                  lambda m: m.group(2) if "<code>" in m.group(2) else f"<code>{m.group(2)}</code>",
                  body, flags=re.S)


def build(repo, out_dir):
    """Writes the manual into out_dir (emptied first). Returns {page: [section ids]}."""
    if os.path.exists(out_dir):
        shutil.rmtree(out_dir)
    os.makedirs(out_dir)
    sections = {}
    nav = " · ".join(f'<a href="{page}">{title}</a>' for page, title in (
        ("index.html", "Plume"), ("smoke.html", "Smoke and fire"),
        ("streak_surfaces.html", "Streak surfaces"), ("toon.html", "Toon smoke"),
        ("flowgraph_fire.html", "Flow-graph fire"), ("flames.html", "Structural flames")))
    for source, page in PAGES:
        with open(os.path.join(repo, source), encoding="utf-8") as f:
            text = f.read()
        md = markdown.Markdown(extensions=["tables", "fenced_code", "toc", "sane_lists"])
        body = md.convert(text)
        taken = set(_HEADING_ID.findall(body))
        body = _bold_lead_ids(body, taken)
        body = _rewrite_links(body, source, repo, out_dir)
        title = text.splitlines()[0].lstrip("# ").strip()
        doc = (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
               f"<title>{html.escape(title)} — Plume manual</title><style>{STYLE}</style>"
               f"</head><body><nav>{nav}</nav>\n{body}\n</body></html>\n")
        with open(os.path.join(out_dir, page), "w", encoding="utf-8") as f:
            f.write(doc)
        sections[page] = sorted(taken)
    return sections


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    try:
        sections = build(argv[0], argv[1])
    except ManualError as e:
        print(f"plume_manual: {e}", file=sys.stderr)
        return 1
    size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(argv[1]) for f in fs)
    print(f"  manual: {len(sections)} pages, {sum(map(len, sections.values()))} sections, "
          f"{size / 1e6:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
