"""DRT's Rendered viewport in a real Blender with a window: Debian's `blender` (3.4, the
one CI installs) on a virtual screen (xvfb-run, Mesa's software OpenGL), DRT as a legacy
add-on (tests/legacy_blender.py). tests/viewport_window_driver.py switches the 3D view to
Rendered and edits the scene from Blender's own event loop; this test reads what it
recorded and the screenshots of the 3D view Blender took after each step.

Checked: the view shows the render (the red cube, the lit plane, the black sky), each
edit shows in the next image (green cube, moved cube, brighter lamp), an edit re-exports
no mesh (a colour: one material), navigation exports nothing, and back in Solid shading
no viewport thread is left and Blender keeps running. The time from each edit to its
first image drawn is printed (measured, not asserted: tests assert no wall-clock times).
"""
from __future__ import annotations

import json
import os
import shutil

import numpy as np
import pytest

from legacy_blender import ROOT, SCENE_SCRIPT, LegacyBlender

DRIVER = os.path.join(ROOT, "tests", "viewport_window_driver.py")


@pytest.fixture(scope="module")
def viewport_run(tmp_path_factory):
    blender, xvfb = shutil.which("blender"), shutil.which("xvfb-run")
    if blender is None or xvfb is None:
        pytest.skip("no `blender` or `xvfb-run` on PATH: the Rendered viewport window test "
                    "did not run; .ci/run installs both with apt-get when run as root")
    b = LegacyBlender(blender, tmp_path_factory.mktemp("viewport_window"))
    proc = b.run("--python", SCENE_SCRIPT, "--", b.blend)
    assert proc.returncode == 0 and os.path.isfile(b.blend), proc.log
    out = b.home / "out"
    out.mkdir()
    proc = b.run("--addons", "drt", b.blend, "--python", DRIVER, "--", str(out),
                 window=True, timeout=900)
    path = out / "viewport.json"
    assert path.is_file(), proc.log
    result = json.loads(path.read_text())
    assert result["error"] is None, result["error"] + proc.log
    assert "Traceback" not in proc.log, proc.log
    result["steps"] = {s["name"]: s for s in result["steps"]}
    for name, s in result["steps"].items():
        if "edit_to_first_draw" in s:
            print(f"\nviewport window, {name}: edit to first image drawn "
                  f"{s['edit_to_first_draw']:.3f} s, to full resolution "
                  f"{s['edit_to_full_resolution']:.3f} s (export {s['export_seconds']:.3f} s)")
    return result


def _view(path) -> np.ndarray:
    from PIL import Image
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=np.float64)


def _cube(px, colour: int) -> np.ndarray:
    """Pixels where channel `colour` (0 red, 1 green) dominates clearly."""
    others = [c for c in range(3) if c != colour]
    return ((px[..., colour] > 60) & (px[..., colour] > 2.0 * px[..., others[0]])
            & (px[..., colour] > 2.0 * px[..., others[1]]))


def test_rendered_viewport_shows_the_render(viewport_run):
    s = viewport_run["steps"]["start"]
    assert s["first_sync"] and s["samples"] >= 4 and s["mesh_evaluations"] == 2, s
    px = _view(s["screenshot"])
    assert px[: px.shape[0] // 6].mean() < 10.0            # the black sky above
    assert _cube(px, 0).sum() > 200                          # the red cube
    assert px[-px.shape[0] // 3:].mean() > 30.0             # the lit plane below


def test_edits_show_without_re_exporting_meshes(viewport_run):
    steps = viewport_run["steps"]
    start, material = _view(steps["start"]["screenshot"]), _view(steps["material"]["screenshot"])
    assert steps["material"]["syncs"] == 1
    assert steps["material"]["mesh_evaluations"] == 0 and steps["material"]["material_exports"] == 1
    assert _cube(material, 1).sum() > 200 and _cube(material, 0).sum() < 20
    moved = _view(steps["move"]["screenshot"])
    assert steps["move"]["mesh_evaluations"] == 0 and steps["move"]["material_exports"] == 0
    was, now = np.nonzero(_cube(material, 1))[1].mean(), np.nonzero(_cube(moved, 1))[1].mean()
    assert now - was > 40, (was, now)                        # the cube moved right
    lamp = _view(steps["lamp"]["screenshot"])
    assert steps["lamp"]["mesh_evaluations"] == 0
    # a lamp's edit keeps the acceleration structure; a move rebuilds it
    assert steps["lamp"]["rebuilt"] is False and steps["move"]["rebuilt"] is True
    lower = slice(-moved.shape[0] // 3, None)
    assert lamp[lower].mean() > 1.3 * moved[lower].mean()    # four times the power
    assert np.abs(start - material).max() > 50


def test_navigation_exports_nothing(viewport_run):
    steps = viewport_run["steps"]
    assert steps["navigate"]["syncs"] == 0
    assert np.abs(_view(steps["navigate"]["screenshot"])
                  - _view(steps["lamp"]["screenshot"])).mean() > 5.0


def test_viewport_denoise_setting_is_honoured(viewport_run):
    """Sampling > Viewport > Denoise turned on restarts the view, and the images drawn are
    OpenImageDenoise's from sample 1 (this scene is nearly noiseless at 4 samples, so
    the view changes little; tests/test_viewport.py measures what denoising buys)."""
    steps = viewport_run["steps"]
    assert steps["denoise"]["syncs"] == 1 and steps["denoise"]["denoised"], steps["denoise"]
    assert not steps["navigate"]["denoised"]


def test_leaving_rendered_mode_stops_tracing(viewport_run):
    s = viewport_run["steps"]["solid"]
    assert s["threads"] == [] and s["responsive_after"] >= 1.5
