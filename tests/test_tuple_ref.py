"""Tuples passed to kernels by reference (engine/kernels/tuple_ref.py): a kernel reads a
`by_ref` tuple as it reads the tuple itself (indices, negative ones, a named tuple's
fields), a kernel it calls gets one pointer instead of every array's fields, reference
counting stays balanced, a kernel may not return such a reference, and as plain Python
`by_ref` is the identity."""
import re
from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

from engine.kernels.jit import kernel
from engine.kernels.tuple_ref import TupleRef, by_ref
from test_kernel_borrowing import leaked_allocations


class Pair(NamedTuple):
    left: np.ndarray
    right: np.ndarray


@kernel(allocates=False)
def _weigh(t, i):
    """Reads members 0, 2 and -1 of a tuple or of a reference to one."""
    return t[0][i] + 10.0 * t[2][i] + 100.0 * t[-1][i]


@kernel(allocates=False)
def _fields(pair, i):
    return pair.left[i] - pair.right[i]


@kernel
def _counted(t, i):
    """The same reads in a kernel with reference counting (it allocates)."""
    scratch = np.empty(1)
    scratch[0] = t[0][i] + 10.0 * t[2][i] + 100.0 * t[-1][i]
    return scratch[0]


@kernel
def _through_refs(t, pair, n):
    ref, pref = by_ref(t), by_ref(pair)
    out = np.empty((n, 4))
    for i in range(n):
        out[i, 0] = _weigh(ref, i)
        out[i, 1] = _fields(pref, i)
        out[i, 2] = _counted(ref, i)
        out[i, 3] = ref[1][i]
    return out


@kernel
def _through_tuples(t, pair, n):
    out = np.empty((n, 4))
    for i in range(n):
        out[i, 0] = _weigh(t, i)
        out[i, 1] = _fields(pair, i)
        out[i, 2] = _counted(t, i)
        out[i, 3] = t[1][i]
    return out


def _arrays():
    rng = np.random.default_rng(7)
    t = (rng.random(9), rng.integers(0, 50, 9), rng.random((9, 2))[:, 0].copy(), rng.random(9))
    return t, Pair(rng.random(9), rng.random(9))


def test_a_reference_reads_as_the_tuple_does():
    t, pair = _arrays()
    by_tuple = _through_tuples(t, pair, 9)
    np.testing.assert_array_equal(_through_refs(t, pair, 9), by_tuple)
    # the reads are the intended ones (a control on the test itself)
    np.testing.assert_allclose(by_tuple[:, 0], t[0] + 10 * t[2] + 100 * t[3])
    np.testing.assert_allclose(by_tuple[:, 1], pair.left - pair.right)


def test_references_leak_nothing():
    t, pair = _arrays()
    _through_refs(t, pair, 9)
    assert leaked_allocations(lambda: _through_refs(t, pair, 9)) == 0


def test_a_callee_gets_one_pointer_not_the_arrays():
    """What makes a reference cheap: the callee's machine-level parameters. A tuple of
    four arrays is some thirty words; its reference is one. (Plain njit, not cached, so
    both signatures compile here and their LLVM IR can be read.)"""
    weigh = njit(_weigh.py_func)

    @njit
    def both(t):
        return weigh(t, 1) + weigh(by_ref(t), 1)

    t, _ = _arrays()
    assert both(t) == 2 * (t[0][1] + 10.0 * t[2][1] + 100.0 * t[3][1])

    def params(is_ref):
        for sig, ir in weigh.inspect_llvm().items():
            if isinstance(sig[0], TupleRef) == is_ref:
                define = re.search(r"define [^\n]*_weigh[^\n]*?\((.*)\)", ir).group(1)
                return define.count(",") + 1
        raise AssertionError(f"no {'reference' if is_ref else 'tuple'} signature")

    by_tuple, by_reference = params(False), params(True)
    print(f"the callee's parameters: {by_tuple} with the tuple, {by_reference} with its reference")
    assert by_tuple >= 30, by_tuple
    assert by_reference <= 6, by_reference


def test_anything_but_a_tuple_passes_through():
    @kernel
    def kinds(a, nothing):
        return by_ref(a)[1] + (1.0 if by_ref(nothing) is None else 0.0)

    assert kinds(np.array([1.0, 2.0]), None) == 3.0


def test_a_kernel_may_not_return_a_reference():
    @kernel
    def leaks(t):
        return by_ref(t)

    with pytest.raises(TypeError, match="reference to a tuple in its own frame"):
        leaks((np.zeros(2), np.ones(2)))


def test_plain_python_reads_the_tuple_itself():
    t, pair = _arrays()
    assert by_ref(t) is t
    out = _through_refs.py_func.__globals__["_weigh"].py_func(by_ref(t), 3)
    assert out == t[0][3] + 10.0 * t[2][3] + 100.0 * t[3][3]
