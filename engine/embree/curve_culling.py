"""Back-face culling of curve hits, as Cycles' Embree is built (EMBREE_BACKFACE_CULLING_CURVES
ON in Blender's build of Embree): a ray meets a hair strand only where it enters the
tube, never on the inside of its wall. A ray that starts on a strand and leaves through
it (a shadow ray towards a lamp behind the strand, a transmitted ray) passes, and a
camera looking down a strand's axis sees through its open end, as in Cycles.

The Embree library DRT loads (the embreex wheel's) is built without that option, so the
same test runs as Embree's filter functions on the curve geometries: Embree calls them
for each candidate hit, and they reject it when the ray's direction and the hit's
geometric normal (outward for round curves) point the same way. The filter is one small
compiled C callback (a Numba cfunc, cached like the kernels), built the first time a
scene has curves.
"""
from __future__ import annotations

import ctypes

import numpy as np
from numba import carray, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from ..kernels.jit import filter_address as jit_filter_address

# RTCFilterFunctionNArguments: int* valid, void* geometryUserPtr, context, RTCRayN* ray,
# RTCHitN* hit, unsigned int N (each a 64-bit word here)
_VALID, _RAY, _HIT, _N = 0, 3, 4, 5
# RTCRayN / RTCHitN hold each field for the N rays one after the other (field k of ray i
# at float k * N + i): a ray's 12 fields, its direction the 5th to 7th; a hit's normal
# its first 3
_RAY_FIELDS, _DIR_X, _NG_X = 12, 4, 0


def _reject_backfacing(valid, ray, hit, n):
    """Mark invalid each of the n candidate hits whose normal faces along the ray."""
    for i in range(n):
        if valid[i] == 0:
            continue
        d = (ray[_DIR_X * n + i] * hit[_NG_X * n + i]
             + ray[(_DIR_X + 1) * n + i] * hit[(_NG_X + 1) * n + i]
             + ray[(_DIR_X + 2) * n + i] * hit[(_NG_X + 2) * n + i])
        if d > 0.0:
            valid[i] = 0


_reject = njit(cache=True)(_reject_backfacing)


@intrinsic
def _pointer(typingctx, address):
    """The integer `address` as a void pointer (for carray)."""
    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], cgutils.voidptr_t)
    return types.voidptr(types.uint64), codegen


def _cull(args):
    words = carray(args, 6, np.uint64)
    n = np.int64(words[_N] & np.uint64(0xFFFFFFFF))
    _reject(carray(_pointer(words[_VALID]), n, np.int32),
            carray(_pointer(words[_RAY]), _RAY_FIELDS * n, np.float32),
            carray(_pointer(words[_HIT]), 3 * n, np.float32), n)


def _view(address, count, ctype):
    return np.ctypeslib.as_array(ctypes.cast(int(address), ctypes.POINTER(ctype)), (count,))


def _cull_python(args):
    """_cull as plain Python (NUMBA_DISABLE_JIT=1), through ctypes."""
    words = np.ctypeslib.as_array(args, (6,))
    n = int(words[_N]) & 0xFFFFFFFF
    _reject(_view(words[_VALID], n, ctypes.c_int32),
            _view(words[_RAY], _RAY_FIELDS * n, ctypes.c_float),
            _view(words[_HIT], 3 * n, ctypes.c_float), n)


def filter_address() -> int:
    """The address of the compiled filter (RTCFilterFunctionN), compiled on first use
    (engine.kernels.jit.filter_address)."""
    return jit_filter_address(_cull, _cull_python)
