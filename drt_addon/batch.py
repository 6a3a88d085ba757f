"""The headless batch renderer on the bpy module.

    python -m drt_addon render SCENE.blend [-o OUT] [--frame F | --frames 1-240 | -a]
                                           [--skip-existing] [overrides] [Dask options]
    python -m drt_addon package [-o DIR] [--platform P] [--kernel-tier T]  (extension zips;
                                                           see docs/install.md)
    python -m drt_addon compare A.exr B.exr [-o DIFF.png]  (compare_images.py)
    python -m drt_addon converge SCENE.blend [-o DIR] ...  (converge.py; docs/convergence.md)
    python -m drt_addon compile [SCENE.blend ...]          (precompile.py: the kernels'
                                                           cache, before a first render)

One machine renders the frames one after the other through Blender's render pipeline
(the DRT RenderEngine); `--workers N` or `--cluster ADDRESS` hands them to Dask
(drt_addon.dask_jobs). docs/batch.md is the user's guide.

Exit codes: 0 success, 2 bad arguments, 3 file missing or not a .blend, 4 render or package
failed, 5 the Dask cluster could not be started or reached.
Errors go to stderr as one line; no traceback reaches the user.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

from . import frames as frame_lists
from .batch_report import FrameResult, Progress, summary_table
from .frame_output import FORMATS, choose_format, save_render_result, set_still_format
from .overrides import Overrides, apply_overrides

EXIT_OK, EXIT_USAGE, EXIT_FILE, EXIT_RENDER, EXIT_CLUSTER = 0, 2, 3, 4, 5
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
    r = sub.add_parser("render", help="render frames of a .blend with DRT")
    r.add_argument("blend", help="the .blend file")
    r.add_argument("-o", "--output",
                   help="output file, with Blender's # frame placeholders (shot_####.png), "
                        "or a folder (ending in /); the format follows the extension "
                        f"({', '.join(sorted(FORMATS))}), else the file's own. PNG/JPEG/"
                        "TIFF use the scene's colour management, EXR is scene-linear. "
                        "Default: the output path and format set in the .blend")
    which = r.add_mutually_exclusive_group()
    which.add_argument("--frame", type=int, help="frame to render (default: the current frame)")
    which.add_argument("--frames", metavar="LIST",
                       help="frames to render: 1-240, 1,5,10-20, 1-240:2 or 1..240")
    which.add_argument("-a", "--animation", action="store_true",
                       help="render the scene's frame range (Start..End, Step)")
    r.add_argument("--skip-existing", action="store_true",
                   help="leave frames whose file already exists (resume a job)")
    r.add_argument("--no-progress", action="store_true", help="no progress bars on stderr")
    o = r.add_argument_group("overrides (in memory; the .blend on disk is not changed)")
    o.add_argument("--samples", type=int, help="samples per pixel (default: the scene's)")
    o.add_argument("--seed", type=int, help="random seed (default: the scene's)")
    o.add_argument("--percentage", type=int,
                   help="resolution percentage, 1..10000 (default: the scene's)")
    o.add_argument("--noise-threshold", type=float, metavar="T",
                   help="turn adaptive sampling on with this noise threshold")
    o.add_argument("--min-samples", type=int, metavar="N",
                   help="adaptive sampling's minimum samples per pixel")
    o.add_argument("--time-limit", type=float, metavar="SECONDS",
                   help="stop sampling a frame after this long (0: no limit)")
    o.add_argument("--engine", default="DRT", choices=("DRT", "CYCLES"),
                   help="render engine (CYCLES for reference images)")
    d = r.add_argument_group("Dask (docs/batch.md)")
    where = d.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N",
                       help="start a local Dask cluster of N worker processes")
    where.add_argument("--cluster", metavar="ADDRESS",
                       help="send the frames to this Dask scheduler (tcp://HOST:PORT)")
    d.add_argument("--sample-batches", type=int, default=1, metavar="K",
                   help="split each frame into K sample ranges rendered on different "
                        "workers and merged exactly")
    d.add_argument("--retries", type=int, default=2, metavar="R",
                   help="times a failed task is tried again (default: 2)")
    pk = sub.add_parser("package", help="build and validate the Blender extension zips, one "
                                        "per platform (downloads the pinned wheels into "
                                        "wheels/); prints one zip path per line")
    pk.add_argument("-o", "--output-dir", help="folder for the zips (default: build/)")
    pk.add_argument("--platform", action="append", dest="platforms", metavar="PLATFORM",
                    help="build only this platform's zip (one of the manifest's platforms, "
                         "e.g. linux-x64; repeatable; default: every platform)")
    pk.add_argument("--kernel-tier", action="append", dest="kernel_tiers",
                    choices=("x86-64-v3", "generic"),
                    help="CPU tier whose compiled kernels this machine's zip ships "
                         "(repeatable; default: both)")
    pk.add_argument("--kernel-scene", action="append", dest="kernel_scenes", metavar="NAME",
                    help="sample scene (sample_blends/NAME.blend) whose render compiles "
                         "the shipped kernels (repeatable; default: compile's scenes)")
    pk.add_argument("--no-kernels", action="store_true",
                    help="ship no compiled kernels (the first render compiles them)")
    from . import compare_images, converge, precompile
    for command in (compare_images, converge, precompile):
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
        zip_paths = packaging.package(
            args.output_dir, platforms=args.platforms,
            kernel_tiers=() if args.no_kernels else tuple(args.kernel_tiers or ()) or None,
            kernel_scenes=tuple(args.kernel_scenes or ()) or None)
    except packaging.PackagingError as e:
        raise CliError(EXIT_RENDER, f"drt: error: package failed: {e}") from None
    except Exception as e:
        raise CliError(EXIT_RENDER, f"drt: error: package failed: {type(e).__name__}: {e}") \
            from None
    for zip_path in zip_paths:
        print(zip_path)
    return EXIT_OK


def _check_arguments(args, overrides: Overrides) -> None:
    """Everything that can be refused before the file is opened (exit 2)."""
    problems = overrides.problems()
    if problems:
        raise CliError(EXIT_USAGE, f"drt: error: {problems[0]}")
    if args.output and not args.output.endswith(("/", os.sep)) \
            and not os.path.isdir(args.output):
        ext = frame_lists.split_extension(args.output)[1].lower()
        if ext and ext not in FORMATS:
            raise CliError(EXIT_USAGE, f"drt: error: unsupported output extension {ext!r}; "
                                       f"use one of {', '.join(sorted(FORMATS))}, or none "
                                       "for the file's own format")
    if args.frames is not None:
        try:
            frame_lists.parse_frames(args.frames)
        except frame_lists.FrameSpecError as e:
            raise CliError(EXIT_USAGE, f"drt: error: --frames: {e}") from None
    if args.workers is not None and args.workers < 1:
        raise CliError(EXIT_USAGE, "drt: error: --workers must be at least 1")
    if args.sample_batches < 1:
        raise CliError(EXIT_USAGE, "drt: error: --sample-batches must be at least 1")
    if args.retries < 0:
        raise CliError(EXIT_USAGE, "drt: error: --retries must be >= 0")
    on_dask = args.workers is not None or args.cluster is not None
    if args.sample_batches > 1 and not on_dask:
        raise CliError(EXIT_USAGE, "drt: error: --sample-batches needs --workers or --cluster")
    if on_dask and overrides.engine != "DRT":
        raise CliError(EXIT_USAGE, "drt: error: --workers and --cluster render with DRT only")


def open_blend(bpy, path: str) -> None:
    try:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else "unreadable file"
        first = first.removeprefix("Error: ")       # Blender's report level
        raise CliError(EXIT_FILE, f"drt: error: cannot open {path}: {first}") from None


def say_warnings(progress, warnings) -> None:
    """The render's warnings (the RenderEngine's reports) on stderr, one line each, each
    once per job."""
    for message in warnings:
        if message not in progress.warned:
            progress.warned.add(message)
            progress.say(f"drt: warning: {message.removeprefix('DRT: ')}", file=sys.stderr)


def _frame_list(args, scene) -> list[int]:
    if args.frames is not None:
        return frame_lists.parse_frames(args.frames)
    if args.animation:
        return frame_lists.scene_frames(scene.frame_start, scene.frame_end, scene.frame_step)
    return [scene.frame_current if args.frame is None else args.frame]


def plan_outputs(bpy, scene, output: str | None, frames: list[int]):
    """[(frame, final path)] and the output settings set on the scene (in memory): `-o`
    with its extension (or the file's own format), else the .blend's output path and
    format. Returns (jobs, note); note says why the file's own format was not used."""
    r = scene.render
    if output is None:
        fmt, _, note = choose_format(r.image_settings, None)
        set_still_format(r.image_settings, fmt)
        return [(f, r.frame_path(frame=f)) for f in frames], note
    if output.startswith("//"):
        output = bpy.path.abspath(output)           # relative to the .blend, as Blender
    folder = output.endswith(("/", os.sep)) or os.path.isdir(output)
    ext = "" if folder else frame_lists.split_extension(output)[1]
    fmt, ext, note = choose_format(r.image_settings, ext or None)
    set_still_format(r.image_settings, fmt)
    pattern = frame_lists.output_pattern(output, ext, len(frames) > 1)
    pattern = os.path.join(os.path.abspath(os.path.dirname(pattern)), os.path.basename(pattern))
    return [(f, frame_lists.fill_placeholder(pattern, f)) for f in frames], note


def _make_folders(jobs) -> None:
    for folder in sorted({os.path.dirname(path) for _, path in jobs}):
        try:
            os.makedirs(folder, exist_ok=True)      # like Blender's own output paths
        except OSError as e:
            raise CliError(EXIT_USAGE, f"drt: error: cannot create the output folder "
                                       f"{folder}: {e.strerror}") from None


def _frame_failed(frame: int, error: str) -> CliError:
    """The one line of a frame whose render failed (the engine's message without its
    'DRT: render failed:' prefix)."""
    reason = error.removeprefix("DRT: ").removeprefix("render failed: ")
    return CliError(EXIT_RENDER, f"drt: error: render of frame {frame} failed: {reason}")


def render_frame_here(bpy, scene, frame: int, path: str, overrides, progress) -> FrameResult:
    """One frame through Blender's render pipeline, written to `path` atomically."""
    from . import render_engine
    scene.frame_set(frame)
    drt = overrides.engine == "DRT"
    asked = scene.drt.samples if drt else scene.cycles.samples
    progress.start_frame(f"frame {frame}", asked)
    t0 = time.perf_counter()
    failed = None
    try:
        bpy.ops.render.render(write_still=False)
    except RuntimeError as e:   # an engine's error report (DRT's is in last_render too)
        failed = str(e).strip().removeprefix("Error: ") or "unknown"
    seconds = time.perf_counter() - t0
    if drt:
        say_warnings(progress, render_engine.last_render.get("warnings") or ())
        if not render_engine.last_render.get("ok"):
            failed = render_engine.last_render.get("error") or failed or "unknown"
    if failed:
        raise _frame_failed(frame, failed)
    try:
        save_render_result(bpy, scene, path)
    except (RuntimeError, OSError) as e:
        raise CliError(EXIT_RENDER, f"drt: error: cannot write {path}: {e}") from None
    stats = render_engine.last_render.get("stats") if drt else None
    result = FrameResult(frame, path, seconds=seconds,
                         samples=stats.samples_done if stats else asked,
                         paths=stats.paths if stats else 0)
    w = scene.render.resolution_x * scene.render.resolution_percentage // 100
    h = scene.render.resolution_y * scene.render.resolution_percentage // 100
    progress.say(f"drt: wrote {path} ({w}x{h}, {result.samples} samples, "
                 f"{overrides.engine}, {seconds:.1f} s)")
    return result


def _render_here(bpy, scene, jobs, overrides, progress) -> list[FrameResult]:
    from . import render_engine
    listener = progress.samples_done
    render_engine.progress_listeners.append(listener)
    render_engine.compile_listeners.append(progress.compiling)
    try:
        results = []
        for frame, path in jobs:
            results.append(render_frame_here(bpy, scene, frame, path, overrides, progress))
            progress.frame_done()
        return results
    finally:
        render_engine.progress_listeners.remove(listener)
        render_engine.compile_listeners.remove(progress.compiling)


def run_render(args) -> int:
    overrides = Overrides.from_args(args)
    _check_arguments(args, overrides)
    check_blend(args.blend)

    import bpy

    from . import register
    register()
    open_blend(bpy, args.blend)
    scene = bpy.context.scene
    for message in apply_overrides(scene, overrides):
        print(f"drt: warning: {message}", file=sys.stderr)
    frames = _frame_list(args, scene)
    jobs, note = plan_outputs(bpy, scene, args.output, frames)
    if note:
        print(f"drt: note: {note}", file=sys.stderr)
    _make_folders(jobs)
    if scene.camera is None:
        raise CliError(EXIT_RENDER, "drt: error: render failed: the scene has no active camera")
    skipped = [FrameResult(f, p, status="skipped") for f, p in jobs
               if args.skip_existing and os.path.exists(p)]
    todo = [(f, p) for f, p in jobs if not (args.skip_existing and os.path.exists(p))]
    progress = Progress(len(todo), enabled=not args.no_progress and bool(todo))
    ok = False
    try:
        if not todo:
            rendered = []
        elif args.workers is not None or args.cluster is not None:
            from .dask_jobs import ClusterError, FrameRenderError, render_on_dask
            try:
                rendered = render_on_dask(bpy, scene, args, overrides, todo, progress)
            except ClusterError as e:
                raise CliError(EXIT_CLUSTER, f"drt: error: {e}") from None
            except FrameRenderError as e:
                raise CliError(EXIT_RENDER, f"drt: error: a frame failed on the cluster "
                                            f"after {args.retries} retries: {e}") from None
        else:
            rendered = _render_here(bpy, scene, todo, overrides, progress)
        ok = True
    finally:
        progress.close(ok)
    order = {f: i for i, (f, _) in enumerate(jobs)}
    results = sorted(skipped + rendered, key=lambda r: order[r.frame])
    print(summary_table(results))
    return EXIT_OK


def run(argv) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "package":
        return run_package(args)
    if getattr(args, "run", None) is not None:      # compare, converge, compile
        return args.run(args)
    return run_render(args)


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
