"""Writes docs/settings.md from the table in drt_addon/export/file_settings.py.

    .venv/bin/python docs/make_settings_docs.py

tests/test_file_settings.py checks that docs/settings.md is what this script writes.
"""
from __future__ import annotations

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "settings.md")

SECTIONS = [
    ("read", "Read from the file",
     "DRT renders with the file's value, as Cycles does."),
    ("own", "Replaced by DRT's own settings",
     "DRT's Render Properties have a setting of their own for these (stored in "
     "`scene.drt`). A warning names the file's Cycles value when it is not Blender's "
     "default and differs from DRT's."),
    ("blender", "Applied by Blender",
     "Blender applies these to DRT's result (or to the objects DRT exports) exactly as to "
     "Cycles'. For example the view transform's Exposure (`scene.view_settings.exposure`) "
     "brightens DRT's image by 2^exposure in the viewer and in 8- and 16-bit files, and "
     "leaves the scene-linear EXR alone, as for Cycles (tests/test_file_settings.py)."),
    ("ignored", "Ignored, with a warning",
     "DRT does not honour these. When the file sets one to anything but the value in "
     "*quiet at*, and it matters (*only when*), the render warns once, naming the setting "
     "and what DRT does instead; the passes DRT does not write are named in one warning. "
     "*Quiet at* is Blender's default except for Denoise and Noise Threshold (adaptive "
     "sampling): Blender turns both on by default and DRT does neither, so a new file "
     "warns about both until they are turned off. Rows marked *with ...* are part of "
     "another row's warning."),
    ("no effect", "No effect on the final image",
     "Speed, memory, the Rendered viewport (its own samples and denoiser) or baking; "
     "never warned."),
]


def _quiet(setting, show) -> str:
    quiet = setting.quiet if isinstance(setting.quiet, tuple) else (setting.quiet,)
    return " or ".join("none" if q is None else show(q) for q in quiet)


def _when(setting, show) -> str:
    if setting.when is None:
        return ""
    path, values = setting.when
    return f"`{path}` is {' or '.join(show(v) for v in values)}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def render_markdown() -> str:
    if ROOT not in sys.path:
        sys.path.insert(0, ROOT)
    from drt_addon.export.file_settings import SETTINGS
    from drt_addon.export.settings_check import show

    lines = ["# The file's render settings", "",
             "Which of a .blend's render settings (Cycles' `scene.cycles`, Blender's "
             "`scene.render`, the view layer's) DRT reads, which it replaces by its own, "
             "which Blender applies for it and which it ignores. Written by "
             "`docs/make_settings_docs.py` from the table in "
             "`drt_addon/export/file_settings.py`, the same table the warnings come from. "
             "Paths start at the scene (`scene.`) or at the view layer being rendered "
             "(`view_layer.`); labels are Cycles' Render Properties panels.", ""]
    for kind, title, intro in SECTIONS:
        rows = [s for s in SETTINGS if s.kind == kind]
        lines += [f"## {title}", "", intro, ""]
        if kind == "ignored":
            lines += ["| setting | path | quiet at | only when | what DRT does |",
                      "|---|---|---|---|---|"]
            for s in rows:
                quiet = _quiet(s, show) if s.warns else "with another row"
                lines.append(f"| {_cell(s.label)} | `{s.path}` | {quiet} | "
                             f"{_when(s, show)} | {_cell(s.how)} |")
        elif kind == "own":
            lines += ["| setting | path | DRT's setting | Blender's default | what DRT does |",
                      "|---|---|---|---|---|"]
            for s in rows:
                lines.append(f"| {_cell(s.label)} | `{s.path}` | `{s.drt}` | "
                             f"{show(s.quiet)} | {_cell(s.how)} |")
        else:
            lines += ["| setting | path | what DRT does |", "|---|---|---|"]
            for s in rows:
                lines.append(f"| {_cell(s.label)} | `{s.path}` | {_cell(s.how)} |")
        lines.append("")
    return "\n".join(lines)


def main():
    text = render_markdown()
    with open(OUT, "w") as f:
        f.write(text)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
