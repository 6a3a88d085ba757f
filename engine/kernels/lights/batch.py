"""Array drivers of the light kernels (compiled loops over rows): what the tests and the
chi-square harnesses call. Inputs are (n, 3) float64 points / directions, (n,) arrays of
uniforms, distances and indices; outputs are freshly allocated arrays. `time`: the rows'
shutter times (n,) in [0, 1], zeros when not given (only moving lamps read it)."""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from .light_set import hit_lamps, lamp_pdf, mesh_pdf, sample, sun_escaped, world_escaped


def _times(time, n):
    return np.zeros(n) if time is None else np.ascontiguousarray(time, np.float64)


def sample_batch(L, p, u_pick, u, time=None):
    """`light_set.sample` over n points (see `_sample_rows`)."""
    return _sample_rows(L, p, u_pick, u, _times(time, len(p)))


@kernel
def _sample_rows(L, p, u_pick, u, time):
    """`light_set.sample` over n points: (k (n,) int64, wi (n, 3), dist (n,), radiance
    (n, 3), pdf (n,) with the pick probability, delta (n,) bool, margin (n,))."""
    n = p.shape[0]
    k_out = np.empty(n, dtype=np.int64)
    wi = np.empty((n, 3))
    dist = np.empty(n)
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    delta = np.empty(n, dtype=np.bool_)
    margin = np.empty(n)
    for i in range(n):
        k, wx, wy, wz, d, r, g, b, pd, dl, m = sample(L, p[i, 0], p[i, 1], p[i, 2],
                                                      u_pick[i], u[i, 0], u[i, 1], time[i])
        k_out[i] = k
        wi[i, 0], wi[i, 1], wi[i, 2] = wx, wy, wz
        dist[i] = d
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
        delta[i] = dl
        margin[i] = m
    return k_out, wi, dist, rad, pdf, delta, margin


def hit_lamps_batch(L, o, d, tmax, time=None):
    """`light_set.hit_lamps` over n rays (see `_hit_rows`)."""
    return _hit_rows(L, o, d, tmax, _times(time, len(o)))


@kernel
def _hit_rows(L, o, d, tmax, time):
    """`light_set.hit_lamps` over n rays: (t (n,), k (n,) int64, radiance (n, 3))."""
    n = o.shape[0]
    t_out = np.empty(n)
    k_out = np.empty(n, dtype=np.int64)
    rad = np.empty((n, 3))
    for i in range(n):
        t, k, r, g, b = hit_lamps(L, o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2],
                                  tmax[i], 31, time[i])
        t_out[i] = t
        k_out[i] = k
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
    return t_out, k_out, rad


def lamp_pdf_batch(L, k, p, wi, t, time=None):
    """`light_set.lamp_pdf` over n rows (see `_pdf_rows`)."""
    return _pdf_rows(L, k, p, wi, t, _times(time, len(p)))


@kernel
def _pdf_rows(L, k, p, wi, t, time):
    """`light_set.lamp_pdf` over n rows: (n,) pdfs, pick probability included."""
    n = p.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = lamp_pdf(L, k[i], p[i, 0], p[i, 1], p[i, 2], wi[i, 0], wi[i, 1], wi[i, 2],
                          t[i], time[i])
    return out


@kernel
def mesh_pdf_batch(L, prim, p, q):
    """`light_set.mesh_pdf` over n rows: (n,) pdfs, pick probability included."""
    n = p.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = mesh_pdf(L, prim[i], p[i, 0], p[i, 1], p[i, 2], q[i, 0], q[i, 1], q[i, 2])
    return out


def sun_escaped_batch(L, j, d, time=None):
    """The j-th non-delta sun for n escaped rays (see `_sun_rows`)."""
    return _sun_rows(L, j, d, _times(time, len(d)))


@kernel
def _sun_rows(L, j, d, time):
    """The j-th non-delta sun for n escaped rays: (radiance (n, 3), pdf (n,))."""
    n = d.shape[0]
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    for i in range(n):
        r, g, b, pd = sun_escaped(L, j, d[i, 0], d[i, 1], d[i, 2], time[i])
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
    return rad, pdf


def world_escaped_batch(L, world, d, ray_bit=2):
    """What n escaped rays along d of kind ray_bit (engine.visibility; diffuse by
    default) see of the world: (radiance (n, 3), the MIS pdf of the world light along d
    (n,))."""
    return _world_rows(L, world, np.ascontiguousarray(d, np.float64), ray_bit)


@kernel
def _world_rows(L, world, d, ray_bit):
    n = d.shape[0]
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    for i in range(n):
        r, g, b, pd = world_escaped(L, world, ray_bit, d[i, 0], d[i, 1], d[i, 2])
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
    return rad, pdf
