"""What a batch job tells the user: progress bars on stderr (one for the job's frames,
one for the current frame's samples, tqdm) and a summary table on stdout at the end."""
from __future__ import annotations

import sys
from dataclasses import dataclass


@dataclass
class FrameResult:
    frame: int
    path: str
    status: str = "rendered"        # rendered | skipped
    seconds: float = 0.0
    samples: int = 0
    paths: int = 0                  # camera paths traced (0: not known, e.g. Cycles)
    where: str = ""                 # the worker(s) that rendered it, on a Dask cluster

    @property
    def paths_per_second(self) -> float:
        return self.paths / self.seconds if self.seconds > 0 and self.paths else 0.0


class Progress:
    """tqdm bars on stderr: the job's frames, and the samples of the frame rendering.
    Messages printed through `say` go to stdout above the bars."""

    def __init__(self, n_frames: int, enabled: bool = True):
        from tqdm import tqdm
        self._tqdm = tqdm
        self.enabled = enabled
        self.frames = tqdm(total=n_frames, desc="frames", unit="frame", file=sys.stderr,
                           position=0, disable=not enabled, dynamic_ncols=True)
        self.samples = None
        self._label = None
        self.warned = set()                 # warnings said (each once per job)

    def say(self, message: str, file=None) -> None:
        self._tqdm.write(message, file=file or sys.stdout)

    def start_frame(self, label: str, total_samples: int, unit: str = "sample") -> None:
        """A new second bar, e.g. ("frame 12", 128 samples)."""
        self.end_frame()
        self.samples = self._tqdm(total=total_samples, desc=label, unit=unit,
                                  file=sys.stderr, position=1, leave=False,
                                  disable=not self.enabled, dynamic_ncols=True)
        self._label = None          # the bar's own label while it says "compiling"

    def compiling(self, done: int, total: int) -> None:
        """The frame's bar while a first render compiles its kernels: what is compiled,
        and no sample rate (the first samples' rate is timed from when they start)."""
        bar = self.samples
        if bar is None or bar.disable:
            return
        from .render_engine import compile_line
        if self._label is None:
            self._label = bar.desc
        bar.set_description_str(f"{self._label}: {compile_line(done, total)}")

    def samples_done(self, done: int, total: int | None = None) -> None:
        bar = self.samples
        if bar is None:
            return
        if self._label is not None:            # the compile is over: time samples anew
            bar.set_description_str(self._label)
            self._label = None
            bar.reset(total=total or bar.total)
            bar.initial = bar.n = bar.last_print_n = done    # the rate counts from here
            bar.refresh()
            return
        if total is not None and total != bar.total:
            bar.total = total
        bar.update(max(0, done - bar.n))

    def end_frame(self) -> None:
        if self.samples is not None:
            self.samples.close()
            self.samples = None

    def frame_done(self) -> None:
        self.frames.update(1)

    def close(self, ok: bool = True) -> None:
        """Close the bars; after a failure they are erased, so the error is the one line
        left on stderr."""
        self.end_frame()
        if not ok:
            self.frames.leave = False
        self.frames.close()


def summary_table(results: list[FrameResult]) -> str:
    """One row per frame: frame, seconds, samples, paths per second, file."""
    show_where = any(r.where for r in results)
    head = ["frame", "seconds", "samples", "Mpaths/s"] + (["worker"] if show_where else []) \
        + ["file"]
    rows = []
    for r in results:
        if r.status == "skipped":
            cells = [str(r.frame), "-", "-", "-"] + (["-"] if show_where else []) + \
                    [f"{r.path} (exists, skipped)"]
        else:
            rate = f"{r.paths_per_second / 1e6:.3f}" if r.paths_per_second else "-"
            cells = [str(r.frame), f"{r.seconds:.2f}", str(r.samples), rate] + \
                    ([r.where] if show_where else []) + [r.path]
        rows.append(cells)
    rendered = [r for r in results if r.status == "rendered"]
    total = sum(r.seconds for r in rendered)
    widths = [max(len(c[i]) for c in [head] + rows) for i in range(len(head))]
    lines = ["  ".join(c.rjust(w) if i < len(head) - 1 else c
                       for i, (c, w) in enumerate(zip(cells, widths)))
             for cells in [head] + rows]
    lines.append(f"{len(rendered)} frame(s) rendered in {total:.1f} s of render time, "
                 f"{len(results) - len(rendered)} skipped")
    return "\n".join(lines)
