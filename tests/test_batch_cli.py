"""The batch renderer's exit codes, each one, with a single clear line on stderr."""
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT, SAMPLES_DIR

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")


def drt(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "drt_addon", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


def assert_one_clear_error_line(proc):
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("drt: error:"), proc.stderr
    assert "Traceback" not in proc.stderr


def test_success_writes_the_image(tmp_path):
    out = tmp_path / "cornell.png"
    proc = drt("render", CORNELL, "-o", str(out), "--samples", "2", "--seed", "3", "--frame", "1")
    assert proc.returncode == 0, proc.stderr
    assert out.exists()
    assert f"wrote {out}" in proc.stdout
    # the progress lines render-farm managers parse (Deadline: `Sample ([0-9]+)/([0-9]+)`)
    assert re.findall(r"Sample ([0-9]+)/([0-9]+)", proc.stdout) == [("1", "2"), ("2", "2")]
    from PIL import Image
    img = np.asarray(Image.open(out)).astype(float)
    assert img.shape[:2] == (256, 256)
    assert img.std() > 10


@pytest.mark.parametrize("args", [
    (),                                             # no command
    ("render",),                                    # no file
    ("render", CORNELL, "--frames", "5-1"),         # a range ending before it starts
    ("render", CORNELL, "--frame", "1", "--frames", "2"),   # two frame choices
    ("render", CORNELL, "--sample-batches", "2"),   # batches need Dask workers
    ("render", CORNELL, "--workers", "2", "--engine", "CYCLES"),  # Dask renders DRT only
    ("render", CORNELL, "--noise-threshold", "0"),
    ("render", CORNELL, "-o", "x.png", "--samples", "zero"),
    ("render", CORNELL, "-o", "x.png", "--samples", "0"),
    ("render", CORNELL, "-o", "x.png", "--seed", "-1"),
    ("render", CORNELL, "-o", "x.bmpx"),           # unknown output format
    ("render", CORNELL, "-o", "/dev/null/cannot/x.png"),   # folder cannot be created
    ("paint", CORNELL),
])
def test_bad_arguments_exit_2(args):
    proc = drt(*args)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert_one_clear_error_line(proc)


def test_missing_file_exits_3(tmp_path):
    proc = drt("render", str(tmp_path / "missing.blend"), "-o", str(tmp_path / "x.png"))
    assert proc.returncode == 3
    assert_one_clear_error_line(proc)
    assert "not found" in proc.stderr


def test_not_a_blend_file_exits_3(tmp_path):
    fake = tmp_path / "fake.blend"
    fake.write_text("this is not a blend file\n")
    proc = drt("render", str(fake), "-o", str(tmp_path / "x.png"))
    assert proc.returncode == 3
    assert_one_clear_error_line(proc)
    assert "not a .blend" in proc.stderr


def test_truncated_blend_exits_3(tmp_path):
    broken = tmp_path / "broken.blend"
    broken.write_bytes(open(CORNELL, "rb").read()[:4000])
    proc = drt("render", str(broken), "-o", str(tmp_path / "x.png"))
    assert proc.returncode == 3, proc.stderr
    assert_one_clear_error_line(proc)


def test_render_failure_exits_4(tmp_path):
    # A valid .blend whose scene has no camera cannot be rendered.
    blend = tmp_path / "no_camera.blend"
    script = ("import bpy; bpy.ops.wm.read_factory_settings(use_empty=True); "
              f"bpy.ops.wm.save_as_mainfile(filepath={str(blend)!r})")
    subprocess.run([sys.executable, "-c", script], check=True, capture_output=True)
    proc = drt("render", str(blend), "-o", str(tmp_path / "x.png"))
    assert proc.returncode == 4, proc.stderr
    assert_one_clear_error_line(proc)
    assert "camera" in proc.stderr
    assert not (tmp_path / "x.png").exists()


_MAGIC = {".png": b"\x89PNG\r\n\x1a\n", ".exr": b"\x76\x2f\x31\x01"}


@pytest.fixture(scope="module", params=[("VIDEO", "FFMPEG"),
                                        ("MULTI_LAYER_IMAGE", "OPEN_EXR_MULTILAYER")])
def movie_output_blend(request, tmp_path_factory):
    """The Cornell box saved with its output set to a video (or a multilayer EXR): Blender
    5 then offers no still format in image_settings.file_format until media_type is
    IMAGE again."""
    media, file_format = request.param
    blend = tmp_path_factory.mktemp(media.lower()) / f"{media.lower()}_output.blend"
    script = (f"import bpy; bpy.ops.wm.open_mainfile(filepath={CORNELL!r}); "
              "s = bpy.context.scene.render.image_settings; "
              f"s.media_type = {media!r}; s.file_format = {file_format!r}; "
              f"bpy.ops.wm.save_as_mainfile(filepath={str(blend)!r}); "
              "print('saved', s.media_type, s.file_format)")
    made = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True,
                          text=True)
    assert f"saved {media} {file_format}" in made.stdout, made.stdout + made.stderr
    return blend


@pytest.mark.parametrize("ext", [".png", ".exr"])
def test_a_file_with_video_output_renders_stills(tmp_path, movie_output_blend, ext):
    """The extension of -o decides the format, whatever the file's output is; the .blend
    on disk is not changed."""
    before = movie_output_blend.read_bytes()
    out = tmp_path / f"still{ext}"
    proc = drt("render", str(movie_output_blend), "-o", str(out), "--samples", "1",
               "--percentage", "10")
    assert proc.returncode == 0, proc.stderr
    assert out.read_bytes().startswith(_MAGIC[ext])
    assert movie_output_blend.read_bytes() == before


def test_a_missing_library_is_one_warning_line_in_a_real_process(bpy_drt, tmp_path):
    """In a process of its own, Blender's own notes about the missing library go to
    stdout; stderr holds DRT's one warning line (tests/hostile_cases.py has the rest)."""
    from hostile_cases import CASES, _write_case
    kind = next(k for name, *_, k in CASES if name.startswith("a linked library"))
    blend = str(tmp_path / "linked.blend")
    _write_case(bpy_drt, kind, blend, str(tmp_path))
    proc = drt("render", blend, "-o", str(tmp_path / "x.png"), "--no-progress")
    assert proc.returncode == 0, proc.stderr
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    assert len(lines) == 1 and lines[0].startswith("drt: warning: linked library"), lines
    assert "Object 'LibCube'" in lines[0]
    assert (tmp_path / "x.png").exists()
