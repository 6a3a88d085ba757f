"""Cycles' light passes and light groups as Blender's render result holds them: their
names (Blender 5 spells them out, 4.x abbreviates), when the view layer asks for them,
and their images from the film (engine.light_passes).

- Diffuse, Glossy and Transmission Direct / Indirect: the light whose path first
  scattered off a lobe of that kind, divided by that kind's Color (0 where the Color is
  0), as Cycles' film divides them; Direct is next-event estimation at the first
  surface and the light its bounce finds, Indirect the rest.
- Diffuse, Glossy and Transmission Color: what the first surface's lobes of that kind
  weigh at the view (their albedo estimates).
- Volume Direct / Indirect: the light of paths that first scattered in a medium.
- Emission: what camera rays see emitted (lamps, emissive surfaces and media).
- Combined_<group>: the light of the lamps, emissive objects and world of one of the
  view layer's light groups (View Layer > Light Groups; Object and World > Light Group).
Combined = (DiffDir + DiffInd) DiffCol + (GlossDir + GlossInd) GlossCol + (TransDir +
TransInd) TransCol + VolumeDir + VolumeInd + Emission + Environment, per pixel, as in
Cycles (docs/passes.md).
"""
from __future__ import annotations

from importlib import import_module

import bpy
import numpy as np

FIVE = bpy.app.version >= (5, 0, 0)


def _vl(prop):
    return lambda vl: bool(getattr(vl, prop, False))


def _cycles(prop):
    return lambda vl: bool(getattr(getattr(vl, "cycles", None), prop, False))


def _table() -> dict:
    """Blender's name: (engine.light_passes slot, its Color slot or None, enabled)."""
    table = {}
    for kind, short, long in (("diffuse", "Diff", "Diffuse"), ("glossy", "Gloss", "Glossy"),
                              ("transmission", "Trans", "Transmission")):
        for part, abbr in (("direct", "Dir"), ("indirect", "Ind")):
            name = f"{long} {part.title()}" if FIVE else f"{short}{abbr}"
            table[name] = (f"{kind}_{part}", f"{kind}_color", _vl(f"use_pass_{kind}_{part}"))
        table[f"{long} Color" if FIVE else f"{short}Col"] = (
            f"{kind}_color", None, _vl(f"use_pass_{kind}_color"))
    for part, abbr in (("direct", "Dir"), ("indirect", "Ind")):
        table[f"Volume {part.title()}" if FIVE else f"Volume{abbr}"] = (
            f"volume_{part}", None, _cycles(f"use_pass_volume_{part}"))
    table["Emission" if FIVE else "Emit"] = ("emission", None, _vl("use_pass_emit"))
    return table


LIGHT_PASSES = _table()


def enabled(view_layer) -> list:
    """The light passes the view layer asks for, by Blender's names."""
    return [name for name, (_, _, on) in LIGHT_PASSES.items() if on(view_layer)]


def splits(view_layer) -> bool:
    """Whether the path tracer splits its light: a light pass or Environment is asked
    for (Environment is the path tracer's too, every sample, as Cycles writes it)."""
    return bool(enabled(view_layer)) or bool(getattr(view_layer, "use_pass_environment",
                                                     False))


def environment(film):
    """Cycles' Environment pass, (h, w, 3) row 0 at the top: the world and sun discs
    camera rays see, through transparent surfaces, on a transparent film too."""
    from .engine_link import engine
    slots = import_module(engine.__name__ + ".light_passes").images(film, ())
    if "environment" not in slots:          # a render that kept no light passes
        return np.zeros((film.height, film.width, 3))
    return slots["environment"]


def group_passes(view_layer) -> list:
    """Combined_<name> of each of the view layer's light groups, as Cycles names them."""
    from .export import light_groups
    return ["Combined_" + name for name in light_groups(view_layer)]


def images(film, scene_groups: tuple, names) -> dict:
    """{Blender pass name: (h, w, 3) image, row 0 at the top} for `names` (light passes
    and Combined_<group> passes)."""
    from .engine_link import engine
    split = import_module(engine.__name__ + ".light_passes")
    slots = split.images(film, tuple(scene_groups))
    out = {}
    for name in names:
        if not slots:                       # a render that kept no light passes
            out[name] = np.zeros((film.height, film.width, 3))
            continue
        if name.startswith("Combined_"):
            out[name] = slots["group:" + name[len("Combined_"):]]
            continue
        slot, colour, _ = LIGHT_PASSES[name]
        out[name] = (split.divide_by_colour(slots[slot], slots[colour]) if colour
                     else slots[slot])
    return out
