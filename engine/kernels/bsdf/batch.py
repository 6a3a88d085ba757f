"""Array drivers of the Principled kernels (compiled too): one material row, facing flag
and wo per element, looping over the elements with one state vector (`walter`: glass
refraction on Walter's pairs only, the sampler's own density, as path_vertex sets it
towards some lights; otherwise Cycles' pairs, kernels/bsdf/dielectric.py); and `Principled`,
the same BSDF as an object over arrays of hits. For the tests' oracles (chi-square,
furnace, reciprocity, moments, Cycles), the table generators and anyone who wants to
probe the BSDF from Python; the integrator calls the scalar kernels directly."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..jit import kernel
from . import params as R
from . import principled as P
from .joint_sample import sample_joint
from .state import S_WALTER


@kernel
def eval_seen_batch(rows, front, wo, wi, allowed, tables, walter=False):
    """f (n, 3) of the lobes `allowed` (n, 3) bool sees (DIFFUSE, GLOSSY, TRANSMISSION)."""
    n = wo.shape[0]
    out = np.zeros((n, 3))
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state)
        if walter:
            state[S_WALTER] = 1.0
        r, g, b = P.eval_seen(state, wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1],
                              wi[k, 2], allowed[k, 0], allowed[k, 1], allowed[k, 2])
        out[k, 0] = r
        out[k, 1] = g
        out[k, 2] = b
    return out


def eval_f_batch(rows, front, wo, wi, tables, walter=False):
    """f (n, 3) of rows (n, NPARAM), front (n,) bool, wo (n, 3), wi (n, 3): every lobe."""
    every = np.ones((wo.shape[0], 3), dtype=np.bool_)
    return eval_seen_batch(rows, front, wo, wi, every, tables, walter)


@kernel
def pdf_batch(rows, front, wo, wi, allowed, tables, walter=False, diffuse_n=(0.0, 0.0, 1.0)):
    """Mixture pdf (n,) with allowed (n, 3) bool over DIFFUSE, GLOSSY, TRANSMISSION
    (diffuse_n: the diffuse and sheen lobes' normal, principled.setup_about)."""
    n = wo.shape[0]
    out = np.zeros(n)
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup_about(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state,
                      diffuse_n[0], diffuse_n[1], diffuse_n[2])
        if walter:
            state[S_WALTER] = 1.0
        out[k] = P.pdf(state, wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2],
                       allowed[k, 0], allowed[k, 1], allowed[k, 2])
    return out


@kernel
def sample_batch(rows, front, wo, u_lobe, u_dir, allowed, tables, walter=False,
                 diffuse_n=(0.0, 0.0, 1.0), joint=False):
    """(wi (n, 3), weight (n, 3), pdf (n,), kind (n,), delta (n,), valid (n,)); `joint`:
    the path tracer's joint_sample.sample_joint (the lobe from u_dir's first number,
    u_lobe the rest), else principled.sample."""
    n = wo.shape[0]
    wi = np.zeros((n, 3))
    weight = np.zeros((n, 3))
    pdf = np.zeros(n)
    kind = np.zeros(n, dtype=np.int64)
    delta = np.zeros(n, dtype=np.bool_)
    valid = np.zeros(n, dtype=np.bool_)
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup_about(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state,
                      diffuse_n[0], diffuse_n[1], diffuse_n[2])
        if walter:
            state[S_WALTER] = 1.0
        if joint:
            s = sample_joint(state, wo[k, 0], wo[k, 1], wo[k, 2], u_lobe[k], u_dir[k, 0],
                             u_dir[k, 1], allowed[k, 0], allowed[k, 1], allowed[k, 2])
        else:
            s = P.sample(state, wo[k, 0], wo[k, 1], wo[k, 2], u_lobe[k], u_dir[k, 0],
                         u_dir[k, 1], allowed[k, 0], allowed[k, 1], allowed[k, 2])
        wi[k, 0], wi[k, 1], wi[k, 2] = s[0], s[1], s[2]
        weight[k, 0], weight[k, 1], weight[k, 2] = s[3], s[4], s[5]
        pdf[k] = s[6]
        kind[k] = s[7]
        delta[k] = s[8]
        valid[k] = s[9]
    return wi, weight, pdf, kind, delta, valid


@kernel
def setup_batch(rows, front, wo, tables, walter=False):
    """The state vectors (n, NSTATE) `principled.setup` fills (slots: state.py)."""
    n = wo.shape[0]
    out = np.zeros((n, P.NSTATE))
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, out[k])
        if walter:
            out[k, S_WALTER] = 1.0
    return out


@kernel
def selection_batch(rows, front, wo, allowed, tables, walter=False):
    """Lobe probabilities (n, 11) of `principled.selection` (diffuse, specular, metal,
    glass; coat, sheen, translucent, hair R, hair TT; subsurface; Principled Hair)."""
    n = wo.shape[0]
    out = np.zeros((n, 11))
    state = np.empty(P.NSTATE)
    for k in range(n):
        P.setup(rows[k], front[k], wo[k, 0], wo[k, 1], wo[k, 2], tables, state)
        if walter:
            state[S_WALTER] = 1.0
        q = P.selection(state, allowed[k, 0], allowed[k, 1], allowed[k, 2])
        for j in range(11):
            out[k, j] = q[j]
    return out


