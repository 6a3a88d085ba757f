"""Rendering a batch job on a Dask cluster (`--workers N` starts a local one, `--cluster
tcp://HOST:PORT` uses a running scheduler).

Each task is one frame, or with `--sample-batches K` one of K ranges of sample indices
of a frame. A task gets only the .blend's path, the frame, the command-line overrides
and its sample range: the worker opens the file itself (once per job: it stays open for
the worker's next task), exports the frame through Blender's render pipeline and renders
its sample range with `engine.render`, one engine thread per task (a worker's task slots
are its cores: start workers with `--nthreads 1` per process). It returns the film's
statistics (sample count, sum, sum of squares, alpha sum per pixel).

Every random number is a function of (seed, pixel, sample index), so the films of
disjoint sample ranges merge by addition (`engine.film.Film.merge`) into the film of the
whole range: the merged mean is the sample-weighted mean, and the per-pixel variance
estimate combines exactly too. The client merges a frame's parts as soon as its last part
comes back and writes the frame (temporary name, then rename) before waiting for any
other, so a worker that dies loses at most the tasks it was running, which Dask runs
again elsewhere; a task that raises is retried `--retries` times.
"""
from __future__ import annotations

import logging
import os
import re
import sys
import threading
import time
from dataclasses import dataclass, replace

from . import shadow_catcher
from .batch_report import FrameResult
from .frame_output import frame_rgba, save_pixels
from .overrides import Overrides, apply_overrides

EXPORT_ENGINE = "DRT_EXPORT_ONLY"


class ClusterError(Exception):
    """The cluster could not be started or reached."""


class FrameRenderError(Exception):
    """A frame failed on the cluster after its retries."""


def sample_ranges(samples: int, batches: int) -> list[tuple[int, int]]:
    """`samples` split into at most `batches` contiguous non-empty ranges of nearly equal
    size, in order."""
    batches = max(1, min(batches, samples))
    edges = [samples * i // batches for i in range(batches + 1)]
    return [(a, b) for a, b in zip(edges, edges[1:])]


def connect(workers: int | None = None, address: str | None = None, timeout: float = 20):
    """A dask.distributed Client: on a new local cluster of `workers` processes (one
    thread each, listening on the loopback only), or on the scheduler at `address`.
    Returns (client, cluster or None); close both when done."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as e:
        raise ClusterError(f"Dask is not installed ({e}); pip install dask distributed "
                           "(versions in requirements.txt)") from None
    cluster = None
    try:
        if address is None:
            _keep_malloc_default()
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None,
                                   silence_logs=logging.ERROR)
            address = cluster.scheduler_address
        return Client(address, timeout=timeout), cluster
    except (OSError, TimeoutError, ValueError) as e:
        if cluster is not None:
            cluster.close()
        where = "start a local Dask cluster" if workers else f"reach the scheduler {address}"
        raise ClusterError(f"cannot {where}: {e}") from None


def _keep_malloc_default() -> None:
    """Dask's nannies start workers with MALLOC_TRIM_THRESHOLD_=65536, which makes glibc
    return memory to the system so eagerly that loading the cached compiled kernels
    (LLVM allocates and frees a lot) took 2-3x as long (measured: 10 s instead of 4 s for
    the first frame). Local workers keep glibc's own adaptive setting."""
    import dask
    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}) or {})
    if environ.pop("MALLOC_TRIM_THRESHOLD_", None) is not None:
        dask.config.set({"distributed.nanny.pre-spawn-environ": environ})


# ----------------------------------------------------------------- on the worker
_BPY_LOCK = threading.Lock()        # bpy is one global state per process
_worker_state = {"registered": False, "file": None, "export": None}
_exported: list = []


@dataclass
class FrameExport:
    description: object             # engine.Scene
    settings: object                # engine.RenderSettings
    region: object                  # export.RenderRegion
    crop: bool
    warnings: list


def _export_engine_class(bpy):
    """A RenderEngine that only exports: Blender hands it the render depsgraph (render
    visibility, render subdivision levels, the frame's motion steps), exactly what the
    DRT RenderEngine exports on one machine."""
    from .export import Reporter, export_scene, render_region

    class DRTExportOnly(bpy.types.RenderEngine):
        bl_idname = EXPORT_ENGINE
        bl_label = "DRT (export for Dask)"
        bl_use_preview = False

        def render(self, depsgraph):
            try:
                scene = depsgraph.scene
                region = render_region(scene)
                reporter = Reporter()
                description = export_scene(depsgraph, reporter, region=region,
                                           render_engine=self)
                _exported.append(FrameExport(description, scene.drt.to_engine_settings(),
                                             region, bool(scene.render.use_crop_to_border),
                                             list(reporter.warnings)))
            except Exception as e:   # raised again in the task, outside Blender
                _exported.append(e)

    return DRTExportOnly


def _import_bpy():
    """bpy in a worker. A local cluster's workers are spawned with the client's sys.path,
    which (bpy being imported there) holds Blender's own scripts/modules folder, whose
    `bpy` package shadows the bpy module: drop those entries first (importing bpy adds
    them back)."""
    if "bpy" not in sys.modules:
        sys.path[:] = [p for p in sys.path if not _BLENDER_SCRIPTS.search(p)]
    import bpy
    return bpy


_BLENDER_SCRIPTS = re.compile(r"[\\/]bpy[\\/]\d+\.\d+[\\/]scripts([\\/]|$)")


