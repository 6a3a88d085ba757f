"""`python -m drt_addon compare` and `converge` (in-process through batch.main, on tiny
images and a 30x30 Cornell box, so the module stays cheap): the printed numbers, the
written files, the cache, and one clear error line for bad input."""
import json
import math
import os
import re

import numpy as np
import pytest

from conftest import SAMPLES_DIR

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")


def drt(capsys, *args):
    from drt_addon.batch import main
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def write_exr(bpy, path, rgb):
    """An OpenEXR of (h, w, 3) values that half floats hold exactly."""
    h, w, _ = rgb.shape
    img = bpy.data.images.new("t", w, h, float_buffer=True, alpha=True)
    rgba = np.concatenate([rgb, np.ones((h, w, 1))], axis=2)[::-1]
    img.pixels.foreach_set(rgba.astype(np.float32).ravel())
    img.filepath_raw = str(path)
    img.file_format = "OPEN_EXR"
    img.save()
    bpy.data.images.remove(img)


def printed(out, name):
    return float(re.search(rf"^{name}\s+(\S+)", out, re.M).group(1))


def test_compare_prints_the_metrics_and_writes_the_error_map(bpy_drt, tmp_path, capsys):
    rng = np.random.default_rng(2)
    ref = rng.integers(1, 16, (24, 32, 3)) / 8.0          # exact in half floats
    test = ref.copy()
    test[6:12, 8:20] += 0.5                               # one visibly brighter patch
    write_exr(bpy_drt, tmp_path / "a.exr", test)
    write_exr(bpy_drt, tmp_path / "b.exr", ref)
    diff = tmp_path / "out" / "diff.png"
    code, out, err = drt(capsys, "compare", str(tmp_path / "a.exr"), str(tmp_path / "b.exr"),
                         "-o", str(diff))
    assert code == 0, err
    n = ref.size
    assert printed(out, "RMSE") == pytest.approx(math.sqrt(6 * 12 * 3 * 0.25 / n), rel=1e-5)
    expected_rel = float(np.sum(0.25 / (ref[6:12, 8:20] ** 2 + 0.01)) / n)
    assert printed(out, "relMSE") == pytest.approx(expected_rel, rel=1e-5)
    from engine.image_error import flip
    assert printed(out, "FLIP") == pytest.approx(flip(test, ref), rel=1e-5)
    from PIL import Image
    error = np.asarray(Image.open(diff).convert("L"), dtype=float)
    assert error.shape == (24, 32)
    # the patch lights up in the error map; far from it the map is black
    assert error[7:11, 10:18].mean() > 60 > error[18:, 24:].max()


def test_png_inputs_are_decoded_from_srgb(bpy_drt, tmp_path):
    from PIL import Image

    from drt_addon.image_files import read_image
    Image.fromarray(np.full((4, 6, 3), 128, np.uint8)).save(tmp_path / "grey.png")
    img = read_image(str(tmp_path / "grey.png"))
    assert img.shape == (4, 6, 3)
    assert img == pytest.approx(((128 / 255 + 0.055) / 1.055) ** 2.4, abs=1e-6)


@pytest.mark.parametrize("args, code, words", [
    (("compare", "{tmp}/missing.exr", "{tmp}/b.exr"), 3, "file not found"),
    (("compare", "{tmp}", "{tmp}/b.exr"), 3, "is a directory"),
    (("compare", "{tmp}/b.exr", "{tmp}/b.exr", "-o", "{tmp}/d.bmpx"), 2, "difference image"),
    (("converge", "{tmp}/missing.blend"), 3, "file not found"),
    (("converge", CORNELL, "--reference", "luxcore:64"), 2, "drt:N or cycles:N"),
    (("converge", CORNELL, "--samplers", "halton"), 2, "--samplers"),
    (("converge", CORNELL, "--max-samples", "0"), 2, "--max-samples"),
    (("converge", CORNELL, "--clamps", "0:x"), 2, "Direct:Indirect"),
    (("converge", CORNELL, "--clamps", "0:1", "--reference", "cycles:16"), 2, "unclamped"),
])
def test_bad_input_is_one_clear_error_line(bpy_drt, tmp_path, capsys, args, code, words):
    (tmp_path / "b.exr").write_bytes(b"")
    args = [a.format(tmp=tmp_path) for a in args]
    got, out, err = drt(capsys, *args)
    assert got == code, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("drt: error:"), err
    assert words in lines[0]


def converge(capsys, out_dir, cache, *extra):
    code, out, err = drt(capsys, "converge", CORNELL, "-o", str(out_dir), "--percentage", "12",
                         "--cache-dir", str(cache), *extra)
    assert code == 0, err
    with open(out_dir / "convergence.json") as f:
        return json.load(f), out


