"""The film: per-pixel sample statistics, mergeable exactly.

For each pixel it keeps the sample count, the sum of the samples' alpha (coverage: 0
where a camera ray saw the transparent film background) and the sum and the sum of
squares of the sampled radiance (float64: a 1080p frame at thousands of samples sums millions of float32-range
values per pixel, and the variance is a difference of two such sums). With filter
importance sampling every sample counts in exactly one pixel with weight one, so two
films rendered from disjoint sample ranges merge by addition into exactly the film of
the whole range, variance estimate included.
"""
from __future__ import annotations

import numpy as np

from .kernels.jit import kernel


@kernel
def _accumulate(pixel, radiance, alpha, count, total, total_sq, alpha_sum):
    """Add each sample to its pixel's statistics (alpha empty: coverage 1)."""
    has_alpha = alpha.shape[0] > 0
    for i in range(pixel.shape[0]):
        p = pixel[i]
        count[p] += 1
        alpha_sum[p] += alpha[i] if has_alpha else 1.0
        for c in range(3):
            v = radiance[i, c]
            total[p, c] += v
            total_sq[p, c] += v * v


class Film:
    def __init__(self, width: int, height: int):
        self.width, self.height = int(width), int(height)
        n = self.width * self.height
        self.count = np.zeros(n, dtype=np.int64)
        self.sum = np.zeros((n, 3), dtype=np.float64)
        self.sum_sq = np.zeros((n, 3), dtype=np.float64)
        self.alpha_sum = np.zeros(n, dtype=np.float64)

    def add(self, pixel: np.ndarray, radiance: np.ndarray, alpha: np.ndarray | None = None) -> None:
        pixel = np.ascontiguousarray(pixel, dtype=np.int64)
        if len(pixel) and (pixel.min() < 0 or pixel.max() >= self.count.size):
            raise IndexError("sample pixel outside the film")
        _accumulate(pixel, np.ascontiguousarray(radiance, dtype=np.float64),
                    np.zeros(0) if alpha is None else np.ascontiguousarray(alpha, np.float64),
                    self.count, self.sum, self.sum_sq, self.alpha_sum)

    def merge(self, other: "Film") -> "Film":
        if (other.width, other.height) != (self.width, self.height):
            raise ValueError("cannot merge films of different sizes")
        self.count += other.count
        self.sum += other.sum
        self.sum_sq += other.sum_sq
        self.alpha_sum += other.alpha_sum
        return self

    def mean(self) -> np.ndarray:
        """(height, width, 3) float64 image, row 0 at the top; zero where no samples."""
        c = np.maximum(self.count, 1)[:, None]
        return (self.sum / c).reshape(self.height, self.width, 3)

    def mean_alpha(self) -> np.ndarray:
        """(height, width) coverage in [0, 1]; the colour from mean() is premultiplied by
        it (background samples add no radiance), as Blender expects."""
        return (self.alpha_sum / np.maximum(self.count, 1)).reshape(self.height, self.width)

    def variance_of_mean(self) -> np.ndarray:
        """Per-pixel estimate of the variance of the pixel mean (unbiased sample
        variance divided by the count), (height, width, 3); inf where fewer than 2."""
        c = self.count[:, None].astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = self.sum / c
            var = (self.sum_sq - c * mean * mean) / (c - 1.0)
            out = np.where(c > 1, np.maximum(var, 0.0) / c, np.inf)
        return out.reshape(self.height, self.width, 3)
