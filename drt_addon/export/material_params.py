"""Material parameters as the exporter combines them ("Params"): a plain value (a float
or an RGB triple) or a NodeParam, a value of the material's shader program that varies
per hit. Linear combinations of Params are exact: NodeParams are combined by the
program."""
from __future__ import annotations

import importlib

import numpy as np

from ..engine_link import engine

cv = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
ve = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")

TOL = 1e-6


class NodeParam:
    """A per-hit parameter: a register of the material's program (NodeCompiler)."""

    def __init__(self, value, nodes):
        self.value = value
        self.nodes = nodes
        self._mean = None

    @property
    def is_color(self) -> bool:
        return self.value.width == 3

    def mean(self):
        """A summary: the average over the unit square of UV and generated coordinates."""
        if self._mean is None:
            self._mean = self.nodes.mean(self.value)
        return self._mean

    def scaled(self, factor, add=0.0) -> "NodeParam":
        """factor x this + add (factor: a float or a NodeParam; add: float or triple)."""
        return NodeParam(_affine(self.nodes, self.value, factor, add), self.nodes)


def _affine(nodes, value, factor, add):
    f = factor.value if isinstance(factor, NodeParam) else nodes.const(float(factor))
    if value.width == 1 and f.width == 1:
        return nodes.emit(cv.CV_MATH, "float", [value, f, nodes.const(float(np.mean(add))),
                                                cv.MATH_OPS.index("MULTIPLY_ADD"), 0])
    if value.width == 1:
        value, f = f, value
    out = nodes.emit(ve.VEC_MATH, "vector", [value, value, value, nodes.convert(f, "float"),
                                             ve.VECTOR_OPS.index("SCALE")])
    if np.any(np.asarray(add, np.float64) != 0.0):
        a = nodes.const(tuple(np.broadcast_to(np.asarray(add, np.float64), (3,))), "vector")
        out = nodes.emit(ve.VEC_MATH, "vector", [out, a, a, a, ve.VECTOR_OPS.index("ADD")])
    return nodes.convert(out, "color")


def _is_tex(p) -> bool:
    return isinstance(p, NodeParam)


def _mean(p):
    return p.mean() if _is_tex(p) else p


def _plain(a):
    a = np.asarray(a, np.float64)
    return tuple(float(x) for x in a) if a.ndim else float(a)


def _same(a, b) -> bool:
    if a is None or b is None:
        return a is b
    if _is_tex(a) or _is_tex(b):
        return _is_tex(a) and _is_tex(b) and a.value.reg == b.value.reg
    return bool(np.allclose(np.asarray(a, float), np.asarray(b, float), atol=TOL))


def _scale(p, f):
    """p x f; f a float or a NodeParam (then p must be a Param of the same program)."""
    if _is_tex(f):
        if _is_tex(p):
            return p.scaled(f)
        if not np.any(np.asarray(p, np.float64)):
            return p
        if np.ndim(p) == 0:
            return f.scaled(float(p))
        c = f.nodes.const(tuple(p), "color")
        return NodeParam(_affine(f.nodes, c, f, 0.0), f.nodes)
    if _is_tex(p):
        if f == 0:
            return _plain(np.zeros(3)) if p.is_color else 0.0
        return p.scaled(f)
    return _plain(np.asarray(p, np.float64) * f)


def _lin(terms, ctx, what):
    """sum_i w_i p_i of Params, exact: NodeParams are summed by the program."""
    const = None
    node = None
    for w, p in terms:
        if w == 0 or p is None:
            continue
        if _is_tex(p):
            term = p.scaled(w)
            if node is None:
                node = term
            else:
                kind = "float" if node.value.width == 1 else "vector"
                a = ctx.nodes.convert(node.value, kind)
                b = ctx.nodes.convert(term.value, kind)
                if kind == "float":
                    s = ctx.nodes.emit(cv.CV_MATH, "float", [a, b, b, cv.MATH_OPS.index("ADD"),
                                                             0])
                else:
                    s = ctx.nodes.convert(ctx.nodes.emit(ve.VEC_MATH, "vector",
                                                         [a, b, b, b,
                                                          ve.VECTOR_OPS.index("ADD")]),
                                          "color")
                node = NodeParam(s, ctx.nodes)
            continue
        v = np.asarray(p, np.float64) * w
        const = v if const is None else const + v
    if node is None:
        return _plain(const) if const is not None else None
    return node.scaled(1.0, add=const if const is not None else 0.0)
