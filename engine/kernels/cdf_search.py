"""Finding u's interval in a CDF from a guide table (the cutpoint method: Devroye,
Non-Uniform Random Variate Generation, III.2.4): for an increasing `cdf` from 0 to 1 and
`cells` equal parts of [0, 1], guide[k] is the last index j with cdf[j] <= k / cells.
The interval of a u in [0, 1) then lies between guide[k] and guide[k + 1], k = floor(u *
cells): a binary search over those few entries finds the same interval as one over the
whole table, so results do not change by a bit, only their cost. The pixel filter's
inverse CDF (camera_rays), the environment map's row and column CDFs
(lights/environment_map) and the light pick (lights/light_set) use it; `bisect_last` is
the plain bisection under it (also motion.object_of's). Guides are built once per scene,
in NumPy."""
from __future__ import annotations

import numpy as np

from .jit import kernel


def guide_cells(n: int, most: int = 1024) -> int:
    """Cells for a CDF of n intervals: a power of two (u * cells and k / cells are exact)
    near n / 4, at most `most`."""
    cells = 1
    while cells * 4 < n and cells < most:
        cells *= 2
    return cells


def guide_table(cdf: np.ndarray, cells: int) -> np.ndarray:
    """The guide of each CDF along the last axis: (..., cells + 1) int32."""
    cdf = np.asarray(cdf, dtype=np.float64)
    if cdf.shape[-1] == 0:                     # an empty set: nothing to find
        return np.zeros(cdf.shape[:-1] + (cells + 1,), np.int32)
    u = np.arange(cells + 1, dtype=np.float64) / cells
    flat = cdf.reshape(-1, cdf.shape[-1])
    guide = np.empty((flat.shape[0], cells + 1), np.int32)
    for r in range(flat.shape[0]):
        guide[r] = np.searchsorted(flat[r], u, side="right") - 1
    return np.clip(guide, 0, cdf.shape[-1] - 1).reshape(cdf.shape[:-1] + (cells + 1,))


@kernel(allocates=False)
def last_at_most(xp, x, guide):
    """The last index j with xp[j] <= x (-1 when x < xp[0]), for xp increasing from 0 to
    1 (ties allowed) and its guide (guide_table)."""
    n = xp.shape[0]
    if x < xp[0]:
        return -1
    if x >= xp[n - 1]:
        return n - 1
    cells = guide.shape[0] - 1
    k = min(max(int(x * cells), 0), cells - 1)
    lo = np.int64(guide[k])                     # xp[lo] <= k / cells <= x (or lo = 0)
    hi = min(np.int64(guide[k + 1]) + 1, n - 1)  # xp[hi] > (k + 1) / cells > x
    return bisect_last(xp, x, lo, hi)


@kernel(allocates=False)
def bisect_last(xp, x, lo, hi):
    """The last j in [lo, hi) with xp[j] <= x, for xp increasing (ties allowed) with
    xp[lo] <= x < xp[hi]: bisection."""
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if xp[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo
