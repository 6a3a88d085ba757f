"""The vocabulary the file-settings table (export.file_settings) is written in: a row
(`FileSetting`), the kinds of what DRT does with a setting, the builders of rows, and
the phrases and conditions several rows share."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

READ = "read"              # DRT renders with the file's value, as Cycles does
OWN = "own"                # DRT has a setting of its own (scene.drt) in its panels
BLENDER = "blender"        # Blender applies it, to DRT's result or to the depsgraph
IGNORED = "ignored"        # not honoured: a warning when the file changes it
NO_EFFECT = "no effect"    # speed, memory, the viewport, baking: not the F12 image
KINDS = (READ, OWN, BLENDER, IGNORED, NO_EFFECT)

NOISE_ONLY = "only the noise differs, not the image it converges to"


@dataclass(frozen=True)
class FileSetting:
    path: str                       # from "scene." or "view_layer."
    label: str                      # where it is in Blender's interface
    kind: str
    how: str                        # what DRT does (docs and warnings)
    quiet: object = None            # IGNORED/OWN: value(s) that need no warning
    drt: Optional[str] = None       # OWN: DRT's own setting, a path from "scene."
    when: Optional[tuple] = None    # (path, values): matters only when path is in values
    warns: bool = True              # False: covered by another row's warning
    group: Optional[str] = None     # rows warned together in one message

    def __post_init__(self):
        assert self.kind in KINDS, self.kind


def _s(path, label, kind, how, **kw):
    return FileSetting(path, label, kind, how, **kw)


def _own(name, label, drt, drt_label, default, **kw):
    return _s(f"scene.cycles.{name}", label, OWN, f"DRT renders with its own {drt_label}",
              quiet=default, drt=f"scene.drt.{drt}", **kw)


def _ignored(path, label, how, quiet, **kw):
    return _s(path, label, IGNORED, how, quiet=quiet, **kw)


def _part_of(parent, names, prefix="scene.cycles"):
    """Rows that only matter with `parent` on, which warns for them."""
    return [_s(f"{prefix}.{name}", f"{parent} > {name}", IGNORED,
               f"part of {parent} (warned there)", warns=False) for name in names]


def _no_effect(names, how, prefix="scene.cycles"):
    return [_s(f"{prefix}.{name}", name, NO_EFFECT, how) for name in names]


_NO_VOLUMES = "DRT renders every volume anyway, Volume objects' grids at their full resolution"
_NULL_SCATTERING = ("DRT renders volumes without ray marching steps: homogeneous ones exactly, "
                    "ones that vary in space (a texture on Density) by null scattering, "
                    "unbiased as Cycles' default")
_SIMPLIFY = ("scene.render.use_simplify", (True,))
_ADAPTIVE = ("scene.cycles.use_adaptive_sampling", (True,))
WRITTEN_PASSES = ("Combined, Depth, Mist, Normal, Position, UV, Vector, Object Index, "
                  "Material Index, Environment, Ambient Occlusion, Shadow Catcher, "
                  "Cryptomatte, Denoising Data and DRT Noise")
_PASSES_HOW = f"not written (DRT writes {WRITTEN_PASSES})"
