"""The top-level hierarchy over the moving objects (a TLAS), so that a ray visits only the
moving objects it may hit instead of every one of them (`engine.kernels.motion_trace`
walks it; `engine.accel` uses it).

Query units: a rigidly moving object is one unit (its triangles in object space); a
deforming object is one unit per time slice (that slice's world triangles). Units come
in the global triangle order. The hierarchy's leaves are ITEMS, each a unit over a range
of time with world bounds valid at every time of the range:
- rigid: each motion interval [t_i, t_i+1] is cut into time segments, each bounded by
  its swept box (`engine.kernels.swept_bounds`); a ray matches the one segment its time
  falls in (times before the first step or after the last belong to the first or last
  segment, as RigidMotion.at clamps);
- deforming: one item per slice, bounded by the slice's vertices (exact: the slice is
  static); a ray matches the slice DeformMotion.slice_of gives for its time.

Small units (at most `kernel_triangles` triangles) get their own small hierarchy over
their triangles (a BLAS, in object or slice space) and are intersected inside the
traversal in float64; larger ones are left to their Embree scene.

Rounding: Embree intersects the ray moved into object space and rounded to float32 (and
the triangles rounded to float32), so its hit can lie a few float32 ulps, times the
transform's condition number, off the float64 world ray and box. Every box is therefore
grown by
    TOLERANCE * kappa * (|box|max + |translation|max)        when built, and by
    TOLERANCE * kappa_max * |origin|max                       at traversal, per ray,
with kappa >= 1 a bound on the object's condition number over the shutter
(`swept_bounds.condition_bound`; 1 for deforming objects, whose rays are not moved).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .box_hierarchy import box_magnitude, build_hierarchy, grow_boxes, max_under_nodes
from .jit import kernel
from .motion import (DEFORM, I_KIND, I_NVERTS, I_SLICES, I_STEP0, I_STEPS, I_VERT0,
                     adjugate_columns, interpolate_steps)
from .swept_bounds import condition_bound, corner_box, plan_interval, swept_box

TOLERANCE = 2.0 ** -16      # relative box growth: 256 float32 ulps
LEAF_ITEMS = 2              # items per TLAS leaf
LEAF_TRIANGLES = 4          # triangles per BLAS leaf
KERNEL_ROUNDING = 2.0 ** -40  # relative growth of BLAS boxes: the float64 tests' rounding


class MotionTLAS(NamedTuple):
    node_box: np.ndarray       # (N, 6) TLAS nodes (engine.kernels.box_hierarchy), grown
    node: np.ndarray           # (N, 3)
    item_box: np.ndarray       # (I, 6) leaf items in node order, grown
    item_unit: np.ndarray      # (I,) the item's unit
    item_slices: np.ndarray    # (I,) slices of a deforming object's item, 0 for rigid
    item_slice: np.ndarray     # (I,) the slice of a deforming object's item
    item_time: np.ndarray      # (I, 2) rigid items: the time range [t0, t1) they bound
    ray_pad: float             # TOLERANCE * the largest kappa (times |origin|max per ray)
    unit_obj: np.ndarray       # (U,) moving object of each unit
    unit_slice: np.ndarray     # (U,) time slice of a deforming object's unit, else 0
    unit_root: np.ndarray      # (U,) BLAS root node of a kernel unit, -1 for Embree
    blas_box: np.ndarray       # (B, 6) every kernel unit's BLAS nodes, one after another
    blas_node: np.ndarray      # (B, 3) children: global BLAS rows; leaves: blas_tri rows
    blas_tri: np.ndarray       # (T,) object-local triangle of each BLAS leaf entry
    translation_inverse: np.ndarray  # (S, 10) per step row (see translation_inverses)


@kernel
def _count_items(M, obj_lo, obj_hi, swept):
    """The number of items, and per step row the (segments, samples) of its interval."""
    info = M.info
    segments = np.ones(M.step_time.shape[0], np.int64)
    samples = np.ones(M.step_time.shape[0], np.int64)
    count = 0
    for o in range(info.shape[0]):
        if info[o, I_KIND] == DEFORM:
            count += info[o, I_SLICES]
            continue
        s0, k = info[o, I_STEP0], info[o, I_STEPS]
        if k == 1:
            count += 1
            continue
        for a in range(s0, s0 + k - 1):
            if swept:
                segments[a], samples[a] = plan_interval(M, a, obj_lo[o], obj_hi[o])
            count += segments[a]
    return count, segments, samples


@kernel
def _translation_magnitude(trans, a, b):
    m = 0.0
    for s in range(a, b):
        m = max(m, abs(trans[s, 0]), abs(trans[s, 1]), abs(trans[s, 2]))
    return m


@kernel
def _fill_items(M, obj_lo, obj_hi, swept, segments, samples, unit_of_obj, kappa,
                item_box, item_unit, item_slices, item_slice, item_time, item_growth):
    """Each item's box, unit, slice or time range, and growth (see the module
    docstring). swept=False: each rigid segment bounded by the object's box at the
    interval's first step only, which is NOT conservative (a negative control)."""
    info, times, verts, trans, linear = M.info, M.step_time, M.verts, M.step_trans, M.step_linear
    w = 0
    for o in range(info.shape[0]):
        if info[o, I_KIND] == DEFORM:
            nv, sl = info[o, I_NVERTS], info[o, I_SLICES]
            for s in range(sl):
                b = info[o, I_VERT0] + s * nv
                for c in range(3):
                    item_box[w, c], item_box[w, 3 + c] = np.inf, -np.inf
                for r in range(b, b + nv):
                    for c in range(3):
                        item_box[w, c] = min(item_box[w, c], verts[r, c])
                        item_box[w, 3 + c] = max(item_box[w, 3 + c], verts[r, c])
                item_unit[w], item_slices[w], item_slice[w] = unit_of_obj[o] + s, sl, s
                item_time[w, 0], item_time[w, 1] = -np.inf, np.inf
                item_growth[w] = TOLERANCE * box_magnitude(item_box, w)
                w += 1
            continue
        s0, k = info[o, I_STEP0], info[o, I_STEPS]
        lo, hi = obj_lo[o], obj_hi[o]
        reach = _translation_magnitude(trans, s0, s0 + k)
        if k == 1:
            for c in range(3):
                item_box[w, c], item_box[w, 3 + c] = np.inf, -np.inf
            corner_box(linear[s0, 0, 0], linear[s0, 0, 1], linear[s0, 0, 2], linear[s0, 1, 0],
                       linear[s0, 1, 1], linear[s0, 1, 2], linear[s0, 2, 0], linear[s0, 2, 1],
                       linear[s0, 2, 2], trans[s0, 0], trans[s0, 1], trans[s0, 2], lo, hi,
                       item_box[w])
            item_unit[w], item_slices[w], item_slice[w] = unit_of_obj[o], 0, 0
            item_time[w, 0], item_time[w, 1] = -np.inf, np.inf
            item_growth[w] = TOLERANCE * kappa[o] * (box_magnitude(item_box, w) + reach)
            w += 1
            continue
        for a in range(s0, s0 + k - 1):
            ns = segments[a]
            t0, t1 = times[a], times[a + 1]
            for j in range(ns):
                f0 = j / ns
                f1 = (j + 1) / ns if j + 1 < ns else 1.0
                if swept:
                    swept_box(M, a, lo, hi, f0, f1, samples[a], True, item_box[w])
                else:
                    swept_box(M, a, lo, hi, 0.0, 0.0, 1, False, item_box[w])
                item_unit[w], item_slices[w], item_slice[w] = unit_of_obj[o], 0, 0
                first, last = a == s0 and j == 0, a == s0 + k - 2 and j + 1 == ns
                item_time[w, 0] = -np.inf if first else t0 + (t1 - t0) * f0
                item_time[w, 1] = np.inf if last else (t1 if j + 1 == ns else t0 + (t1 - t0) * f1)
                item_growth[w] = TOLERANCE * kappa[o] * (box_magnitude(item_box, w) + reach)
                w += 1
    return w