def test_converge_measures_the_ladders_and_caches_them(bpy_drt, tmp_path, capsys):
    args = ("--reference", "drt:256", "--samplers", "random,jittered", "--max-samples", "16",
            "--with-cycles")
    result, out = converge(capsys, tmp_path / "a", tmp_path / "cache", *args)
    assert result["resolution"] == [30, 30]
    assert result["reference"]["engine"] == "DRT" and not result["reference"]["cached"]
    curves = {c["label"]: c for c in result["curves"]}
    assert set(curves) == {"DRT path random", "DRT path jittered",
                           "Cycles (" + bpy_drt.context.scene.cycles.sampling_pattern.lower()
                           + ")"}
    for c in curves.values():
        assert c["samples"] == [1, 2, 4, 8, 16]
        assert c["relmse"][-1] < c["relmse"][0] / 4       # 16x the samples
        assert c["flip"][-1] < c["flip"][0]
    rand = curves["DRT path random"]
    assert all(b < a for a, b in zip(rand["relmse"], rand["relmse"][1:]))
    assert rand["seconds"] == sorted(rand["seconds"])    # cumulative (progressive)
    # Independent samples: MSE falls as 1/samples, RMSE as its root. Tolerance 0.2 on a
    # 900-pixel image (measured -1.00 and -0.48).
    assert rand["slopes"]["samples"]["relmse"] == pytest.approx(-1.0, abs=0.2)
    assert rand["slopes"]["samples"]["rmse"] == pytest.approx(-0.5, abs=0.1)
    assert "DRT path random" in out and "wrote" in out
    from PIL import Image
    with Image.open(tmp_path / "a" / "convergence.png") as png:
        assert png.width > 400 and png.height > 400

    again, _ = converge(capsys, tmp_path / "b", tmp_path / "cache", *args)
    assert again["reference"]["cached"]
    assert all(c["cached"] for c in again["curves"])
    assert [c["relmse"] for c in again["curves"]] == [c["relmse"] for c in result["curves"]]


def test_converge_against_a_cycles_reference(bpy_drt, tmp_path, capsys):
    result, _ = converge(capsys, tmp_path / "c", tmp_path / "cache", "--reference",
                         "cycles:64", "--samplers", "sobol", "--max-samples", "4",
                         "--with-cycles")
    ref = result["reference"]
    assert ref["engine"] == "Cycles" and ref["samples"] == 64
    assert ref["noise_floor"]["relmse"] > 0          # from its two independent halves
    for c in result["curves"]:
        assert c["relmse"][-1] < c["relmse"][0] / 2


def test_an_integrator_that_cannot_render_the_scene_is_skipped_with_its_reason(
        bpy_drt, tmp_path, capsys):
    code, out, err = drt(capsys, "converge", os.path.join(SAMPLES_DIR, "fog_room.blend"),
                         "-o", str(tmp_path), "--percentage", "25", "--reference", "drt:16",
                         "--samplers", "random", "--integrators", "path,whitted",
                         "--max-samples", "2", "--cache-dir", str(tmp_path / "cache"))
    assert code == 0, err
    with open(tmp_path / "convergence.json") as f:
        result = json.load(f)
    assert [c["label"] for c in result["curves"]] == ["DRT path random"]
    assert result["skipped"][0]["label"] == "DRT whitted random"
    assert "volumes" in result["skipped"][0]["reason"]
    assert "skipped DRT whitted random" in out


def test_clamps_are_measured_as_bias_traded_for_noise(bpy_drt, tmp_path, capsys):
    """--clamps: against an unclamped reference, a strong indirect clamp is less noisy at
    one sample than the unclamped curve but flattens at its bias, so more samples stop
    paying; the unclamped curve keeps falling (measured relMSE at 1 and 64 samples:
    unclamped 0.70 and 0.015, clamp 0:0.1 0.29 and 0.095)."""
    result, out = converge(capsys, tmp_path / "k", tmp_path / "cache", "--reference",
                           "drt:256", "--samplers", "random", "--max-samples", "64",
                           "--clamps", "0:0,0:0.1")
    assert result["reference"]["clamps"] == "off"
    curves = {c["label"]: c for c in result["curves"]}
    free, clamped = curves["DRT path random clamp 0:0"], curves["DRT path random clamp 0:0.1"]
    assert clamped["clamp"] == [0.0, 0.1]
    assert clamped["relmse"][0] < free["relmse"][0] / 1.5     # less noise at one sample
    assert clamped["relmse"][-1] > 2 * free["relmse"][-1]     # its bias at 64
    gain = lambda c: c["relmse"][0] / c["relmse"][-1]        # noqa: E731
    assert gain(clamped) < gain(free) / 4, (gain(clamped), gain(free))
    assert "clamp 0:0.1" in out
