"""Cycles' shadow catcher in Blender: the Shadow Catcher pass (View Layer > Passes >
Light > Shadow Catcher, Cycles' `use_pass_shadow_catcher`) and the Combined pass Cycles'
film makes of a scene with shadow catcher objects (engine.shadow_catcher says how).
The export reads Object > Visibility > Shadow Catcher of meshes and lamps."""
from __future__ import annotations

from importlib import import_module

import numpy as np

PASS = "Shadow Catcher"


def _engine():
    from .engine_link import engine
    return import_module(engine.__name__ + ".shadow_catcher")


def pass_on(view_layer) -> bool:
    """Whether the view layer asks for the Shadow Catcher pass (Cycles' property)."""
    cycles = getattr(view_layer, "cycles", None) if view_layer is not None else None
    return bool(getattr(cycles, "use_pass_shadow_catcher", False))


def combined(ctx, film, view_layer) -> tuple[np.ndarray, np.ndarray]:
    """The Combined pass (colour (h, w, 3), alpha (h, w)), row 0 at the top: the film's
    own in a scene without catchers; else Cycles' matte, with the shadow laid in when
    the Shadow Catcher pass is off (view_layer None: the viewport, where it is)."""
    return of_film(film, ctx.catcher is not None, pass_on(view_layer),
                   ctx.scene.film_transparent)


def of_film(film, has_catcher: bool, on: bool, transparent: bool):
    """The Combined pass of a film (see `combined`): has_catcher, whether its scene has
    catchers (its render a RenderContext.catcher); on, the Shadow Catcher pass;
    transparent, Film > Transparent."""
    rgb, alpha = film.mean(), film.mean_alpha()
    if not has_catcher:
        return rgb, alpha
    sc = _engine()
    return sc.combined(rgb, alpha, sc.parts(film), on, not transparent)


def shadow_pass(ctx, film) -> np.ndarray:
    """The Shadow Catcher pass (h, w, 3), row 0 at the top: 1 where no catcher is seen."""
    if ctx.catcher is None:
        return np.ones((film.height, film.width, 3))
    sc = _engine()
    return sc.shadow_pass(film.mean(), film.mean_alpha(), sc.parts(film))
