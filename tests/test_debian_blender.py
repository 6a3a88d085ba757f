"""DRT in a real Blender binary: Debian's `blender` package (Blender 3.4, system Python
3.11), the one installable in CI (.ci/run installs it), with DRT as a legacy add-on.

The add-on is this checkout, linked as <BLENDER_USER_SCRIPTS>/addons/drt; the packages the
tracer needs besides NumPy (embreex, numba, llvmlite: the extension's bundled wheels) are
this test environment's own, linked into one folder on PYTHONPATH, and NumPy is Debian's
python3-numpy, exactly as docs/batch.md tells a render-farm worker to set it up. A first
Blender run enables the add-on in the preferences (BLENDER_USER_CONFIG) and builds the
scene (tests/legacy_blender_scene.py); then Blender renders it the ways docs/batch.md
shows: `-E DRT -o OUT -f 1`, `-a` over the scene's 2 frames, Flamenco's
`-y --render-output --render-format --render-frame 1..2` and Deadline's
`-t 1 -x 1 -o OUT -s 1 -e 1 -a`, the last two with the engine from the file.

Blender exits 0 even when a render engine raised (a blank image is saved), so every run is
checked in its log (no Traceback or Error line, `Sample i/N` progress lines, `Saved:`) and
in its pixels (black sky at the top, the lamp's light on the plane, the red cube).

Blender's DRT shares the suite's kernel cache (the checkout's engine/kernels/__pycache__,
reached through the add-on's link): cached kernels load under the add-on's module name
(`drt.engine.*`) as under the suite's (`engine.*`), engine/kernels/cache_files.py, so a
kernel compiled by either is compiled once (engine/kernels/compile_lock.py). The scene
renders with DRT's Whitted integrator, on the same compiled tracer as the path tracer.
Without a `blender` on PATH the tests are skipped, saying that they did not run.
"""
from __future__ import annotations

import os
import re
import shutil
import sys

import numpy as np
import pytest

from legacy_blender import SCENE_SCRIPT, LegacyBlender

SAMPLES = 4             # tests/legacy_blender_scene.py

@pytest.fixture(scope="module")
def legacy_blender(tmp_path_factory):
    blender = shutil.which("blender")
    if blender is None:
        pytest.skip("no `blender` binary on PATH: the Debian Blender (legacy add-on) tests "
                    "did not run; .ci/run installs it with apt-get when run as root")
    b = LegacyBlender(blender, tmp_path_factory.mktemp("debian_blender"))
    proc = b.run("--python", SCENE_SCRIPT, "--", b.blend)
    found = re.search(r"DRT-PYTHON (\d+\.\d+)", proc.log)
    ours = f"{sys.version_info[0]}.{sys.version_info[1]}"
    if found and found.group(1) != ours:
        pytest.skip(f"this Blender's Python is {found.group(1)}, the test environment's "
                    f"{ours}: its compiled packages cannot load there; the Debian Blender "
                    "tests did not run")
    assert proc.returncode == 0 and os.path.isfile(b.blend), proc.log
    assert "DRT-SCENE" in proc.log and "Traceback" not in proc.log, proc.log
    b.build_log = proc.log
    return b


def test_exporter_reads_corner_normals(legacy_blender):
    """Blender before 4.1 computes corner normals only when asked (calc_normals_split):
    the smooth plane's, read by the exporter, are unit vectors, not zeros."""
    found = re.search(r"DRT-CORNER-NORMALS (\S+) (\S+)", legacy_blender.build_log)
    assert found, legacy_blender.build_log
    assert abs(float(found.group(1)) - 1.0) < 1e-3 and abs(float(found.group(2)) - 1.0) < 1e-3


def _check_log(proc, frames: int, threads: str | None = None):
    """Exit code 0, no Python error, per frame `Sample i/N` progress up to N and one
    `Saved:` line; returns the saved paths."""
    log = proc.log
    assert proc.returncode == 0, log
    assert "Traceback" not in log, log
    assert not re.search(r"^Error", log, re.M), log
    progress = re.findall(r"^Fra:\d+ \|.*Sample (\d+)/(\d+).*$", log, re.M)
    assert progress and {int(n) for _, n in progress} == {SAMPLES}, log
    assert sum(int(i) == SAMPLES for i, _ in progress) == frames, log
    if threads is not None:
        lines = re.findall(r"^Fra:\d+ \|.*Sample \d+/\d+.*$", log, re.M)
        assert all(line.endswith(f"| {threads}") for line in lines), log
    saved = re.findall(r"^Saved: '(.+)'", log, re.M)
    assert len(saved) == frames, log
    return saved


def _pixels(path) -> np.ndarray:
    from PIL import Image
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=np.float64)


def _check_pixels(path):
    """Black sky in the top rows, lamp light on the plane below, the red cube."""
    px = _pixels(path)
    assert px.shape == (24, 32, 3)
    assert px[:3].max() < 8.0, px[:3].max()                 # the top rows see the black world
    lower = px[12:]
    assert lower.mean() > 40.0, lower.mean()               # the plane, lit by the lamp
    near, far = px[18:22, 8:11].mean(), px[11:13, :6].mean()
    assert near > 2.0 * far, (near, far)                   # brightest under the lamp
    red = (px[..., 0] > 60) & (px[..., 0] > 2.5 * px[..., 1]) & (px[..., 0] > 2.5 * px[..., 2])
    assert red.sum() >= 4, red.sum()                        # the red cube's Principled BSDF
    return px


def test_renders_a_frame_with_dash_E_DRT(legacy_blender):
    b = legacy_blender
    out = b.home / "f1" / "frame_####"
    proc = b.run("--addons", "drt", b.blend, "-E", "DRT", "-o", str(out), "-f", "1")
    saved = _check_log(proc, frames=1, threads="all cores")   # no -t: DRT's default
    assert saved == [str(b.home / "f1" / "frame_0001.png")]
    _check_pixels(saved[0])


def test_renders_the_scene_range_with_dash_a(legacy_blender):
    b = legacy_blender
    out = b.home / "anim" / "frame_####"
    proc = b.run("--addons", "drt", b.blend, "-E", "DRT", "-o", str(out), "-a")
    saved = _check_log(proc, frames=2)
    assert saved == [str(b.home / "anim" / f"frame_000{f}.png") for f in (1, 2)]
    first, second = (_check_pixels(p) for p in saved)
    assert np.abs(first - second).max() > 30.0          # the cube moved: frame 2 is its own


def test_flamenco_command_line(legacy_blender):
    """Flamenco's Simple Blender Render: no -E (the file's engine, the add-on enabled in
    the preferences); it reads the `Saved:` and `Time:` lines."""
    b = legacy_blender
    out = b.home / "flamenco" / "######"
    proc = b.run("-y", b.blend, "--render-output", str(out), "--render-format", "PNG",
                 "--render-frame", "1..2")
    saved = _check_log(proc, frames=2)
    assert saved == [str(b.home / "flamenco" / f"00000{f}.png") for f in (1, 2)]
    assert len(re.findall(r"^ Time: \d\d:\d\d\.\d\d", proc.log, re.M)) == 2, proc.log
    for path in saved:
        _check_pixels(path)


def test_deadline_command_line_with_threads(legacy_blender):
    """Deadline's form: the engine saved in the file, the add-on enabled in the
    preferences, and `-t 1` reaching DRT's engine (printed on every progress line)."""
    b = legacy_blender
    out = b.home / "deadline" / "shot_####"
    proc = b.run(b.blend, "-t", "1", "-x", "1", "-o", str(out), "-s", "1", "-e", "1", "-a")
    saved = _check_log(proc, frames=1, threads="1 thread")
    assert saved == [str(b.home / "deadline" / "shot_0001.png")]
    _check_pixels(saved[0])
