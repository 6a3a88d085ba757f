"""Adaptive sampling as Cycles does it: pixels stop taking samples once their error
estimate is under a noise threshold.

The error of a pixel is measured on two films: the mean I of all its samples and the mean
A of half of them, Cycles' class A (engine.film keeps both). With stratified or quasi-Monte Carlo
samples the spread of single samples overstates the error of their mean; I - A does not,
since both halves are estimates of the same integral from the same kind of point set.
Cycles' per-pixel error (after Dammertz et al., "A hierarchical automatic stopping
condition for Monte Carlo global illumination", 2.1) is

    error = (|I_r - A_r| + |I_g - A_g| + |I_b - A_b|) / (0.0001 + s(I_r + I_g + I_b)),

with s(x) = sqrt(x) below 1 and x above (bright pixels need less relative precision), and
a pixel has converged when error < 5 x threshold (Cycles scales the user's threshold by 5).
Converged pixels next to unconverged ones are kept alive (a 3x3 box spread, as Cycles'
two filter passes), so noise does not end in hard seams. Checks happen as Cycles' render
scheduler makes them: first after (min_samples + 1) | (step - 1) + 1 samples (80 for Min
Samples 64 and step 16: the first sample count past min_samples that ends a step), then
every `step` samples.

Automatic values, as Cycles: threshold 0 means max(0.001, 1 / samples); min samples 0
means max(4, ceil(16 / threshold^0.3)) (threshold 0.01: 64 samples).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .film import Film

# Cycles checks convergence every 16 samples.
STEP = 16


@dataclass(frozen=True)
class AdaptiveSampling:
    threshold: float        # the user's threshold (before Cycles' factor 5)
    min_samples: int
    step: int = STEP

    @classmethod
    def from_settings(cls, settings) -> "AdaptiveSampling | None":
        """None when the settings do not ask for adaptive sampling."""
        if not settings.adaptive_sampling:
            return None
        threshold = settings.adaptive_threshold or max(0.001, 1.0 / settings.samples)
        if settings.adaptive_min_samples:
            least = max(4, settings.adaptive_min_samples)
        else:
            least = max(4, math.ceil(16.0 / threshold ** 0.3))
        return cls(threshold=float(threshold), min_samples=int(least))

    def first_check(self) -> int:
        """Samples before the first convergence check (Cycles' AdaptiveSampling::
        align_samples: the first filter follows 0-based sample (min + 1) | (step - 1))."""
        return ((self.min_samples + 1) | (self.step - 1)) + 1

    def pixel_error(self, film: Film, pixels=None) -> np.ndarray:
        """Cycles' relative error estimate of each pixel (flat order) or of `pixels` (flat
        indices); inf for pixels without samples in both halves."""
        sel = slice(None) if pixels is None else pixels
        diff = np.abs(film.half_difference(pixels)).sum(axis=1)
        count, half = film.count[sel], film.count_half[sel]
        intensity = film.sum[sel].sum(axis=1) / np.maximum(count, 1)
        scale = np.where(intensity < 1.0, np.sqrt(np.maximum(intensity, 0.0)), intensity)
        err = diff / (1e-4 + scale)
        return np.where((half > 0) & (half < count), err, np.inf)

    def active(self, film: Film) -> np.ndarray:
        """(n,) bool: pixels that still take samples (not converged, or next to one that
        is not), every pixel checked."""
        unconverged = ~(self.pixel_error(film) < 5.0 * self.threshold)
        return spread(unconverged.reshape(film.height, film.width)).reshape(-1)

    def check(self, film: Film, sampled: np.ndarray, unconverged: np.ndarray) -> np.ndarray:
        """The pixels (flat indices) that go on after a pass over `sampled`: only theirs is
        checked again, as Cycles checks (a pixel that took no samples keeps its state), and
        `unconverged` (n,) bool is updated in place; so a check costs in proportion to the
        pixels still sampling, not the frame. Equal to np.flatnonzero(active(film))."""
        unconverged[sampled] = ~(self.pixel_error(film, sampled) < 5.0 * self.threshold)
        return np.flatnonzero(spread(unconverged.reshape(film.height, film.width)))

    def passes(self, total: int, first_passes):
        """Sample ranges (relative to the render's first sample) for an adaptive render:
        `first_passes` up to the first check, then `step` samples a pass, each ending
        where Cycles checks convergence."""
        head = min(self.first_check(), total)
        yield from first_passes(head)
        for a in range(head, total, self.step):
            yield a, min(a + self.step, total)


def spread(mask: np.ndarray) -> np.ndarray:
    """(h, w) bool: True where any pixel of the 3x3 neighbourhood is True."""
    out = mask.copy()
    out[:, 1:] |= mask[:, :-1]
    out[:, :-1] |= mask[:, 1:]
    rows = out.copy()
    out[1:] |= rows[:-1]
    out[:-1] |= rows[1:]
    return out


def noise_variance(film: Film) -> np.ndarray:
    """(h, w, 3) estimate of the variance of each pixel's mean from the two half films:
    (I - A)^2, unbiased for independent samples and honest for stratified ones (one degree
    of freedom per pixel: average it over regions)."""
    d = film.half_difference()
    return (d * d).reshape(film.height, film.width, 3)
