"""The batch renderer's bookkeeping without Blender: frame lists, `#` output paths, the
output format, atomic writes and the summary table."""
import os
from types import SimpleNamespace

import pytest

from drt_addon.batch_report import FrameResult, summary_table
from drt_addon.frame_output import choose_format, save_atomically, temp_path
from drt_addon.frames import (FrameSpecError, fill_placeholder, output_pattern,
                              parse_frames, scene_frames)


@pytest.mark.parametrize("spec, frames", [
    ("7", [7]),
    ("1-4", [1, 2, 3, 4]),
    ("1..4", [1, 2, 3, 4]),
    ("1-9:4", [1, 5, 9]),
    ("1,5,10-12", [1, 5, 10, 11, 12]),
    ("3, 1-3", [3, 1, 2]),              # listed twice: once, first position
    ("-2-1", [-2, -1, 0, 1]),
    ("-5--4", [-5, -4]),
])
def test_frame_lists(spec, frames):
    assert parse_frames(spec) == frames


@pytest.mark.parametrize("spec", ["", "a", "5-1", "1-", "1-5:0", "1;2", "0-2000000"])
def test_bad_frame_lists_are_refused(spec):
    with pytest.raises(FrameSpecError):
        parse_frames(spec)


def test_scene_range_with_step():
    assert scene_frames(1, 10, 3) == [1, 4, 7, 10]
    assert scene_frames(5, 5, 1) == [5]


@pytest.mark.parametrize("pattern, frame, path", [
    ("shot_####.png", 7, "shot_0007.png"),
    ("a##_b###.exr", 12, "a##_b012.exr"),      # the rightmost run, as Blender
    ("f_#.png", 123, "f_123.png"),             # more digits than #: not cut
    ("f_###.png", -4, "f_-04.png"),
    ("plain.png", 3, "plain.png"),
])
def test_placeholders(pattern, frame, path):
    assert fill_placeholder(pattern, frame) == path


def test_output_patterns(tmp_path):
    folder = str(tmp_path)
    assert output_pattern(folder, ".exr", True) == os.path.join(folder, "####.exr")
    assert output_pattern("out/", ".png", False) == os.path.join("out", "####.png")
    assert output_pattern("out/shot_##", ".png", True) == "out/shot_##.png"
    assert output_pattern("out/shot", ".png", True) == "out/shot####.png"
    assert output_pattern("out/still.png", ".png", False) == "out/still.png"
    assert output_pattern("out/anim.png", ".png", True) == "out/anim####.png"
    assert output_pattern("out/v1.2_####", ".exr", True) == "out/v1.2_####.exr"


def _settings(fmt, media="IMAGE"):
    return SimpleNamespace(file_format=fmt, media_type=media)


def test_output_format_choice():
    assert choose_format(_settings("JPEG"), ".exr") == ("OPEN_EXR", ".exr", None)
    assert choose_format(_settings("OPEN_EXR_MULTILAYER", "MULTI_LAYER_IMAGE"), ".exr")[0] \
        == "OPEN_EXR_MULTILAYER"
    assert choose_format(_settings("TIFF"), None) == ("TIFF", ".tif", None)
    fmt, ext, note = choose_format(_settings("FFMPEG", "VIDEO"), None)
    assert (fmt, ext) == ("PNG", ".png") and "video" in note


def test_a_failed_write_leaves_the_old_file_and_no_partial_one(tmp_path):
    final = tmp_path / "f_0001.png"
    final.write_bytes(b"old complete frame")

    def crash_halfway(tmp):
        with open(tmp, "wb") as f:
            f.write(b"half a fra")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        save_atomically(crash_halfway, str(final))
    assert final.read_bytes() == b"old complete frame"
    assert sorted(os.listdir(tmp_path)) == ["f_0001.png"]

    save_atomically(lambda tmp: open(tmp, "wb").write(b"new frame"), str(final))
    assert final.read_bytes() == b"new frame"
    assert sorted(os.listdir(tmp_path)) == ["f_0001.png"]
    assert temp_path(str(final)).endswith(".png") and temp_path(str(final)) != str(final)


def test_summary_table():
    table = summary_table([FrameResult(1, "/o/f1.png", seconds=2.0, samples=16,
                                       paths=4_000_000),
                           FrameResult(2, "/o/f2.png", status="skipped")])
    lines = table.splitlines()
    assert lines[0].split() == ["frame", "seconds", "samples", "Mpaths/s", "file"]
    assert lines[1].split() == ["1", "2.00", "16", "2.000", "/o/f1.png"]
    assert "skipped" in lines[2]
    assert lines[-1].startswith("1 frame(s) rendered") and "1 skipped" in lines[-1]