class Sample(NamedTuple):
    wi: np.ndarray        # (n, 3) local direction
    weight: np.ndarray    # (n, 3) f |cos| / pdf (zero where sampling failed)
    pdf: np.ndarray       # (n,) mixture pdf over the allowed lobes (inf for a delta)
    kind: np.ndarray      # (n,) lobe kind: P.DIFFUSE, P.GLOSSY, P.TRANSMISSION, P.SUBSURFACE
    delta: np.ndarray     # (n,) bool: a perfectly specular choice
    valid: np.ndarray     # (n,) bool


class Principled:
    """The compiled Principled BSDF at n hits: material rows (n, NPARAM) (`params`) and
    facing flags (n,). `from_materials` packs `engine.scene.Material`s; `allowed` masks
    are (n, 3) or (3,) bools over DIFFUSE, GLOSSY, TRANSMISSION, None for all."""

    def __init__(self, rows, front=True, walter=False):
        self.walter = walter
        self.rows = np.ascontiguousarray(rows, dtype=np.float64)
        self.n = len(self.rows)
        self.front = np.ascontiguousarray(np.broadcast_to(np.asarray(front, bool), (self.n,)))
        self.tables = P.kernel_tables()

    @classmethod
    def from_materials(cls, table, index, front=True, filter_alpha=None):
        """The materials of the MaterialTable `table` at the hits `index` (n,)."""
        rows = R.pack_materials(table)[np.asarray(index)]
        if filter_alpha is not None:
            rows[:, R.P_FILTER_ALPHA] = filter_alpha
        return cls(rows, front)

    @classmethod
    def with_params(cls, base_color, metallic=0.0, transmission=0.0, roughness=0.5,
                    ior=1.5, specular_ior_level=0.5, front=True,
                    glossy_model=R.GLOSSY_GGX, walter=False):
        """Per-hit Principled inputs (arrays (n,) or scalars, base_color (n, 3)) with no
        textures, coat or sheen: rows of the base lobes only."""
        base = np.asarray(base_color, dtype=np.float64).reshape(-1, 3)
        n = len(base)
        rows = np.zeros((n, R.NPARAM))
        rows[:, R.P_BASE:R.P_BASE + 3] = base
        for col, v in ((R.P_METALLIC, metallic), (R.P_TRANSMISSION, transmission),
                       (R.P_ROUGHNESS, roughness), (R.P_IOR, ior),
                       (R.P_SPEC_LEVEL, specular_ior_level), (R.P_GLOSSY_MODEL, glossy_model)):
            rows[:, col] = v
        rows[:, R.P_SPEC_TINT:R.P_SPEC_TINT + 3] = 1.0         # no Specular Tint
        rows[:, R.P_GLASS_REFLECT:R.P_GLASS_REFLECT + 3] = 1.0  # nor a reflection tint
        return cls(rows, front, walter)

    @classmethod
    def of(cls, n, front=True, **material):
        """n hits of one `engine.scene.Material(**material)`."""
        from ...bsdf.material_table import MaterialTable
        from ...scene import Material
        return cls.from_materials(MaterialTable([Material(**material)]),
                                  np.zeros(n, np.int64), front)

    def _allowed(self, allowed):
        a = np.ones(3, bool) if allowed is None else np.asarray(allowed, bool)
        return np.ascontiguousarray(np.broadcast_to(a, (self.n, 3)))

    def _dirs(self, w):
        return np.ascontiguousarray(np.broadcast_to(np.asarray(w, np.float64), (self.n, 3)))

    def eval_f(self, wo, wi, allowed=None):
        """f (n, 3): every lobe, or the `allowed` ones."""
        if allowed is None:
            return eval_f_batch(self.rows, self.front, self._dirs(wo), self._dirs(wi),
                                self.tables, self.walter)
        return eval_seen_batch(self.rows, self.front, self._dirs(wo), self._dirs(wi),
                               self._allowed(allowed), self.tables, self.walter)

    def pdf(self, wo, wi, allowed=None, diffuse_n=(0.0, 0.0, 1.0)):
        """The pdf (n,) over wi of `sample` with the same `allowed` (and diffuse_n)."""
        return pdf_batch(self.rows, self.front, self._dirs(wo), self._dirs(wi),
                         self._allowed(allowed), self.tables, self.walter,
                         tuple(float(x) for x in diffuse_n))

    def states(self, wo=(0.0, 0.0, 1.0)):
        """The per-hit state vectors (n, NSTATE) at wo (slots: state.py)."""
        return setup_batch(self.rows, self.front, self._dirs(wo), self.tables, self.walter)

    def selection(self, wo, allowed=None):
        """The probabilities (n, 10) with which `sample` picks each lobe at wo."""
        return selection_batch(self.rows, self.front, self._dirs(wo),
                               self._allowed(allowed), self.tables, self.walter)

    def sample(self, wo, u_lobe, u_dir, allowed=None, diffuse_n=(0.0, 0.0, 1.0)) -> Sample:
        """Directions drawn at wo; diffuse_n: the diffuse lobe's unit normal in the
        local frame (a bent frame's raw normal, principled.setup_about; the sheen's too)."""
        u_lobe = np.ascontiguousarray(np.broadcast_to(np.asarray(u_lobe, np.float64), (self.n,)))
        u_dir = np.ascontiguousarray(np.broadcast_to(np.asarray(u_dir, np.float64), (self.n, 2)))
        return Sample(*sample_batch(self.rows, self.front, self._dirs(wo), u_lobe, u_dir,
                                    self._allowed(allowed), self.tables, self.walter,
                                    tuple(float(x) for x in diffuse_n)))
