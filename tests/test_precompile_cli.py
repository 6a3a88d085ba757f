"""`python -m drt_addon compile`: the README's set-up step that compiles and caches the
kernels before a first render (drt_addon/precompile.py). Run in subprocesses on the
suite's own kernel cache: the first run compiles what is missing, the second nothing."""
from __future__ import annotations

import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "sample_blends", "cornell_box.blend")


def drt(*args):
    return subprocess.run([sys.executable, "-m", "drt_addon", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=1200)


def test_compile_caches_the_kernels_a_render_needs():
    runs = [drt("compile", SCENE, "--no-progress") for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr[-2000:]
        assert re.search(r"^drt: cornell_box\.blend: \d+ kernels compiled, [0-9.]+ s$",
                         r.stdout, re.M), r.stdout
        assert "kernels compiled and cached" in r.stdout
    assert "cornell_box.blend: 0 kernels compiled" in runs[1].stdout   # all from the cache


def test_compile_shares_scenes_out_among_processes():
    """`--jobs 2`: each scene compiled by one of two processes, every scene's line
    passed on, the total line naming the processes; run again, nothing is compiled."""
    torus = os.path.join(ROOT, "sample_blends", "motion_torus.blend")
    runs = [drt("compile", "--jobs", "2", SCENE, torus, "--no-progress") for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr[-2000:]
        for name in ("cornell_box", "motion_torus"):
            assert re.search(rf"^drt: {name}\.blend: \d+ kernels compiled, [0-9.]+ s$",
                             r.stdout, re.M), r.stdout
        assert re.search(r"^drt: kernels compiled and cached in \d+ s \(2 processes\)$",
                         r.stdout, re.M), r.stdout
    assert runs[1].stdout.count(" 0 kernels compiled") == 2


def test_compile_refuses_what_is_not_a_scene(tmp_path):
    missing = drt("compile", str(tmp_path / "nope.blend"))
    assert missing.returncode == 3 and "file not found" in missing.stderr
    text = tmp_path / "notes.blend"
    text.write_text("not a blend file")
    bad = drt("compile", str(text))
    assert bad.returncode == 3 and "is not a .blend file" in bad.stderr
