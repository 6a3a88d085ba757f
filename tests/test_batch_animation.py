"""The batch renderer on frame ranges (in this process, through `batch.main`): every frame
written under its `#` name, the .blend's own output path and format, a video output
falling back to PNG, --skip-existing resuming a job, progress bars and the summary."""
import os

import numpy as np
import pytest

from batch_scenes import FRAMES, build_animated_cornell
from conftest import read_image_linear

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def anim_blend(bpy_drt, tmp_path_factory):
    return build_animated_cornell(bpy_drt, tmp_path_factory.mktemp("anim") / "anim.blend")


def drt(*args):
    from drt_addon.batch import main
    return main(["render", *map(str, args)])


def test_a_frame_range_writes_every_frame(bpy_drt, anim_blend, tmp_path, capsys):
    code = drt(anim_blend, "-o", tmp_path / "a_###.exr", "--frames", "1-3")
    out, err = capsys.readouterr()
    assert code == 0, err
    names = [f"a_00{f}.exr" for f in FRAMES]
    assert sorted(os.listdir(tmp_path)) == names          # and no temporary file left
    images = [read_image_linear(bpy_drt, str(tmp_path / n)) for n in names]
    assert images[0].shape == (24, 32, 3)
    # the block moves: each frame is its own render
    assert np.abs(images[0] - images[1]).max() > 0.05
    assert np.abs(images[1] - images[2]).max() > 0.05
    rows = [l.split() for l in out.splitlines() if l.endswith(".exr") and "wrote" not in l]
    assert [r[0] for r in rows] == ["1", "2", "3"] and all(r[2] == "4" for r in rows)
    assert "frames: 100%" in err and "frame 3" in err       # the two tqdm bars


def test_skip_existing_resumes_a_job(anim_blend, tmp_path, capsys):
    done = tmp_path / "f_0002.png"
    done.write_bytes(b"a frame rendered before the interruption")
    code = drt(anim_blend, "-o", tmp_path / "f_####.png", "--animation", "--skip-existing",
               "--no-progress")
    out, err = capsys.readouterr()
    assert code == 0, err
    assert done.read_bytes() == b"a frame rendered before the interruption"
    for f in (1, 3):
        assert (tmp_path / f"f_000{f}.png").read_bytes().startswith(PNG_MAGIC)
    assert "(exists, skipped)" in out and "2 frame(s) rendered" in out and "1 skipped" in out
    # --no-progress: no bars on stderr, only the render's warnings (one line each)
    assert all(l.startswith("drt: warning:") for l in err.splitlines()), err
    assert "Max Samples is 64, not used" in err


def test_without_o_the_blend_output_path_and_format(bpy_drt, anim_blend, tmp_path, capsys):
    """The .blend says //out/anim_#### as PNG: the frames land next to the file."""
    blend = tmp_path / "copy.blend"
    blend.write_bytes(open(anim_blend, "rb").read())
    code = drt(blend, "--frames", "2,3", "--samples", "1", "--no-progress")
    out, err = capsys.readouterr()
    assert code == 0, err
    assert sorted(os.listdir(tmp_path / "out")) == ["anim_0002.png", "anim_0003.png"]
    assert (tmp_path / "out" / "anim_0002.png").read_bytes().startswith(PNG_MAGIC)


def test_a_video_output_falls_back_to_png(bpy_drt, tmp_path, capsys):
    blend = build_animated_cornell(bpy_drt, tmp_path / "video.blend", video_output=True)
    before = open(blend, "rb").read()
    code = drt(blend, "--frame", "3", "--samples", "1", "--no-progress")
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "video" in err and "PNG" in err and err.startswith("drt: note:")
    assert (tmp_path / "out" / "anim_0003.png").read_bytes().startswith(PNG_MAGIC)
    assert open(blend, "rb").read() == before               # the file is not changed


def test_a_multilayer_exr_output_keeps_the_enabled_passes(bpy_drt, anim_blend, tmp_path,
                                                          capsys):
    """The file's own format, multilayer OpenEXR: one file per frame with the view
    layer's enabled passes beside Combined."""
    bpy = bpy_drt
    bpy.ops.wm.open_mainfile(filepath=anim_blend, load_ui=False)
    settings = bpy.context.scene.render.image_settings
    settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    bpy.context.scene.view_layers[0].use_pass_z = True
    blend = str(tmp_path / "multilayer.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
    code = drt(blend, "--frame", "2", "--samples", "1", "-o", tmp_path / "ml_#",
               "--no-progress")
    assert code == 0, capsys.readouterr().err
    header = (tmp_path / "ml_2.exr").read_bytes()[:4096]
    assert b"Combined.R" in header and b"Depth.Z" in header
