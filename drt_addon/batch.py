"""The headless batch renderer on the bpy module.

    python -m drt_addon render SCENE.blend -o OUT.png [--samples N] [--seed S] [--frame F]
    python -m drt_addon package [-o DIR] [--platform P]   (build the extension zips;
                                                           see docs/install.md)
    python -m drt_addon compare A.exr B.exr [-o DIFF.png]  (compare_images.py)
    python -m drt_addon converge SCENE.blend [-o DIR] ...  (converge.py; docs/convergence.md)

Exit codes: 0 success, 2 bad arguments, 3 file missing or not a .blend, 4 render or package failed.
Errors go to stderr as one line; no traceback reaches the user.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

EXIT_OK, EXIT_USAGE, EXIT_FILE, EXIT_RENDER = 0, 2, 3, 4
FORMATS = {".png": "PNG", ".exr": "OPEN_EXR", ".jpg": "JPEG", ".jpeg": "JPEG",
           ".tif": "TIFF", ".tiff": "TIFF"}
# A .blend starts with "BLENDER", or is zstd- or gzip-compressed.
_BLEND_MAGICS = (b"BLENDER", b"\x28\xb5\x2f\xfd", b"\x1f\x8b")


class CliError(Exception):
    def __init__(self, code, message):
        super().__init__(message)
        self.code = code


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise CliError(EXIT_USAGE, f"drt: error: {message} (see '{self.prog} --help')")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="drt", description="DRT headless renderer (Blender's bpy module).")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("render", help="render one frame of a .blend with DRT")
    r.add_argument("blend", help="the .blend file")
    r.add_argument("-o", "--output", required=True,
                   help="output image; the format follows the extension "
                        f"({', '.join(sorted(FORMATS))}); PNG/JPEG/TIFF use the scene's "
                        "colour management, EXR is scene-linear")
    r.add_argument("--samples", type=int, help="samples per pixel (default: the scene's)")
    r.add_argument("--seed", type=int, help="random seed (default: the scene's)")
    r.add_argument("--frame", type=int, help="frame to render (default: the current frame)")
    r.add_argument("--percentage", type=int,
                   help="resolution percentage, 1..10000 (default: the scene's)")
    r.add_argument("--engine", default="DRT", choices=("DRT", "CYCLES"),
                   help="render engine (CYCLES for reference images)")
    pk = sub.add_parser("package", help="build and validate the Blender extension zips, one "
                                        "per platform (downloads the pinned wheels into "
                                        "wheels/); prints one zip path per line")
    pk.add_argument("-o", "--output-dir", help="folder for the zips (default: build/)")
    pk.add_argument("--platform", action="append", dest="platforms", metavar="PLATFORM",
                    help="build only this platform's zip (one of the manifest's platforms, "
                         "e.g. linux-x64; repeatable; default: every platform)")
    from . import compare_images, converge
    for command in (compare_images, converge):
        command.add_parser(sub)
    return p


def check_blend(path: str) -> None:
    if not os.path.exists(path):
        raise CliError(EXIT_FILE, f"drt: error: file not found: {path}")
    if os.path.isdir(path):
        raise CliError(EXIT_FILE, f"drt: error: {path} is a directory, not a .blend file")
    try:
        with open(path, "rb") as f:
            head = f.read(8)
    except OSError as e:
        raise CliError(EXIT_FILE, f"drt: error: cannot read {path}: {e.strerror}") from None
    if not any(head.startswith(m) for m in _BLEND_MAGICS):
        raise CliError(EXIT_FILE, f"drt: error: {path} is not a .blend file")


def run_package(args) -> int:
    from . import packaging
    if args.output_dir and os.path.exists(args.output_dir) and not os.path.isdir(args.output_dir):
        raise CliError(EXIT_USAGE, f"drt: error: {args.output_dir} is not a folder")
    if args.platforms:
        try:
            listed = packaging.manifest_platforms()
        except packaging.PackagingError as e:
            raise CliError(EXIT_RENDER, f"drt: error: package failed: {e}") from None
        unknown = [p for p in args.platforms if p not in listed]
        if unknown:
            raise CliError(EXIT_USAGE, f"drt: error: unknown platform {', '.join(unknown)}; "
                                       f"the manifest lists {', '.join(listed)}")
    try:
        zip_paths = packaging.package(args.output_dir, platforms=args.platforms)
    except packaging.PackagingError as e:
        raise CliError(EXIT_RENDER, f"drt: error: package failed: {e}") from None
    except Exception as e:
        raise CliError(EXIT_RENDER, f"drt: error: package failed: {type(e).__name__}: {e}") \
            from None
    for zip_path in zip_paths:
        print(zip_path)
    return EXIT_OK


def set_still_format(settings, file_format: str) -> None:
    """Point the scene's output settings (in memory only; the file on disk is not
    written) at a still image format. Since Blender 5.0 a file whose output is a video
    has `media_type` VIDEO, which offers only FFMPEG as file format (and MULTI_LAYER_IMAGE
    only multilayer EXR): switch it to IMAGE first."""
    if getattr(settings, "media_type", "IMAGE") != "IMAGE":
        settings.media_type = "IMAGE"
    settings.file_format = file_format
    if file_format == "OPEN_EXR":
        settings.color_depth = "32"


def run(argv) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "package":
        return run_package(args)
    if getattr(args, "run", None) is not None:      # compare, converge
        return args.run(args)
    ext = os.path.splitext(args.output)[1].lower()
    if ext not in FORMATS:
        raise CliError(EXIT_USAGE, f"drt: error: unsupported output extension {ext or '(none)'!r};"
                                   f" use one of {', '.join(sorted(FORMATS))}")
    if args.samples is not None and not (1 <= args.samples <= 1 << 24):
        raise CliError(EXIT_USAGE, "drt: error: --samples must be between 1 and 16777216")
    if args.seed is not None and args.seed < 0:
        raise CliError(EXIT_USAGE, "drt: error: --seed must be >= 0")
    check_blend(args.blend)
    out_dir = os.path.dirname(os.path.abspath(args.output))
    try:
        os.makedirs(out_dir, exist_ok=True)      # like Blender's own output paths
    except OSError as e:
        raise CliError(EXIT_USAGE, f"drt: error: cannot create the output folder {out_dir}: "
                                   f"{e.strerror}") from None

    import bpy

    from . import register
    from . import render_engine
    register()
    try:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(args.blend), load_ui=False)
    except RuntimeError as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else "unreadable file"
        raise CliError(EXIT_FILE, f"drt: error: cannot open {args.blend}: {first}") from None
    scene = bpy.context.scene
    if args.frame is not None:
        scene.frame_set(args.frame)
    scene.render.engine = args.engine
    if args.samples is not None:
        scene.drt.samples = args.samples
        if args.engine == "CYCLES":
            scene.cycles.samples = args.samples
    if args.seed is not None:
        scene.drt.seed = args.seed
        if args.engine == "CYCLES":
            scene.cycles.seed = args.seed
    if args.percentage is not None:
        if not 1 <= args.percentage <= 10000:
            raise CliError(EXIT_USAGE, "drt: error: --percentage must be in 1..10000")
        scene.render.resolution_percentage = args.percentage
    if scene.camera is None:
        raise CliError(EXIT_RENDER, "drt: error: render failed: the scene has no active camera")
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - t0
    if args.engine == "DRT" and not render_engine.last_render.get("ok"):
        raise CliError(EXIT_RENDER, f"drt: error: render failed: "
                                    f"{render_engine.last_render.get('error') or 'unknown error'}")
    set_still_format(scene.render.image_settings, FORMATS[ext])
    image = bpy.data.images.get("Render Result")
    if image is None:
        raise CliError(EXIT_RENDER, "drt: error: render failed: Blender produced no image")
    try:
        image.save_render(filepath=os.path.abspath(args.output), scene=scene)
    except RuntimeError as e:
        raise CliError(EXIT_RENDER, f"drt: error: cannot write {args.output}: {e}") from None
    w = int(scene.render.resolution_x * scene.render.resolution_percentage / 100)
    h = int(scene.render.resolution_y * scene.render.resolution_percentage / 100)
    samples = scene.drt.samples if args.engine == "DRT" else scene.cycles.samples
    print(f"drt: wrote {args.output} ({w}x{h}, {samples} samples, {args.engine}, "
          f"{seconds:.1f} s)")
    return EXIT_OK


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        return run(argv)
    except CliError as e:
        print(str(e), file=sys.stderr)
        return e.code
    except KeyboardInterrupt:
        print("drt: error: interrupted", file=sys.stderr)
        return EXIT_RENDER
    except Exception as e:  # the promise: one clear line, never a bare traceback
        print(f"drt: error: render failed: {type(e).__name__}: {e}", file=sys.stderr)
        return EXIT_RENDER
