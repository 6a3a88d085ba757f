"""The table of DRT's microfiber sheen lobe (engine/kernels/bsdf/sheen.py): the LTC
parameters a, b and the albedo R over (cos theta_o, roughness), as Cycles uses them, and
the fit that produces it from measurements of Cycles (tests/cycles_sheen_probe.py).

Stored in `engine/bsdf/data/sheen_ltc.npz` as `table` (3, 32, 32) float64: [a, b, R]
indexed [roughness node, cos theta_o node], both grids uniform on [0, 1] (Cycles'
32 x 32 layout and bilinear lookup). Rebuild it with

    python tests/cycles_sheen_probe.py /tmp/sheen_probe.npz     # renders (bpy), ~2 min
    python -m engine.bsdf.sheen_table /tmp/sheen_probe.npz      # fits, ~2 min

The fit: each probe pixel is one value R z a^2 / (pi |(a x + b z, a y, z)|^4) of the lobe
at its view angle mu and the sun's local direction (x, y, z). Per roughness node, a, b
and R are piecewise linear in mu with knots at the 32 table nodes (as the lookup makes
them), and the 96 knot values are fitted by least squares to every lit pixel of that
roughness's dome (about 15,000 values), with a faint smoothness penalty on the second
differences over mu so that knots with few pixels stay tame, and a fainter pull of log a
and b towards 0 where R ~ 0 leaves the shape undetermined (the lowest roughness). Cycles reads roughness 0 at
1e-3 (its clamp), 3.1 % of the way to the next node; the first row is solved for that.
`fit_report` gives the residuals (measured, see FIT_NOTES).
"""
from __future__ import annotations

import os
import sys
import threading

import numpy as np

NODES = 32
ROUGH_MIN = 1e-3
PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "sheen_ltc.npz")
SMOOTH = 1e-3                 # weight of the second-difference penalty (values ~ 0.1 - 1)
PRIOR = 1e-4                  # weight of a pull of log a and b towards 0, for the knots
#                               where R ~ 0 leaves the shape undetermined (low roughness)

FIT_NOTES = """measured on the probe of tests/cycles_sheen_probe.py (filled in by the fit)"""

_lock = threading.Lock()
_table = None


def load() -> np.ndarray:
    """The table (3, NODES, NODES) [a, b, R][roughness, cos theta_o], read once."""
    global _table
    if _table is None:
        with _lock:
            if _table is None:
                with np.load(PATH) as f:
                    t = np.ascontiguousarray(f["table"], dtype=np.float64)
                if t.shape != (3, NODES, NODES) or not np.isfinite(t).all():
                    raise ValueError(f"{PATH}: not a sheen table of shape (3, {NODES}, {NODES})")
                _table = t
    return _table


def _interp(knots, mu):
    """Piecewise-linear values at mu of knots on the uniform grid over [0, 1]."""
    x = np.clip(mu, 0.0, 1.0) * (NODES - 1)
    i0 = np.minimum(x.astype(np.int64), NODES - 1)
    i1 = np.minimum(i0 + 1, NODES - 1)
    t = x - i0
    return (1.0 - t) * knots[i0] + t * knots[i1]


def lobe(a, b, R, x, y, z):
    """f cos towards (x, y, z) in the lobe's frame: R z a^2 / (pi |M^-1 w|^4), z > 0."""
    len2 = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return np.where(z > 0, R * z * a * a / (np.pi * len2 * len2), 0.0)


def pixel_samples(probe, dome):
    """(mu, x, y, z, value) of every pixel of dome `dome` lit by each sun."""
    px, cols = int(probe["px"]), int(probe["cols"])
    r0, c0 = (dome // cols) * px, (dome % cols) * px
    N = probe["normal"][r0:r0 + px, c0:c0 + px].reshape(-1, 3)
    ok = np.abs(np.linalg.norm(N, axis=1) - 1.0) < 2e-3
    N = N[ok] / np.linalg.norm(N[ok], axis=1, keepdims=True)
    v = np.array([0.0, 0.0, 1.0])
    mu = N[:, 2]
    t = v[None, :] - mu[:, None] * N
    tn = np.linalg.norm(t, axis=1, keepdims=True)
    t = np.where(tn > 1e-9, t / np.maximum(tn, 1e-300), np.array([1.0, 0.0, 0.0]))
    b = np.cross(N, t)
    out = []
    for s, l in enumerate(probe["suns"]):
        val = probe["images"][s, r0:r0 + px, c0:c0 + px].reshape(-1, 3)[ok].mean(1)
        out.append(np.stack([mu, t @ l, b @ l, N @ l, val], 1))
    return np.concatenate(out, 0)


def fit_dome(samples, start=None):
    """Knots (3, NODES) [a, b, R] fitted to one dome's samples (from `start`, knots of a
    neighbouring roughness, if given)."""
    from scipy.optimize import least_squares
    mu, x, y, z, val = samples.T
    keep = z > 1e-3
    mu, x, y, z, val = mu[keep], x[keep], y[keep], z[keep], val[keep]

    def unpack(p):
        return np.exp(p[:NODES]), p[NODES:2 * NODES], p[2 * NODES:]

    def residuals(p):
        a, b, R = unpack(p)
        r = lobe(_interp(a, mu), _interp(b, mu), _interp(R, mu), x, y, z) - val
        pen = [SMOOTH * np.diff(k, 2) for k in (p[:NODES], b, R)]
        return np.concatenate([r] + pen + [PRIOR * p[:2 * NODES]])

    p0 = np.concatenate([np.zeros(NODES), np.zeros(NODES), np.full(NODES, 0.2)])
    if start is not None:
        p0 = np.concatenate([np.log(np.maximum(start[0], 1e-6)), start[1], start[2]])
    res = least_squares(residuals, p0, method="trf", x_scale="jac", max_nfev=200,
                        jac_sparsity=_sparsity(mu), tr_solver="lsmr")
    a, b, R = unpack(res.x)
    return np.stack([a, b, R])


def _sparsity(mu):
    """Which knots each residual depends on: the two around its mu, for a, b and R; the
    penalty rows three consecutive knots of one parameter."""
    from scipy.sparse import lil_matrix
    n = len(mu)
    x = np.clip(mu, 0.0, 1.0) * (NODES - 1)
    i0 = np.minimum(x.astype(np.int64), NODES - 1)
    i1 = np.minimum(i0 + 1, NODES - 1)
    m = lil_matrix((n + 3 * (NODES - 2) + 2 * NODES, 3 * NODES), dtype=np.int8)
    rows = np.arange(n)
    for q in range(3):
        m[rows, q * NODES + i0] = 1
        m[rows, q * NODES + i1] = 1
        for j in range(NODES - 2):
            m[n + q * (NODES - 2) + j, q * NODES + j:q * NODES + j + 3] = 1
    for j in range(2 * NODES):
        m[n + 3 * (NODES - 2) + j, j] = 1
    return m


def fit_from_probe(probe) -> np.ndarray:
    rows = [None] * NODES
    start = None
    for k in range(NODES - 1, -1, -1):    # rough to smooth, each from its neighbour
        rows[k] = start = fit_dome(pixel_samples(probe, k), start)
        print(f"roughness node {k}: a {start[0, ::8].round(3)}, b {start[1, ::8].round(3)}"
              f", R {start[2, ::8].round(3)}", flush=True)
    table = np.stack(rows, 1)             # (3, rough, mu)
    t = ROUGH_MIN * (NODES - 1)           # dome 0 was read at roughness 1e-3
    table[:, 0] = (table[:, 0] - t * table[:, 1]) / (1.0 - t)
    table[0] = np.maximum(table[0], 1e-3)     # a > 0
    table[2] = np.maximum(table[2], 0.0)      # R >= 0
    return table


def fit_report(probe, table) -> dict:
    """Residuals of the table against the probe (lit pixels of the sheen domes): largest
    and RMS absolute error, RMS of the values, and the Lambertian dome's largest error
    (a check of the probe's geometry and units)."""
    errs, vals = [], []
    for k in range(NODES):
        mu, x, y, z, val = pixel_samples(probe, k).T
        r = max(k / (NODES - 1), ROUGH_MIN)
        y_ = r * (NODES - 1)
        j0 = min(int(y_), NODES - 1)
        j1 = min(j0 + 1, NODES - 1)
        tj = y_ - j0
        knots = (1.0 - tj) * table[:, j0] + tj * table[:, j1]
        model = lobe(_interp(knots[0], mu), _interp(knots[1], mu), _interp(knots[2], mu),
                     x, y, z)
        errs.append(model - val)
        vals.append(val)
    e, v = np.concatenate(errs), np.concatenate(vals)
    mu, x, y, z, val = pixel_samples(probe, NODES).T
    lam = np.abs(np.maximum(z, 0.0) / np.pi - val).max()
    return dict(max_abs=float(np.abs(e).max()), rms=float(np.sqrt((e * e).mean())),
                rms_value=float(np.sqrt((v * v).mean())), lambert_max_abs=float(lam))


def main(path):
    with np.load(path) as f:
        probe = {k: f[k] for k in f.files}
    table = fit_from_probe(probe)
    print(fit_report(probe, table))
    np.savez_compressed(PATH, table=table)
    print("saved", PATH)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/sheen_probe.npz")
