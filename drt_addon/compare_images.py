"""`python -m drt_addon compare A.exr B.exr [-o DIFF.png]`: the error of image A against
the reference B (RMSE, relative MSE and FLIP, defined in engine/image_error.py) and a
false-colour difference image: FLIP's per-pixel error through the magma colour map
(black: no visible difference, yellow-white: the largest).
"""
from __future__ import annotations

import os
from importlib import import_module

import numpy as np

from .batch import EXIT_FILE, EXIT_OK, EXIT_USAGE, CliError

DIFF_FORMATS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


def add_parser(sub) -> None:
    c = sub.add_parser("compare", help="error of image A against reference B (RMSE, relMSE, "
                                       "FLIP) and a false-colour difference image")
    c.set_defaults(run=run_compare)
    c.add_argument("test", help="image A (OpenEXR, PNG, or any format Blender reads)")
    c.add_argument("reference", help="image B, the reference")
    c.add_argument("-o", "--output", help="the difference image, PNG/JPEG/TIFF "
                                          "(default: A_vs_B.png in the current folder)")


def default_output(test: str, reference: str) -> str:
    def stem(p):
        return os.path.splitext(os.path.basename(p))[0]
    return f"{stem(test)}_vs_{stem(reference)}.png"


def false_colour(error: np.ndarray) -> np.ndarray:
    """(h, w) error in [0, 1] to (h, w, 3) uint8 through matplotlib's magma."""
    from matplotlib import colormaps
    rgba = colormaps["magma"](np.clip(error, 0.0, 1.0))
    return (rgba[..., :3] * 255.0 + 0.5).astype(np.uint8)


def write_false_colour(error: np.ndarray, path: str) -> None:
    from PIL import Image
    Image.fromarray(false_colour(error)).save(path)


def _image_error():
    """engine.image_error, imported when used (the CLI parser stays light)."""
    from .engine_link import engine
    return import_module(engine.__name__ + ".image_error")


def format_metrics(err) -> str:
    image_error = _image_error()
    lines = [f"RMSE    {err.rmse:.6g}",
             f"relMSE  {err.relmse:.6g}  (eps {image_error.RELMSE_EPS:g})"]
    if err.flip is not None:
        lines.append(f"FLIP    {err.flip:.6g}  (LDR-FLIP of the images clipped to [0, 1])")
    return "\n".join(lines)


def run_compare(args) -> int:
    from .image_files import ImageFileError, read_image
    image_error = _image_error()
    out = args.output or default_output(args.test, args.reference)
    if os.path.splitext(out)[1].lower() not in DIFF_FORMATS:
        raise CliError(EXIT_USAGE, f"drt: error: the difference image must be one of "
                                   f"{', '.join(DIFF_FORMATS)}: {out}")
    try:
        test, ref = read_image(args.test), read_image(args.reference)
    except ImageFileError as e:
        raise CliError(EXIT_FILE, f"drt: error: {e}") from None
    try:
        error_map, mean_flip = image_error.flip_map(test, ref)
        err = image_error.ImageError(rmse=image_error.rmse(test, ref),
                                     relmse=image_error.relmse(test, ref), flip=mean_flip)
    except ValueError as e:
        raise CliError(EXIT_USAGE, f"drt: error: cannot compare {args.test} with "
                                   f"{args.reference}: {e}") from None
    out_dir = os.path.dirname(os.path.abspath(out))
    try:
        os.makedirs(out_dir, exist_ok=True)
        write_false_colour(error_map, out)
    except OSError as e:
        raise CliError(EXIT_USAGE, f"drt: error: cannot write {out}: "
                                   f"{e.strerror or e}") from None
    print(format_metrics(err))
    print(f"drt: wrote {out} (FLIP error map, magma colour map)")
    return EXIT_OK