def _export_frame(blend: str, stamp, frame: int, overrides: Overrides) -> FrameExport:
    bpy = _import_bpy()

    from . import register
    with _BPY_LOCK:
        if not _worker_state["registered"]:
            register()
            bpy.utils.register_class(_export_engine_class(bpy))
            _worker_state["registered"] = True
        key = (blend, stamp, overrides)
        if _worker_state["file"] != key:
            bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
            apply_overrides(bpy.context.scene, overrides)
            _worker_state.update(file=key, export=None)
        cached = _worker_state["export"]
        if cached is not None and cached[0] == frame:
            return cached[1]
        scene = bpy.context.scene
        scene.frame_set(frame)
        scene.render.engine = EXPORT_ENGINE
        _exported.clear()
        try:
            bpy.ops.render.render(write_still=False)
        finally:
            scene.render.engine = overrides.engine
        if not _exported:
            raise RuntimeError(f"frame {frame}: Blender did not run the export")
        if isinstance(_exported[0], Exception):
            raise _exported[0]
        _worker_state["export"] = (frame, _exported[0])
        return _exported[0]


def render_part(blend: str, stamp, frame: int, overrides: Overrides, sample_start: int,
                sample_end: int) -> dict:
    """The task: samples [sample_start, sample_end) of `frame`, as film statistics."""
    from .engine_link import engine
    t0 = time.perf_counter()
    exported = _export_frame(blend, stamp, frame, overrides)
    settings = replace(exported.settings, threads=1)
    ctx = engine.RenderContext(exported.description, settings)
    try:
        film, stats = engine.render(exported.description, settings, context=ctx,
                                    sample_start=sample_start, sample_end=sample_end)
    finally:
        ctx.close()
    # what the frame's Combined needs of a scene with shadow catchers
    catcher = (ctx.catcher is not None,
               shadow_catcher.pass_on(_import_bpy().context.view_layer),
               bool(exported.description.film_transparent))
    try:
        from distributed import get_worker
        where = get_worker().address
    except (ImportError, ValueError):
        where = "local"
    return {"frame": frame, "start": sample_start, "end": sample_end,
            "width": film.width, "height": film.height, "film": film.statistics(),
            "region": exported.region, "crop": exported.crop, "paths": stats.paths,
            "seconds": time.perf_counter() - t0, "worker": where,
            "warnings": exported.warnings, "catcher": catcher}


# ----------------------------------------------------------------- on the client
def merge_parts(parts: list[dict]):
    """The film of a frame from its parts (disjoint sample ranges), merged in sample
    order."""
    from .engine_link import engine
    parts = sorted(parts, key=lambda p: p["start"])
    film = None
    for p in parts:
        f = engine.Film.from_statistics(p["width"], p["height"], p["film"])
        film = f if film is None else film.merge(f)
    return film


def file_stamp(path: str):
    """What makes a worker open the file again: its path, size and modification time."""
    st = os.stat(path)
    return (st.st_size, st.st_mtime_ns)


def render_frames(client, bpy, scene, blend: str, jobs, overrides: Overrides,
                  sample_batches: int = 1, retries: int = 2, progress=None,
                  on_part=None) -> list[FrameResult]:
    """Render [(frame, path)] on the cluster of `client` and write each frame with the
    scene's output settings (the client's open `scene`) as soon as its parts are in.
    on_part(part) is called with every finished task's result."""
    from dask.distributed import as_completed
    blend = os.path.abspath(blend)
    stamp = file_stamp(blend)
    ranges = sample_ranges(scene.drt.samples, sample_batches)
    path_of = dict(jobs)
    futures = [client.submit(render_part, blend, stamp, frame, overrides, a, b,
                             retries=retries, pure=False, key=f"drt-frame{frame}-{a}-{b}-"
                             f"{time.time_ns()}")
               for frame, _ in jobs for a, b in ranges]
    if progress is not None and len(ranges) > 1:
        progress.start_frame("sample batches", len(futures), unit="part")
    parts: dict[int, list] = {}
    results = []
    done_parts = 0
    try:
        for future in as_completed(futures):
            try:
                part = future.result()
            except Exception as e:
                raise FrameRenderError(f"{type(e).__name__}: {e}") from None
            future.release()
            done_parts += 1
            if on_part is not None:
                on_part(part)
            if progress is not None:
                progress.samples_done(done_parts)
            frame = part["frame"]
            parts.setdefault(frame, []).append(part)
            if len(parts[frame]) < len(ranges):
                continue
            results.append(_write_frame(bpy, scene, parts.pop(frame), path_of[frame],
                                        progress))
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
    return results


def _write_frame(bpy, scene, frame_parts, path, progress) -> FrameResult:
    film = merge_parts(frame_parts)
    p0 = frame_parts[0]
    rgb, alpha = shadow_catcher.of_film(film, *p0.get("catcher", (False, False, False)))
    save_pixels(bpy, scene, frame_rgba(rgb, alpha, p0["region"], p0["crop"]), path)
    result = FrameResult(p0["frame"], path, seconds=sum(p["seconds"] for p in frame_parts),
                         samples=int(max(p["end"] for p in frame_parts)),
                         paths=sum(p["paths"] for p in frame_parts),
                         where=",".join(sorted({p["worker"].split("://")[-1]
                                                for p in frame_parts})))
    if progress is not None:
        progress.say(f"drt: wrote {path} ({film.width}x{film.height}, {result.samples} "
                     f"samples, on {result.where})")
        progress.frame_done()
    return result


def render_on_dask(bpy, scene, args, overrides: Overrides, jobs, progress):
    """The batch CLI's Dask path: connect, render, close."""
    client, cluster = connect(args.workers, args.cluster)
    try:
        return render_frames(client, bpy, scene, args.blend, jobs, overrides,
                             args.sample_batches, args.retries, progress)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
