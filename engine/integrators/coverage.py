"""What camera rays leave uncovered: the film's alpha, shared by the integrators.

A camera sample's coverage (alpha) is 1 unless its camera ray, possibly continued through
transparent surfaces (throughput `b`), escapes to the background with Film > Transparent,
or reaches a holdout surface (Cycles' holdout: no colour, and a hole in the alpha whatever
the film setting). In both cases the uncovered part is what got through: 1 - mean(b).
"""
from __future__ import annotations

import numpy as np


def uncovered(b: np.ndarray) -> np.ndarray:
    """Alpha of samples whose camera ray got through with throughput b (n, 3)."""
    return 1.0 - np.clip(b.mean(1), 0.0, 1.0)


def background_is_transparent(ctx, alpha_out, depth) -> bool:
    """Whether rays escaping at this depth show the film's transparent background (camera
    rays, continued only through transparent surfaces, with Film > Transparent): they then
    add no world radiance and write their coverage instead."""
    return alpha_out is not None and depth == 0 and ctx.scene.film_transparent


def end_at_holdouts(ctx, hits, alive, b, path, alpha_out, depth) -> np.ndarray:
    """Camera-ray paths (depth 0) alive and hitting a holdout end there, with their alpha
    written; returns the updated `alive` mask. Other rays see holdout objects as usual."""
    if depth != 0 or ctx.surfaces.holdout is None:
        return alive
    hold = alive & hits.hit & ctx.surfaces.holdout[np.maximum(hits.prim, 0)]
    if hold.any() and alpha_out is not None:
        alpha_out[path[hold]] = uncovered(b[hold])
    return alive & ~hold
