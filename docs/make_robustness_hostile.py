"""Writes docs/robustness_hostile.md: the catalogue of hostile and broken input, with the
messages DRT really gives (tests/hostile_cases.py builds and renders every case).

    .venv/bin/python docs/make_robustness_hostile.py

tests/test_hostile_input.py checks that the page holds the table this script writes.
"""
from __future__ import annotations

import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "robustness_hostile.md")
for p in (ROOT, os.path.join(ROOT, "tests")):
    if p not in sys.path:
        sys.path.insert(0, p)

HEAD = """# Hostile and broken input

What DRT does with files and scenes that are broken or odd. Each row is one case of
`tests/hostile_cases.py`, made as a small .blend and tried the two ways a user meets it:
opened and rendered in Blender (the message is Blender's own when the file cannot be
opened or has no camera, else the DRT render's report, shown in Blender's status bar
and Info editor), and rendered by the batch renderer
(`python -m drt_addon render FILE.blend -o out.png`, see [batch.md](batch.md)).
The messages below are the real ones, written by `docs/make_robustness_hostile.py`;
`tests/test_hostile_input.py` checks that they are still what DRT says.

Each case gets one message, never a traceback, a crash or a hang; an image that comes out
black says why. The batch renderer's exit codes: 0 rendered (warnings, if any, on stderr
as `drt: warning:` lines), 2 bad arguments, 3 the file is missing or not a readable
.blend, 4 the render failed, 5 the Dask cluster could not be reached.

"""

MEMORY = """
## Memory

DRT renders in work units of at most `chunk_paths` paths (32768 by default) over passes
of 1, 2, 4 ... samples, so memory follows the image size and the chunk, never samples x
pixels: any Samples value DRT's property allows (up to 16777216) is accepted and rendered
progressively, and Esc stops it within a work unit. The film keeps 96 bytes per pixel
(sums, squared sums, counts and alpha for the running mean and its noise estimate);
Blender's render result and the image handed to it add about 48 bytes per pixel in an
F12 render. Peak memory measured by `docs/make_robustness_hostile.py` (tracemalloc, one
thread, the Cornell box; bound: 104 bytes per pixel + 1 KB per path of a work unit + 2 MB,
which `tests/test_memory.py` asserts):

"""

TAIL = """
By the same per-pixel sizes, a 7680 x 4320 frame needs about 3.2 GB of film and 1.6 GB
more inside Blender, whatever the sample count.

## Notes

- A node loop: Blender marks one link of every loop of nodes invalid (drawn red in the
  node editor); Cycles ignores those links and so does DRT, which reads the rest of the
  tree. A tree that would take more than 2048 node reads to walk (for example a long chain
  of Mix Shaders each feeding both inputs of the next) is cut off there, with a warning,
  instead of taking exponential time.
- A missing linked library: Blender opens the file with empty placeholders where the
  linked data was; the render goes on without it (as Cycles), and the warning names the
  library and what it should have brought. The exit code is 0: check stderr for
  `drt: warning: linked library` in render-farm jobs that must not miss assets.
- Rendering never changes the user's data: the .blend on disk, the scene's current frame
  and its render, DRT and Cycles settings, and the objects (names, transforms, mesh
  vertices, materials) are the same after a render, a cancelled render and a failed one
  (`tests/test_render_side_effects.py`).
- Cancel (Esc) is looked at before each object of the export, before and after the
  acceleration structure is built, between work units of the tracing and before the
  extra passes; after it Blender renders again normally. Twenty renders in one session
  do not grow its memory: the test bounds the growth over the last fifteen by three
  times the size of the exported scene (`tests/test_render_side_effects.py`).
"""


def main() -> None:
    import bpy

    import drt_addon
    from hostile_cases import markdown_table, run_cases
    from memory_probe import memory_table
    drt_addon.register()
    with tempfile.TemporaryDirectory() as folder:
        outcomes = run_cases(bpy, folder)
    memory = memory_table()
    with open(OUT, "w") as f:
        f.write(HEAD + markdown_table(outcomes) + MEMORY + memory + TAIL)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
