"""Rays that do not hit the surface they leave, as Cycles casts them (its ray `self`
primitives and the Embree filter of kernel/device/cpu/bvh.h).

A ray leaving a surface starts exactly on it, with no offset, and names the primitive it
leaves (and, for a shadow ray towards an emissive triangle, the one it goes to). Embree
calls this filter for each candidate hit; a hit on a named primitive is rejected and
traversal goes on. Anything else is hit, even at distance 0: a coincident face, a cube
resting on a floor, the other half of a mirrored mesh, as in Cycles.

The names are DRT's global ids (engine.accel): the global triangle or curve segment and
the object-table row of its place (-1 unless it is an instanced mesh's). The filter maps
a candidate's Embree ids to them as engine.accel does for hits: the top scene's geometry
it belongs to (the instance's, for a hit inside one) gives the first global id and the
first row, and the primitive and element ids are added.

The query's memory (per thread, engine.embree.rays.RayRecord.q, int64 words): Embree's
RTCIntersectArguments (the same layout as RTCOccludedArguments), then its
RTCRayQueryContext (instID, instPrimID: one 64-bit word), then DRT's words the filter
reads from the context pointer Embree hands it.
"""
from __future__ import annotations

import ctypes

import numpy as np
from numba import carray

from ..kernels.jit import filter_address as jit_filter_address

from .curve_culling import _pointer, _view

# RTCIntersectArguments / RTCOccludedArguments: flags (uint32) and feature mask (uint32)
# in word 0, then the context, filter and user-geometry callback pointers, and the
# minimum-width factor of builds with RTC_MIN_WIDTH
Q_FLAGS, Q_CONTEXT, Q_FILTER, Q_CALLBACK, Q_MIN_WIDTH = 0, 1, 2, 3, 4
# the context, from word 6: Embree's instance stack, then DRT's
Q_CONTEXT_AT = 6
C_SKIP_PRIM, C_SKIP_ROW, C_LIGHT_PRIM, C_LIGHT_ROW, C_BASE, C_ROW = 1, 2, 3, 4, 5, 6
Q_FILTER_ADDRESS = Q_CONTEXT_AT + 7       # the filter, kept while a ray names nothing
Q_CURVE_GEOM = Q_CONTEXT_AT + 8           # the top scene's curve geometry id (-1: none)
Q_WORDS = Q_CONTEXT_AT + 9
# how far inside its triangle a reported hit lies, in barycentrics (twice FLT_EPSILON;
# engine.embree.rays.inside)
INSIDE = 2.0 ** -22
# RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER (every geometry's candidates), incoherent
# rays, every feature (RTC_FEATURE_FLAG_ALL in the high half)
FLAGS_WORD = np.int64((2 | (0xFFFFFFFF << 32)) - (1 << 64))

# RTCFilterFunctionNArguments: int* valid, void* geometryUserPtr, context, RTCRayN* ray,
# RTCHitN* hit, unsigned int N. RTCHitN holds each field for the N hits one after the
# other: Ng (3), u, v, primID, geomID, instID[1], instPrimID[1] (9 fields)
_VALID, _CONTEXT, _HIT, _N = 0, 2, 4, 5
_PRIM, _GEOM, _INST, _INST_PRIM, _HIT_FIELDS = 5, 6, 7, 8, 9
_INVALID = np.uint32(0xFFFFFFFF)
_ANY = 1 << 32


def _filter(args):
    """Mark invalid each of the N candidate hits on a primitive the context names (one
    function, no call inside: this runs for every candidate hit of a named ray)."""
    words = carray(args, 6, np.uint64)
    n = np.int64(words[_N] & np.uint64(0xFFFFFFFF))
    context = carray(_pointer(words[_CONTEXT]), C_ROW + 1, np.int64)
    hit = carray(_pointer(words[_HIT]), _HIT_FIELDS * n, np.uint32)
    valid = carray(_pointer(words[_VALID]), n, np.int32)
    # the geometry tables, as views of a length no id reaches (a view allocates nothing)
    geom_base = carray(_pointer(np.uint64(context[C_BASE])), _ANY, np.int64)
    geom_row = carray(_pointer(np.uint64(context[C_ROW])), _ANY, np.int64)
    for i in range(n):
        if valid[i] == 0:
            continue
        inst = hit[_INST * n + i]
        owner = np.int64(inst if inst != _INVALID else hit[_GEOM * n + i])
        prim = geom_base[owner] + np.int64(hit[_PRIM * n + i])
        row = geom_row[owner]
        if row >= 0:
            element = hit[_INST_PRIM * n + i]
            row += 0 if element == _INVALID else np.int64(element)
        if ((prim == context[C_SKIP_PRIM] and row == context[C_SKIP_ROW])
                or (prim == context[C_LIGHT_PRIM] and row == context[C_LIGHT_ROW])):
            valid[i] = 0


def _filter_python(args):
    """_filter as plain Python (NUMBA_DISABLE_JIT=1), through ctypes."""
    words = np.ctypeslib.as_array(args, (6,))
    n = int(words[_N]) & 0xFFFFFFFF
    context = _view(words[_CONTEXT], C_ROW + 1, ctypes.c_int64)
    hit = _view(words[_HIT], _HIT_FIELDS * n, ctypes.c_uint32)
    valid = _view(words[_VALID], n, ctypes.c_int32)
    for i in range(n):
        inst, geom = int(hit[_INST * n + i]), int(hit[_GEOM * n + i])
        owner = inst if inst != _INVALID else geom
        prim = int(_view(context[C_BASE] + 8 * owner, 1, ctypes.c_int64)[0]) \
            + int(hit[_PRIM * n + i])
        row = int(_view(context[C_ROW] + 8 * owner, 1, ctypes.c_int64)[0])
        if row >= 0:
            element = int(hit[_INST_PRIM * n + i])
            row += 0 if element == _INVALID else element
        if valid[i] and ((prim, row) == (context[C_SKIP_PRIM], context[C_SKIP_ROW])
                         or (prim, row) == (context[C_LIGHT_PRIM], context[C_LIGHT_ROW])):
            valid[i] = 0


def filter_address() -> int:
    """The address of the compiled filter (RTCFilterFunctionN), compiled on first use
    (engine.kernels.jit.filter_address)."""
    return jit_filter_address(_filter, _filter_python)
