"""The Ambient Occlusion pass, as Cycles writes it (View Layer > Passes > Data > Ambient
Occlusion): at the first surface each camera ray meets, the share of cosine-weighted
directions about the surface's shading normal along which nothing stops a ray within
the world's AO distance (World > Ambient Occlusion > Distance; 10 m without a world).

As Cycles' AO rays are shadow rays, they pass through transparent surfaces, objects
that cast no shadow and volumes, weighted by what those let through (RGB); a direction
below the surface's geometric plane counts as occluded (Cycles casts no ray there). The
pass is the mean over the pixel's camera samples, a sample that hits nothing adding 0,
so an edge pixel is weighted by its coverage.

Cycles casts one AO ray per render sample from inside its path tracer. Here the rays
leave the first hits of the first-hit passes (engine.aov: the first
min(samples, AOV_SAMPLES) camera samples of a pixel), `rays_per_sample` from each, so
that a pixel gets min(samples, max_rays) rays in all; their directions are the
sampler's numbers of the first bounce's BSDF direction (Cycles' AO takes the BSDF's
numbers too), stratified over the pixel's rays. Above max_rays samples the pass is
noisier than Cycles' (docs/index.md; tests/test_ao_pass.py measures it at 64).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .sampling import dimensions as D
from .warp import cosine_hemisphere, to_world

DEFAULT_DISTANCE = 10.0      # Cycles' AO distance when the scene has no world
MAX_RAYS = 64                # AO rays per pixel at most


@dataclass(frozen=True)
class AmbientOcclusion:
    """What the AO pass reads: the AO distance (metres) and the most rays per pixel."""
    distance: float = DEFAULT_DISTANCE
    max_rays: int = MAX_RAYS

    def __post_init__(self):
        if not (self.distance >= 0.0 and np.isfinite(self.distance)):
            raise ValueError(f"AO distance must be a finite length >= 0, got {self.distance}")
        if self.max_rays < 1:
            raise ValueError(f"AO rays per pixel must be at least 1, got {self.max_rays}")

    def rays_per_sample(self, samples: int, camera_samples: int) -> int:
        """AO rays from each of a pixel's `camera_samples` first hits, for a render of
        `samples` per pixel."""
        return max(1, min(int(samples), self.max_rays) // max(1, camera_samples))


def occlusion(ctx, ao: AmbientOcclusion, pixel: np.ndarray, index: np.ndarray, si,
              time: np.ndarray | None, m: int) -> np.ndarray:
    """(n, 3): for each first hit `si` (of camera sample `index` of pixel `pixel`, at
    shutter time `time` or None), the mean over m rays of what reaches distance
    ao.distance unoccluded."""
    n = len(si.position)
    if n == 0 or m < 1:
        return np.zeros((n, 3))
    rows = np.repeat(np.arange(n), m)
    sample = (np.asarray(index, np.int64)[:, None] * m + np.arange(m)).ravel()
    pixels = np.repeat(pixel, m)
    u = ctx.sampler.get_2d(D.bounce_dim(0, D.BSDF_DIR), pixels, sample)
    normal = si.shading_normal[rows]
    d = to_world(cosine_hemisphere(u), normal)
    above = (d * si.geometric_normal[rows]).sum(1) > 0.0
    passed = np.zeros((len(rows), 3))
    if above.any() and ao.distance == 0.0:
        passed[above] = 1.0             # nothing lies within no distance (as in Cycles)
    elif above.any():
        r = np.nonzero(above)[0]
        # each ray starts on its surface and names the triangle it leaves (Cycles')
        prim = np.ascontiguousarray(si.prim[rows[r]], np.int64)
        inst = (np.full(len(r), -1, np.int64) if si.inst is None
                else np.ascontiguousarray(si.inst[rows[r]], np.int64))
        o = si.position[rows[r]]
        far = np.full(len(r), ao.distance)
        t = None if time is None else np.asarray(time)[rows[r]]
        passed[r] = _transmitted(ctx, o, np.ascontiguousarray(d[r]), far, t,
                                 pixels[r], sample[r], np.stack([prim, inst], 1))
    return passed.reshape(n, m, 3).mean(axis=1)


def _transmitted(ctx, o, d, far, time, pixel, sample, skip) -> np.ndarray:
    """(n, 3) what each ray carries to `far`: 1 or 0 against opaque surfaces, the
    transmittance of transparent layers and volumes as the path tracer's shadow rays
    take it (engine.integrators.compiled_path); skip (n, 2): the triangle and place each
    ray leaves."""
    integ = ctx.integrator
    transparent = getattr(integ, "any_transparent", False) or \
        getattr(integ, "skips_shadows", False) or getattr(integ, "has_volumes", False)
    if not transparent:
        blocked = ctx.accel.occluded(o, d, far, time, skip)
        return np.repeat((~blocked).astype(np.float64)[:, None], 3, axis=1)
    from .kernels.medium_density import shadow_keys
    from .kernels.volume import STACK
    from .sampling.dispatch import pixel_keys
    n = len(o)
    if integ.has_volumes:       # the camera's media (first hits stop at volume bounds)
        stacks = np.ascontiguousarray(np.tile(integ.start_stack, (n, 1)), np.int32)
    else:
        stacks = np.full((0, STACK), -1, np.int32)
    keys = np.zeros(0, np.uint64)
    if integ.heterogeneous:
        pkey = pixel_keys(np.uint64(ctx.sampler.seed), np.asarray(pixel, np.int64))
        keys = shadow_keys(pkey, np.asarray(sample, np.int64), np.arange(n, dtype=np.int64),
                           0)
    return integ.shadow_transmittance(o, d, far, time, stacks, keys, skip)
