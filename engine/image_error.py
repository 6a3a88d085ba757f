"""Error metrics between a test image and a reference: what convergence studies measure.

Images are (h, w, 3) scene-linear arrays (an alpha channel, if any, is dropped; a
single-channel (h, w) image counts as grey).

- RMSE: sqrt(mean((test - ref)^2)) over every pixel and colour channel.
- Relative MSE (relMSE), the convention of pbrt's and Cycles' convergence studies:
  mean((test - ref)^2 / (ref^2 + eps)) per pixel and channel, with eps = RELMSE_EPS =
  1e-2 (the same as docs/make_benchmarks.py): the squared error relative to the
  reference's brightness, with eps keeping black pixels from dominating.
- FLIP (NVIDIA's perceptual difference, `flip-evaluator` package): the mean of the
  per-pixel FLIP error in [0, 1]. We use LDR-FLIP on the image a display shows
  through Blender's "Standard" view transform at exposure 0: scene-linear values clipped
  to [0, 1], handed to FLIP as linear sRGB (FLIP applies no tone mapping then). Its cost
  is one evaluation per image pair whatever the dynamic range, where HDR-FLIP evaluates
  a number of exposures that grows with the reference's dynamic range; the clip hides
  errors in pixels brighter than 1 in both images (lamps seen directly), which RMSE and
  relMSE still count.

`fit_slope` fits the convergence rate: the least-squares slope of log(error) against
log(samples) or log(seconds) (-1 for the MSE of unbiased Monte Carlo, -0.5 for its RMSE),
after taking off what a noisy reference adds to every measurement (`noise_floor`).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

RELMSE_EPS = 1e-2


def as_rgb(image) -> np.ndarray:
    """(h, w, 3) float64 of an (h, w), (h, w, 1), (h, w, 3) or (h, w, 4) array."""
    a = np.asarray(image, dtype=np.float64)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[2] not in (1, 3, 4):
        raise ValueError(f"expected an (h, w), (h, w, 3) or (h, w, 4) image, got shape "
                         f"{a.shape}")
    if a.shape[2] == 1:
        a = np.repeat(a, 3, axis=2)
    return a[..., :3]


def _pair(test, reference):
    t, r = as_rgb(test), as_rgb(reference)
    if t.shape != r.shape:
        raise ValueError(f"the images differ in size: {t.shape[1]}x{t.shape[0]} against "
                         f"{r.shape[1]}x{r.shape[0]}")
    for name, a in (("test", t), ("reference", r)):
        bad = int((~np.isfinite(a)).sum())
        if bad:
            raise ValueError(f"the {name} image has {bad} NaN or infinite values")
    return t, r


def rmse(test, reference) -> float:
    t, r = _pair(test, reference)
    return float(np.sqrt(np.mean((t - r) ** 2)))


def relmse(test, reference, eps: float = RELMSE_EPS) -> float:
    t, r = _pair(test, reference)
    return float(np.mean((t - r) ** 2 / (r * r + eps)))


def display_image(image) -> np.ndarray:
    """The linear image FLIP compares: scene-linear clipped to [0, 1] (float32)."""
    return np.ascontiguousarray(np.clip(as_rgb(image), 0.0, 1.0), dtype=np.float32)


def flip_map(test, reference):
    """(per-pixel LDR-FLIP error (h, w) float32 in [0, 1], its mean)."""
    import flip_evaluator
    t, r = _pair(test, reference)
    error, mean, _ = flip_evaluator.evaluate(display_image(r), display_image(t), "LDR",
                                             inputsRGB=False, applyMagma=False,
                                             computeMeanError=True)
    return np.asarray(error, dtype=np.float32).reshape(t.shape[:2]), float(mean)


def flip(test, reference) -> float:
    return flip_map(test, reference)[1]


@dataclass
class ImageError:
    rmse: float
    relmse: float
    flip: float | None = None

    def as_dict(self) -> dict:
        return asdict(self)


METRICS = ("rmse", "relmse", "flip")


def measure(test, reference, with_flip: bool = True) -> ImageError:
    return ImageError(rmse=rmse(test, reference), relmse=relmse(test, reference),
                      flip=flip(test, reference) if with_flip else None)


def fit_slope(x, y, floor: float = 0.0):
    """Least-squares slope of log(y - floor) against log(x), for an error y that adds
    up like a variance (MSE, relMSE) and a floor the reference's own noise adds to every
    measurement in expectation (`noise_floor`): fitted over the points with x > 0 and
    y > 2 * floor (where the correction is at most half the value); None with fewer than
    two such points."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    floor = max(float(floor), 0.0)
    keep = (x > 0) & np.isfinite(y) & (y > 2.0 * floor) & (y > 0)
    if keep.sum() < 2 or np.ptp(np.log(x[keep])) == 0:
        return None
    slope, _ = np.polyfit(np.log(x[keep]), np.log(y[keep] - floor), 1)
    return float(slope)


def metric_slope(metric: str, x, values, floor: dict | None = None):
    """`fit_slope` of one metric's values against x, corrected for the reference noise
    `floor` (a `noise_floor` dict): RMSE through its square (the MSE adds up), FLIP
    uncorrected (it has no such additive floor)."""
    floor = floor or {}
    if metric == "rmse":
        s = fit_slope(x, np.square(np.asarray(values, dtype=np.float64)), floor.get("mse", 0.0))
        return None if s is None else s / 2.0
    return fit_slope(x, values, floor.get(metric, 0.0) if metric != "flip" else 0.0)


def noise_floor(variance_of_mean, reference) -> dict:
    """The error a noisy reference adds, in expectation, to every measurement against it
    (its noise is independent of the test image's): the mean per-pixel variance of the
    reference's mean (engine.film.Film.variance_of_mean) as RMSE and relMSE floors."""
    v, r = _pair(variance_of_mean, reference)
    mse = float(np.mean(v))
    return {"mse": mse, "rmse": float(np.sqrt(mse)),
            "relmse": float(np.mean(v / (r * r + RELMSE_EPS))), "flip": 0.0}
