"""Baking, as Cycles bakes (Blender's Render > Bake): the light, colour, emission, normal
or ambient occlusion of points on a surface, one per texel of an image, instead of what
a camera sees.

Blender rasterises the object's UV layout and hands each texel a triangle and its
barycentrics (drt_addon.bake reads them). Each point is shaded as Cycles' bake kernel
shades it (its init_from_bake.h, read for definitions): a ray from the point plus its
normal, travelling back along the normal, that hits the point itself (no intersection
test: `points`), so the view direction is the normal; the path tracer goes on from
there as from a camera ray. What a pass keeps:
- COMBINED: everything (the filter's Direct / Indirect and closure kinds pick the light
  passes' slots: engine.kernels.light_tally);
- DIFFUSE, GLOSSY, TRANSMISSION: that kind's Direct and / or Indirect light, divided by
  its Color unless the filter's Color is on (Cycles' bake); Color alone: the albedo;
- EMIT: the surface's emission (what the "camera" ray finds there);
- NORMAL: the world-space shading normal (Blender turns it into tangent or object space);
- AO: engine.ambient_occlusion's, from the points.
A texel's first sample is at its centre, the others spread over its footprint as Cycles
spreads them (`jittered`); Normal and AO take the centres.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np

from .accel import Hits
from .kernels.light_tally import SLOT_NAMES

# Blender's bake pass filter bits (eBakePassFilter)
EMIT, DIFFUSE, GLOSSY, TRANSMISSION, DIRECT, INDIRECT, COLOR = 2, 4, 8, 16, 64, 128, 256
KINDS = ("COMBINED", "DIFFUSE", "GLOSSY", "TRANSMISSION", "EMIT", "NORMAL", "AO")
# the kinds whose empty texels Cycles leaves with alpha 1 (data passes)
OPAQUE_WHEN_EMPTY = ("EMIT", "NORMAL", "AO")


@dataclass
class BakePoints:
    """The surface points of n texels: rays (origins, directions) that hit them at t = 1,
    and their hits as the path tracer takes them."""
    origins: np.ndarray     # (n, 3)
    directions: np.ndarray  # (n, 3) unit: minus the shading normal
    hits: Hits
    normal: np.ndarray      # (n, 3) the world-space shading normal, front side


def points(ctx, prim: np.ndarray, u: np.ndarray, v: np.ndarray) -> BakePoints:
    """The points of global triangles `prim` (engine.accel's ids) at Blender's bake
    barycentrics (u weighs the triangle's corner 0, v corner 1, 1 - u - v corner 2)."""
    prim = np.ascontiguousarray(prim, np.int64)
    n = len(prim)
    # Embree's barycentrics: u weighs corner 1, v corner 2
    eu = np.ascontiguousarray(v, np.float64)
    ev = np.ascontiguousarray(1.0 - np.asarray(u, np.float64) - eu, np.float64)
    index = np.arange(n)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    first = ctx.surfaces.build(Hits(np.ones(n), prim, eu, ev), index, up,
                               origins=np.zeros((n, 3)))
    # the shading normal on the triangle's front side (build turns it towards the ray)
    side = np.where(first.front_facing, 1.0, -1.0)[:, None]
    normal = first.shading_normal * side
    origins = first.position + normal
    return BakePoints(origins, -normal, Hits(np.ones(n), prim, eu, ev), normal)


def _light_kinds(kind: str, filt: int) -> list:
    """The light-tally slots a pass sums (before any division by Color)."""
    parts = [p for p, bit in (("direct", DIRECT), ("indirect", INDIRECT)) if filt & bit]
    if kind == "COMBINED":
        kinds = [k for k, bit in (("diffuse", DIFFUSE), ("glossy", GLOSSY),
                                  ("transmission", TRANSMISSION)) if filt & bit]
        slots = [f"{k}_{p}" for k in kinds + ["volume"] for p in parts]
        return slots + (["emission"] if filt & EMIT else [])
    return [f"{kind.lower()}_{p}" for p in parts]


ALL_LIGHT = EMIT | DIFFUSE | GLOSSY | TRANSMISSION | DIRECT | INDIRECT


def _whole(kind: str, filt: int) -> bool:
    """Whether a pass is all the light (Combined with every filter): the path tracer's
    radiance, with no light passes to split."""
    return kind == "COMBINED" and filt & ALL_LIGHT == ALL_LIGHT


def _first_hit_only(kind: str, filt: int) -> bool:
    """Whether a pass is read at the first hit alone (Emit; a colour with no light)."""
    return kind == "EMIT" or (kind in ("DIFFUSE", "GLOSSY", "TRANSMISSION")
                              and not filt & (DIRECT | INDIRECT))


def settings_for(settings, kind: str, filt: int = -1):
    """The render settings a bake of `kind` with filter `filt` traces with: the light
    passes on where a pass is made of their slots, no bounce where it is read at the
    first hit alone."""
    out = replace(settings, light_passes=not _whole(kind, filt) and kind in (
        "COMBINED", "DIFFUSE", "GLOSSY", "TRANSMISSION", "EMIT"))
    return replace(out, max_bounces=0) if _first_hit_only(kind, filt) else out


def jittered(ctx, texel, index, u, v, footprint):
    """Blender barycentrics (u, v) of samples `index` of `texel`s, moved within the
    texel as Cycles moves them: sample 0 at the centre, the others by the sampler's pixel
    numbers r over the footprint (du/dx, du/dy, dv/dx, dv/dy), u + (r - 1/2) . du; a
    point that would leave its triangle stays at the centre (Cycles draws again)."""
    if footprint is None:
        return u, v
    from .sampling import dimensions as D
    r = ctx.sampler.get_2d(D.PIXEL, texel, index) - 0.5
    f = footprint
    ju = u + r[:, 0] * f[:, 0] + r[:, 1] * f[:, 1]
    jv = v + r[:, 0] * f[:, 2] + r[:, 1] * f[:, 3]
    inside = (index > 0) & (ju >= 0.0) & (jv >= 0.0) & (ju + jv <= 1.0)
    return np.where(inside, ju, u), np.where(inside, jv, v)


def bake(ctx, prim, u, v, kind: str, filt: int = -1, samples: int | None = None,
         ao_distance: float = 10.0, cancelled=None, footprint=None) -> np.ndarray:
    """(n, 3) values of pass `kind` (KINDS) with Blender's filter bits `filt` at n texels
    (see `points`); ctx: a RenderContext made with `settings_for(settings, kind, filt)`.
    footprint: (n, 4) each texel's (du/dx, du/dy, dv/dx, dv/dy) (Blender's
    BakeDifferential), over which the samples spread (`jittered`); None: at centres."""
    if kind not in KINDS:
        raise ValueError(f"DRT cannot bake {kind!r} (it bakes {', '.join(KINDS)})")
    prim = np.ascontiguousarray(prim, np.int64)
    bu, bv = np.asarray(u, np.float64), np.asarray(v, np.float64)
    footprint = None if footprint is None else np.asarray(footprint, np.float64)
    n = len(prim)
    if kind == "NORMAL":
        return points(ctx, prim, bu, bv).normal
    samples = int(samples or ctx.settings.samples)
    if kind == "AO":
        from .ambient_occlusion import AmbientOcclusion, occlusion
        pts = points(ctx, prim, bu, bv)
        si = ctx.surfaces.build(pts.hits, np.arange(n), pts.directions, origins=pts.origins)
        ao = AmbientOcclusion(distance=ao_distance, max_rays=samples)
        return occlusion(ctx, ao, np.arange(n), np.zeros(n, np.int64), si, None, samples)
    total = np.zeros((n, 3))
    colour = np.zeros((n, 3))
    names = _light_kinds(kind, filt) if kind != "EMIT" else ["emission"]
    slot = {name: i for i, name in enumerate(SLOT_NAMES)}
    colour_slot = slot.get(f"{kind.lower()}_color")
    whole = _whole(kind, filt)

    def run(texels: np.ndarray) -> None:
        """All samples of `texels`, a few at a time (about 64k paths a call)."""
        chunk = max(1, (1 << 16) // max(len(texels), 1))
        for start in range(0, samples, chunk):
            if cancelled is not None and cancelled():
                return
            k = min(chunk, samples - start)
            texel = np.repeat(texels, k)
            index = np.tile(np.arange(start, start + k, dtype=np.int64), len(texels))
            ju, jv = jittered(ctx, texel, index, bu[texel], bv[texel],
                              None if footprint is None else footprint[texel])
            at = points(ctx, prim[texel], ju, jv)
            found = ctx.integrator.radiance(texel, index, at.origins, at.directions,
                                            np.full(len(texel), np.inf), split=not whole,
                                            first_hits=at.hits)
            # each unit owns its texels (no two threads add to one row), each texel's
            # k samples one after the other
            if whole:
                total[texels] += found.reshape(-1, k, 3).sum(axis=1)
                continue
            got = found.passes
            value = sum((got[:, slot[s]] for s in names), np.zeros((len(texel), 3)))
            total[texels] += value.reshape(-1, k, 3).sum(axis=1)
            if colour_slot is not None:
                colour[texels] += got[:, colour_slot].reshape(-1, k, 3).sum(axis=1)

    threads = ctx.settings.threads or min(os.cpu_count() or 1, 8)
    units = np.array_split(np.arange(n, dtype=np.int64), max(1, min(n, 2 * threads)))
    with ThreadPoolExecutor(threads) as pool:
        for f in [pool.submit(run, unit) for unit in units]:
            f.result()
    total /= samples
    colour /= samples
    if kind in ("DIFFUSE", "GLOSSY", "TRANSMISSION"):
        if not filt & (DIRECT | INDIRECT):
            return colour                       # the albedo alone
        if not filt & COLOR:
            from .light_passes import divide_by_colour
            return divide_by_colour(total, colour)
    return total
