"""Array drivers of the Principled kernels (compiled too): one material row, facing flag
and wo per element, looping over the elements with one state vector. For tests (against
the NumPy `PrincipledBSDF`) and chi-square checks; the integrator calls the scalar
kernels directly."""
from __future__ import annotations

import numpy as np

from ..jit import kernel
from . import principled as P


@kernel
def eval_f_batch(rows, front, wo, wi, tables):
    """f (n, 3) of rows (n, NPARAM), front (n,) bool, wo (n, 3), wi (n, 3)."""
    n = wo.shape[0]
    out = np.zeros((n, 3))
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state)
        r, g, b = P.eval_f(state, wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2])
        out[k, 0] = r
        out[k, 1] = g
        out[k, 2] = b
    return out


@kernel
def pdf_batch(rows, front, wo, wi, allowed, tables):
    """Mixture pdf (n,) with allowed (n, 3) bool over DIFFUSE, GLOSSY, TRANSMISSION."""
    n = wo.shape[0]
    out = np.zeros(n)
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state)
        out[k] = P.pdf(state, wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2],
                       allowed[k, 0], allowed[k, 1], allowed[k, 2])
    return out


@kernel
def sample_batch(rows, front, wo, u_lobe, u_dir, allowed, tables):
    """(wi (n, 3), weight (n, 3), pdf (n,), kind (n,), delta (n,), valid (n,))."""
    n = wo.shape[0]
    wi = np.zeros((n, 3))
    weight = np.zeros((n, 3))
    pdf = np.zeros(n)
    kind = np.zeros(n, dtype=np.int64)
    delta = np.zeros(n, dtype=np.bool_)
    valid = np.zeros(n, dtype=np.bool_)
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state)
        s = P.sample(state, wo[k, 0], wo[k, 1], wo[k, 2], u_lobe[k], u_dir[k, 0],
                     u_dir[k, 1], allowed[k, 0], allowed[k, 1], allowed[k, 2])
        wi[k, 0], wi[k, 1], wi[k, 2] = s[0], s[1], s[2]
        weight[k, 0], weight[k, 1], weight[k, 2] = s[3], s[4], s[5]
        pdf[k] = s[6]
        kind[k] = s[7]
        delta[k] = s[8]
        valid[k] = s[9]
    return wi, weight, pdf, kind, delta, valid
