"""Warnings for the file's render settings DRT does not honour, from the table in
export.file_settings: one per setting the file sets to a value DRT does not render (a
setting DRT has its own version of: when the file's differs from both Blender's default
and DRT's), the passes DRT does not write in one warning."""
from __future__ import annotations

import math

from .file_settings import IGNORED, OWN, SETTINGS, WRITTEN_PASSES, FileSetting

_MISSING = object()


def read(path: str, scene, view_layer):
    """The setting's value, or _MISSING (an older Blender, no Cycles)."""
    root, *names = path.split(".")
    value = {"scene": scene, "view_layer": view_layer}[root]
    for name in names:
        value = getattr(value, name, _MISSING)
        if value is _MISSING or value is None and name != names[-1]:
            return _MISSING
    return value


def _comparable(value):
    """A bpy collection by its length, an ID by its name, everything else as it is."""
    if hasattr(value, "name_full"):
        return value.name_full
    if hasattr(value, "__len__") and not isinstance(value, str):
        return len(value)
    return value


def _equal(a, b) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=1e-7)
        except (TypeError, ValueError):
            return False
    return a == b


def is_quiet(setting: FileSetting, value) -> bool:
    quiet = setting.quiet if isinstance(setting.quiet, tuple) else (setting.quiet,)
    return any(_equal(_comparable(value), q) for q in quiet)


def show(value) -> str:
    value = _comparable(value)
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _matters(setting: FileSetting, scene, view_layer) -> bool:
    if setting.when is None:
        return True
    path, values = setting.when
    value = read(path, scene, view_layer)
    return value is not _MISSING and any(_equal(value, v) for v in values)


def not_honoured(scene, view_layer) -> list:
    """[(setting, file value, DRT's value or None)] of the warned rows that the file
    sets to something DRT does not render."""
    out = []
    for setting in SETTINGS:
        if setting.kind not in (IGNORED, OWN) or not setting.warns:
            continue
        value = read(setting.path, scene, view_layer)
        if value is _MISSING or is_quiet(setting, value):
            continue
        if not _matters(setting, scene, view_layer):
            continue
        if setting.kind == OWN:
            own = read(setting.drt, scene, view_layer)
            if own is _MISSING or _equal(_comparable(value), _comparable(own)):
                continue
            out.append((setting, value, own))
        else:
            out.append((setting, value, None))
    return out


def check(scene, view_layer, reporter) -> None:
    """One warning per setting of the file DRT does not honour (the passes DRT does not
    write in one warning)."""
    grouped = []
    for setting, value, own in not_honoured(scene, view_layer):
        if setting.group is not None:
            grouped.append(setting.label.rpartition(" > ")[2])
        elif setting.kind == OWN:
            reporter.warn(f"DRT: Cycles' {setting.label} is {show(value)}, not used: "
                          f"{setting.how}, set to {show(own)}", key=setting.path)
        else:
            reporter.warn(f"DRT: {setting.label} is {show(value)}: {setting.how}",
                          key=setting.path)
    if grouped:
        reporter.warn(f"DRT: passes {', '.join(grouped)} are enabled but DRT does not "
                      f"write them (it writes {WRITTEN_PASSES})", key="passes")