@kernel
def _triangle_boxes(M, obj, vbase, out):
    """Bounds of each triangle of object obj with vertices from row vbase, grown by
    KERNEL_ROUNDING of their magnitude."""
    verts, tris = M.verts, M.tris
    row0 = M.prim_start[obj] - M.prim_start[0]
    for i in range(out.shape[0]):
        for c in range(3):
            lo, hi = np.inf, -np.inf
            for k in range(3):
                x = verts[vbase + tris[row0 + i, k], c]
                lo, hi = min(lo, x), max(hi, x)
            out[i, c], out[i, 3 + c] = lo, hi
        g = KERNEL_ROUNDING * box_magnitude(out, i) + 1e-300
        for c in range(3):
            out[i, c] -= g
            out[i, 3 + c] += g


@kernel
def translation_inverses(M, out):
    """Per motion step row a: (1, the inverse of the linear part row-major) when the
    interval a -> a + 1 only translates (rotation and stretch equal at both steps), so
    rays move into object space without a slerp; else all 0."""
    info, quat, stretch = M.info, M.step_quat, M.step_stretch
    out[:] = 0.0
    for o in range(info.shape[0]):
        if info[o, I_KIND] == DEFORM:
            continue
        s0, k = info[o, I_STEP0], info[o, I_STEPS]
        for a in range(s0, s0 + k - 1):
            same = True
            for c in range(4):
                same = same and quat[a, c] == quat[a + 1, c]
            for i in range(3):
                for j in range(3):
                    same = same and stretch[a, i, j] == stretch[a + 1, i, j]
            if not same:
                continue
            a00, a01, a02, a10, a11, a12, a20, a21, a22, _, _, _ = interpolate_steps(
                M.step_trans, quat, stretch, a, 0.0)
            r0x, r0y, r0z, r1x, r1y, r1z, r2x, r2y, r2z, det = adjugate_columns(
                a00, a01, a02, a10, a11, a12, a20, a21, a22)
            out[a, 0] = 1.0
            out[a, 1], out[a, 2], out[a, 3] = r0x / det, r0y / det, r0z / det
            out[a, 4], out[a, 5], out[a, 6] = r1x / det, r1y / det, r1z / det
            out[a, 7], out[a, 8], out[a, 9] = r2x / det, r2y / det, r2z / det


