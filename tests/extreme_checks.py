"""Checks shared by the extreme-input tests, the fuzzer and docs/make_robustness_docs.py.

z_test compares two renders of the same scene made with independent random numbers
(the 'random' sampler, so each film's variance estimate is honest): per pixel, the
difference of the two means (summed over RGB) divided by its estimated standard
deviation. Equal images give z of mean about 0; a systematic difference shifts the mean
of z across the image (a 5% brighter light: +0.23 at the settings of
tests/test_extremes_scale.py) and widens its spread."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ZTest:
    pass_rate: float       # share of pixels with |z| < 3
    mean_z: float          # mean of the signed z over the pixels
    rel_mean: float        # (image mean / reference image mean) - 1

    def __str__(self):
        return (f"{100 * self.pass_rate:.1f}% of pixels |z| < 3, mean z {self.mean_z:+.3f}, "
                f"image mean {100 * self.rel_mean:+.2f}%")


def z_test(film, reference) -> ZTest:
    var = film.variance_of_mean().sum(-1) + reference.variance_of_mean().sum(-1)
    diff = film.mean().sum(-1) - reference.mean().sum(-1)
    z = diff / np.sqrt(np.maximum(var, 1e-12))
    return ZTest(float((np.abs(z) < 3).mean()), float(z.mean()),
                 float(film.mean().mean() / reference.mean().mean() - 1.0))


def sane(film, stats) -> list:
    """What is wrong with a render's numbers: non-finite samples (the renderer zeroes them
    and counts them), non-finite or negative pixels. Empty when all is well."""
    problems = []
    if stats.nonfinite_samples:
        problems.append(f"{stats.nonfinite_samples} non-finite samples")
    img = film.mean()
    if not np.isfinite(img).all():
        problems.append("non-finite pixels")
    elif img.min() < 0:
        problems.append(f"negative pixels (min {img.min():.3g})")
    return problems
