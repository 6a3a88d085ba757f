"""Which frames a batch job renders, and the file each one goes to (no bpy here).

Frame lists: `7`, `1-240`, `1..240` (Flamenco's spelling), `1-240:2` (every 2nd frame),
and comma-separated mixes such as `1,5,10-20`; a frame listed twice renders once, in the
order first given. Negative frames are allowed (`-5--1`), as in Blender.

Output paths follow Blender's `####` convention: the rightmost run of `#` becomes the
frame number, zero-padded to the run's length (`shot_####.png` -> `shot_0007.png`).
"""
from __future__ import annotations

import os
import re

_ITEM = re.compile(r"^\s*(-?\d+)\s*(?:(?:\.\.|-)\s*(-?\d+)\s*(?::\s*(\d+)\s*)?)?$")
MAX_FRAMES = 1_048_574     # Blender's MAXFRAME: no job is longer than the timeline


class FrameSpecError(ValueError):
    pass


def parse_frames(spec: str) -> list[int]:
    """The frames of a frame list such as `1,5,10-20` (see the module docstring)."""
    frames, seen = [], set()
    if not spec.strip():
        raise FrameSpecError("empty frame list")
    for item in spec.split(","):
        m = _ITEM.match(item)
        if m is None:
            raise FrameSpecError(f"cannot read {item.strip()!r} (use e.g. 7, 1-240, 1-240:2 "
                                 "or 1,5,10-20)")
        first = int(m.group(1))
        last = first if m.group(2) is None else int(m.group(2))
        step = int(m.group(3) or 1)
        if last < first:
            raise FrameSpecError(f"range {item.strip()!r} ends before it starts")
        if step < 1:
            raise FrameSpecError(f"step of {item.strip()!r} must be at least 1")
        if len(frames) + (last - first) // step + 1 > MAX_FRAMES:
            raise FrameSpecError(f"more than {MAX_FRAMES} frames")
        for f in range(first, last + 1, step):
            if f not in seen:
                seen.add(f)
                frames.append(f)
    return frames


def scene_frames(frame_start: int, frame_end: int, frame_step: int = 1) -> list[int]:
    """The scene's animation range, as Blender's `-a` renders it."""
    return list(range(frame_start, frame_end + 1, max(1, frame_step)))


def has_placeholder(path: str) -> bool:
    return "#" in path


def fill_placeholder(pattern: str, frame: int) -> str:
    """`pattern` with its rightmost run of `#` replaced by the zero-padded frame."""
    end = pattern.rfind("#")
    if end < 0:
        return pattern
    start = end
    while start > 0 and pattern[start - 1] == "#":
        start -= 1
    digits = end - start + 1
    number = f"-{abs(frame):0{max(digits - 1, 1)}d}" if frame < 0 else f"{frame:0{digits}d}"
    return pattern[:start] + number + pattern[end + 1:]


def split_extension(path: str) -> tuple[str, str]:
    """(stem, extension) of an output path; a `#` run is never part of an extension."""
    stem, ext = os.path.splitext(path)
    if "#" in ext or os.sep in ext:
        return path, ""
    return stem, ext


def output_pattern(output: str, extension: str, many_frames: bool) -> str:
    """The `#` pattern of `-o OUTPUT` for files of `extension` (with its dot).

    A folder (an existing one, or a path ending in a separator) gets `####` + extension
    inside it; a path without an extension gets the extension; several frames and no `#`
    get `####` before the extension (Blender's `-o /tmp/out` gives /tmp/out0001.png)."""
    if output.endswith(("/", os.sep)) or os.path.isdir(output):
        return os.path.join(output, "####" + extension)
    stem, ext = split_extension(output)
    if not ext:
        stem, ext = output, extension
    if many_frames and not has_placeholder(stem):
        stem += "####"
    return stem + ext