def _units(info):
    """(unit_obj, unit_slice, first unit of each object): one unit per rigid object,
    one per time slice of a deforming object, in object order."""
    n = len(info)
    per = (np.where(info[:, I_KIND] == DEFORM, info[:, I_SLICES], 1).astype(np.int64)
           if n else np.zeros(0, np.int64))
    first = np.concatenate([[0], np.cumsum(per)[:-1]]).astype(np.int64) if n else per
    unit_obj = np.repeat(np.arange(n, dtype=np.int64), per)
    unit_slice = np.arange(len(unit_obj), dtype=np.int64) - first[unit_obj]
    return unit_obj, unit_slice, first


def _triangle_hierarchies(M, unit_obj, unit_slice, kernel_triangles):
    """The BLAS of every unit of at most kernel_triangles triangles, concatenated:
    (unit_root, blas_box, blas_node, blas_tri)."""
    info, prim_start = M.info, M.prim_start
    unit_root = np.full(len(unit_obj), -1, np.int64)
    boxes, nodes, tris, nb, nt = [], [], [], 0, 0
    for un, o in enumerate(unit_obj):
        count = int(prim_start[o + 1] - prim_start[o])
        if count == 0 or count > kernel_triangles:
            continue
        vbase = info[o, I_VERT0] + (unit_slice[un] * info[o, I_NVERTS]
                                    if info[o, I_KIND] == DEFORM else 0)
        tb = np.empty((count, 6))
        _triangle_boxes(M, o, vbase, tb)
        box, node, order = build_hierarchy(tb, LEAF_TRIANGLES)
        inner = node[:, 0] == 0
        node[inner, 1:] += nb                     # children: global BLAS rows
        node[~inner, 1] += nt                     # leaves: rows of blas_tri
        unit_root[un] = nb
        boxes.append(box)
        nodes.append(node)
        tris.append(order.astype(np.int64))
        nb += len(box)
        nt += count
    return (unit_root, np.concatenate(boxes) if boxes else np.zeros((0, 6)),
            np.concatenate(nodes) if nodes else np.zeros((0, 3), np.int64),
            np.concatenate(tris) if tris else np.zeros(0, np.int64))


def build_tlas(M, obj_lo: np.ndarray, obj_hi: np.ndarray, swept: bool = True,
               kernel_triangles: int = 256) -> MotionTLAS:
    """The hierarchy over the moving objects packed in M (engine.kernels.motion), given
    each rigid object's object-space box obj_lo, obj_hi (n, 3) (ignored for deforming
    objects). swept=False is a negative control for tests (see `_fill_items`)."""
    n = len(M.info)
    obj_lo = np.ascontiguousarray(obj_lo, np.float64).reshape(n, 3)
    obj_hi = np.ascontiguousarray(obj_hi, np.float64).reshape(n, 3)
    unit_obj, unit_slice, unit_of_obj = _units(M.info)
    kappa = condition_bound(M)
    count, segments, samples = _count_items(M, obj_lo, obj_hi, swept)
    item_box = np.empty((count, 6))
    item_unit, item_slices, item_slice = (np.empty(count, np.int64) for _ in range(3))
    item_time, item_growth = np.empty((count, 2)), np.empty(count)
    filled = _fill_items(M, obj_lo, obj_hi, swept, segments, samples, unit_of_obj, kappa,
                         item_box, item_unit, item_slices, item_slice, item_time, item_growth)
    assert filled == count
    node_box, node, order = build_hierarchy(item_box, LEAF_ITEMS)
    if count == 0:
        node_box, node = np.zeros((0, 6)), np.zeros((0, 3), np.int64)
    item_box, item_unit, item_growth = item_box[order], item_unit[order], item_growth[order]
    item_slices, item_slice, item_time = item_slices[order], item_slice[order], item_time[order]
    # a node grown by the largest growth of its items holds every grown item box
    grow_boxes(node_box, max_under_nodes(node, item_growth))
    grow_boxes(item_box, item_growth)
    unit_root, blas_box, blas_node, blas_tri = _triangle_hierarchies(
        M, unit_obj, unit_slice, kernel_triangles)
    inverses = np.empty((len(M.step_time), 10))
    translation_inverses(M, inverses)
    c = np.ascontiguousarray
    return MotionTLAS(c(node_box), c(node), c(item_box), c(item_unit), c(item_slices),
                      c(item_slice), c(item_time), float(TOLERANCE * kappa.max(initial=1.0)),
                      c(unit_obj), c(unit_slice), c(unit_root), c(blas_box), c(blas_node),
                      c(blas_tri), c(inverses))
