"""The film: per-pixel sample statistics, mergeable exactly.

For each pixel it keeps the sample count, the sum of the samples' alpha (coverage: 0
where a camera ray saw the transparent film background) and the sum and the sum of
squares of the sampled radiance (float64: a 1080p frame at thousands of samples sums millions of float32-range
values per pixel, and the variance is a difference of two such sums). With filter
importance sampling every sample counts in exactly one pixel with weight one, so two
films rendered from disjoint sample ranges merge by addition into exactly the film of
the whole range, variance estimate included.

It also keeps the sum of half of the samples alone (and their count): a second film of
Cycles' class A, the samples s whose popcount(s & 0xaaaaaaaa) is odd (two of every four
consecutive indices; Christensen, Kensler and Kilpatrick, "Progressive Multi-Jittered
Sample Sequences", 10.2.1: each half of a progressive sequence is itself well spread), as
Cycles keeps for adaptive sampling. The difference between the whole mean and that
half's mean estimates the error of the pixel honestly even for stratified and
quasi-Monte Carlo samples, whose sum of squares overstates it (engine.adaptive_sampling).

With `extra` channels it also sums, per pixel, that many more RGB values of each sample
(the light passes and light groups of engine.light_passes).
"""
from __future__ import annotations

import numpy as np

from .kernels.jit import kernel


@kernel
def _accumulate_extra(pixel, extra, extra_sum):
    """Add each sample's extra channels (n, k, 3) to its pixel's sums."""
    for i in range(pixel.shape[0]):
        p = pixel[i]
        for j in range(extra.shape[1]):
            for c in range(3):
                extra_sum[p, j, c] += extra[i, j, c]


@kernel
def in_half(s):
    """1 if sample index s is in the half film (Cycles' class A: popcount(s &
    0xaaaaaaaa) odd, the parity folded down to bit 0), else 0."""
    x = s & 0xAAAAAAAA
    x ^= x >> 16
    x ^= x >> 8
    x ^= x >> 4
    x ^= x >> 2
    x ^= x >> 1
    return x & 1


@kernel
def _accumulate(pixel, index, radiance, alpha, count, total, total_sq, alpha_sum,
                count_half, total_half):
    """Add each sample to its pixel's statistics (alpha empty: coverage 1); samples of
    class A also to the half film."""
    has_alpha = alpha.shape[0] > 0
    for i in range(pixel.shape[0]):
        p = pixel[i]
        half = in_half(index[i])
        count[p] += 1
        count_half[p] += half
        alpha_sum[p] += alpha[i] if has_alpha else 1.0
        for c in range(3):
            v = radiance[i, c]
            total[p, c] += v
            total_sq[p, c] += v * v
            if half:
                total_half[p, c] += v


class Film:
    def __init__(self, width: int, height: int, extra: int = 0):
        self.width, self.height = int(width), int(height)
        n = self.width * self.height
        self.extra_sum = np.zeros((n, int(extra), 3), dtype=np.float64)
        self.count = np.zeros(n, dtype=np.int64)
        self.sum = np.zeros((n, 3), dtype=np.float64)
        self.sum_sq = np.zeros((n, 3), dtype=np.float64)
        self.alpha_sum = np.zeros(n, dtype=np.float64)
        self.count_half = np.zeros(n, dtype=np.int64)
        self.sum_half = np.zeros((n, 3), dtype=np.float64)

    def add(self, pixel: np.ndarray, radiance: np.ndarray, alpha: np.ndarray | None = None,
            *, index: np.ndarray, extra: np.ndarray | None = None) -> None:
        """Add samples: `pixel` and sample `index` (n,), radiance (n, 3), alpha (n,)
        or None (opaque), and the extra channels (n, k, 3) when the film keeps k."""
        pixel = np.ascontiguousarray(pixel, dtype=np.int64)
        index = np.ascontiguousarray(index, dtype=np.int64)
        if len(pixel) and (pixel.min() < 0 or pixel.max() >= self.count.size):
            raise IndexError("sample pixel outside the film")
        if index.shape != pixel.shape:
            raise ValueError("one sample index per sample")
        _accumulate(pixel, index, np.ascontiguousarray(radiance, dtype=np.float64),
                    np.zeros(0) if alpha is None else np.ascontiguousarray(alpha, np.float64),
                    self.count, self.sum, self.sum_sq, self.alpha_sum,
                    self.count_half, self.sum_half)
        if self.extra_sum.shape[1]:
            if extra is None or extra.shape != (len(pixel),) + self.extra_sum.shape[1:]:
                raise ValueError("this film keeps extra channels: one row of them per sample")
            _accumulate_extra(pixel, np.ascontiguousarray(extra, np.float64), self.extra_sum)

    STATISTICS = ("count", "sum", "sum_sq", "alpha_sum", "count_half", "sum_half",
                  "extra_sum")

    def statistics(self) -> dict:
        """Every per-pixel array by name: all a film is, to ship to another process and
        rebuild there with `from_statistics`."""
        return {name: getattr(self, name) for name in self.STATISTICS}

    @classmethod
    def from_statistics(cls, width: int, height: int, arrays: dict) -> "Film":
        extra = arrays.get("extra_sum")
        film = cls(width, height, extra=extra.shape[1] if np.ndim(extra) == 3 else 0)
        for name in cls.STATISTICS:
            if name in arrays:
                getattr(film, name)[:] = arrays[name]
        return film

    def merge(self, other: "Film") -> "Film":
        if (other.width, other.height) != (self.width, self.height):
            raise ValueError("cannot merge films of different sizes")
        for name in self.STATISTICS:
            getattr(self, name).__iadd__(getattr(other, name))
        return self

    def mean(self) -> np.ndarray:
        """(height, width, 3) float64 image, row 0 at the top; zero where no samples."""
        c = np.maximum(self.count, 1)[:, None]
        return (self.sum / c).reshape(self.height, self.width, 3)

    def mean_alpha(self) -> np.ndarray:
        """(height, width) coverage in [0, 1]; the colour from mean() is premultiplied by
        it (background samples add no radiance), as Blender expects."""
        return (self.alpha_sum / np.maximum(self.count, 1)).reshape(self.height, self.width)

    def half_difference(self, pixels=None) -> np.ndarray:
        """(n, 3) mean of all samples minus mean of the half film's, per pixel (flat
        order), or of `pixels` (flat indices) alone; 0 where a pixel has no sample in one
        of the halves. Its square estimates the variance of the pixel mean (with n/2
        samples in each half, E[(I - A)^2] = sigma^2 / n), whatever the sampler's
        stratification."""
        sel = slice(None) if pixels is None else pixels
        c = self.count[sel][:, None].astype(np.float64)
        co = self.count_half[sel][:, None].astype(np.float64)
        ok = (co > 0) & (co < c)
        with np.errstate(divide="ignore", invalid="ignore"):
            d = self.sum[sel] / c - self.sum_half[sel] / co
        return np.where(ok, d, 0.0)

    def variance_of_mean(self) -> np.ndarray:
        """Per-pixel estimate of the variance of the pixel mean (unbiased sample
        variance divided by the count), (height, width, 3); inf where fewer than 2."""
        c = self.count[:, None].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = self.sum / c
            var = (self.sum_sq - c * mean * mean) / (c - 1.0)
            out = np.where(c > 1, np.maximum(var, 0.0) / c, np.inf)
        return out.reshape(self.height, self.width, 3)
