"""Array drivers of the light kernels (compiled loops over rows): what the tests and the
chi-square harnesses call. Inputs are (n, 3) float64 points / directions, (n,) arrays of
uniforms, distances and indices; outputs are freshly allocated arrays. `time`: the rows'
shutter times (n,) in [0, 1], zeros when not given (only moving lamps read it).
The receivers (tree_importance.py) are the points p, with `normals` (n, 3) and `mode`
(OMNI, ONE_SIDED or TWO_SIDED; OMNI without normals), or segments from p along the
`normals` of lengths `t` (mode SEGMENT)."""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from .light_set import hit_lamps, lamp_pdf, mesh_pdf, sample, sun_escaped, world_escaped
from .tree import OMNI
from .tree import pick as tree_pick


def _times(time, n):
    return np.zeros(n) if time is None else np.ascontiguousarray(time, np.float64)


def receivers(p, normals=None, mode=OMNI, t=None):
    """(n, 8) receiver rows: p, the normals (zeros without them), the mode, t."""
    p = np.asarray(p, np.float64).reshape(-1, 3)
    r = np.zeros((len(p), 8))
    r[:, :3] = p
    if normals is not None:
        r[:, 3:6] = normals
    r[:, 6] = mode
    if t is not None:
        r[:, 7] = t
    return r


def sample_batch(L, p, u_pick, u, time=None, normals=None, mode=OMNI):
    """`light_set.sample` over n points (see `_sample_rows`)."""
    return _sample_rows(L, receivers(p, normals, mode), u_pick, u, _times(time, len(p)))


@kernel
def _sample_rows(L, rc, u_pick, u, time):
    """`light_set.sample` over n points: (k (n,) int64, wi (n, 3), dist (n,), radiance
    (n, 3), pdf (n,) with the pick probability, delta (n,) bool, light_prim (n,) int64:
    the emissive triangle's global id, -1 for lamps, margin (n,))."""
    n = rc.shape[0]
    k_out = np.empty(n, dtype=np.int64)
    wi = np.empty((n, 3))
    dist = np.empty(n)
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    delta = np.empty(n, dtype=np.bool_)
    light_prim = np.empty(n, dtype=np.int64)
    margin = np.empty(n)
    for i in range(n):
        k, wx, wy, wz, d, r, g, b, pd, dl, m, mg = sample(L, _recv(rc, i), u_pick[i], u[i, 0],
                                                      u[i, 1], time[i])
        k_out[i] = k
        wi[i, 0], wi[i, 1], wi[i, 2] = wx, wy, wz
        dist[i] = d
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
        delta[i] = dl
        light_prim[i] = m
        margin[i] = mg
    return k_out, wi, dist, rad, pdf, delta, light_prim, margin


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


def lamp_pdf_batch(L, k, p, wi, t, time=None, normals=None, mode=OMNI):
    """`light_set.lamp_pdf` over n rows (see `_pdf_rows`)."""
    return _pdf_rows(L, k, receivers(p, normals, mode), wi, t, _times(time, len(p)))


@kernel(allocates=False)
def _recv(rc, i):
    return (rc[i, 0], rc[i, 1], rc[i, 2], rc[i, 3], rc[i, 4], rc[i, 5], rc[i, 6], rc[i, 7])


@kernel
def _pdf_rows(L, k, rc, wi, t, time):
    """`light_set.lamp_pdf` over n rows: (n,) pdfs, pick probability included."""
    n = rc.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = lamp_pdf(L, k[i], _recv(rc, i), wi[i, 0], wi[i, 1], wi[i, 2], t[i],
                          time[i])
    return out


def mesh_pdf_batch(L, prim, p, q, normals=None, mode=OMNI):
    """`light_set.mesh_pdf` over n rows: (n,) pdfs, pick probability included."""
    return _mesh_rows(L, prim, receivers(p, normals, mode), q)


@kernel
def _mesh_rows(L, prim, rc, q):
    n = rc.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = mesh_pdf(L, prim[i], _recv(rc, i), q[i, 0], q[i, 1], q[i, 2], 0.0)
    return out


def sun_escaped_batch(L, j, d, time=None, p=None, normals=None, mode=OMNI):
    """The j-th non-delta sun for n escaped rays leaving the receivers p (the origin
    without them) (see `_sun_rows`)."""
    p = np.zeros((len(d), 3)) if p is None else p
    return _sun_rows(L, j, d, _times(time, len(d)), receivers(p, normals, mode))


@kernel
def _sun_rows(L, j, d, time, rc):
    """The j-th non-delta sun for n escaped rays: (radiance (n, 3), pdf (n,))."""
    n = d.shape[0]
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    for i in range(n):
        r, g, b, pd = sun_escaped(L, j, d[i, 0], d[i, 1], d[i, 2], _recv(rc, i), time[i])
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
    return rad, pdf


def world_escaped_batch(L, world, d, ray_bit=2, p=None, normals=None, mode=OMNI):
    """What n escaped rays along d of kind ray_bit (engine.visibility; diffuse by
    default), leaving the receivers p (the origin without them), see of the world:
    (radiance (n, 3), the MIS pdf of the world light along d (n,))."""
    d = np.ascontiguousarray(d, np.float64).reshape(-1, 3)
    p = np.zeros((len(d), 3)) if p is None else p
    return _world_rows(L, world, d, ray_bit, receivers(p, normals, mode))


@kernel
def _world_rows(L, world, d, ray_bit, rc):
    n = d.shape[0]
    rad = np.empty((n, 3))
    pdf = np.empty(n)
    for i in range(n):
        r, g, b, pd = world_escaped(L, world, ray_bit, d[i, 0], d[i, 1], d[i, 2],
                                    _recv(rc, i), 0.0)
        rad[i, 0], rad[i, 1], rad[i, 2] = r, g, b
        pdf[i] = pd
    return rad, pdf


def tree_pick_batch(L, u, p, normals=None, mode=OMNI, time=None, t=None):
    """The light tree's pick (tree.pick) for one receiver per uniform u (n,) (p (n, 3) or
    one point for all): (entries (n,) int64, probabilities (n,))."""
    u = np.ascontiguousarray(u, np.float64)
    p = np.broadcast_to(np.asarray(p, np.float64), (len(u), 3))
    if normals is not None:
        normals = np.broadcast_to(np.asarray(normals, np.float64), (len(u), 3))
    return _tree_rows(L, receivers(p, normals, mode, t), u, _times(time, len(u)))


@kernel
def _tree_rows(L, rc, u, time):
    n = u.shape[0]
    k_out = np.empty(n, dtype=np.int64)
    prob = np.empty(n)
    for i in range(n):
        k_out[i], prob[i] = tree_pick(L, _recv(rc, i), u[i], time[i])
    return k_out, prob
