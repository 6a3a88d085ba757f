"""A bounding volume hierarchy over axis-aligned boxes, and the ray-box (slab) test that
walks it: the compiled building blocks of the hierarchy over moving objects
(`engine.kernels.motion_tlas`) and of the small per-object triangle hierarchies inside it.

A hierarchy is two arrays: node_box (N, 6), each row (lo x, lo y, lo z, hi x, hi y, hi z),
and node (N, 3), each row (is_leaf, first item or left child, item count or right child);
node 0 is the root, the right child of an inner node is its left child + 1, and the items
of a leaf are rows first .. first + count - 1 of the item order `build_hierarchy` returns.
"""
from __future__ import annotations

import numpy as np

from .jit import kernel

BINS = 16                     # SAH candidate splits per node: the bins' boundaries


@kernel
def build_hierarchy(item_box, leaf_size):
    """Binned surface-area-heuristic hierarchy over item boxes (I, 6). Returns
    (node_box (N, 6), node (N, 3), order (I,)): the nodes (see the module docstring) and
    the item order their leaves index into. Each node is split along the widest axis of
    its items' centroids at the bin boundary of least (count x surface area) summed over
    both sides; when every centroid falls in one bin, at the median."""
    n = item_box.shape[0]
    order = np.arange(n)
    cap = max(2 * n, 1)
    node_box = np.empty((cap, 6))
    node = np.zeros((cap, 3), np.int64)
    cent = np.empty((n, 3))
    for i in range(n):
        for c in range(3):
            cent[i, c] = 0.5 * (item_box[i, c] + item_box[i, 3 + c])
    stack = np.empty((cap, 3), np.int64)          # (node, first item, end item)
    sp = 0
    used = 1
    if n > 0:
        stack[0, 0], stack[0, 1], stack[0, 2] = 0, 0, n
        sp = 1
    nb = BINS
    bin_box = np.empty((nb, 6))
    bin_count = np.empty(nb, np.int64)
    tmp = np.empty(n, np.int64)
    clo, chi = np.empty(3), np.empty(3)
    while sp > 0:
        sp -= 1
        nd, start, end = stack[sp, 0], stack[sp, 1], stack[sp, 2]
        for c in range(3):
            node_box[nd, c], node_box[nd, 3 + c] = np.inf, -np.inf
            clo[c], chi[c] = np.inf, -np.inf
        for k in range(start, end):
            it = order[k]
            for c in range(3):
                node_box[nd, c] = min(node_box[nd, c], item_box[it, c])
                node_box[nd, 3 + c] = max(node_box[nd, 3 + c], item_box[it, 3 + c])
                clo[c] = min(clo[c], cent[it, c])
                chi[c] = max(chi[c], cent[it, c])
        count = end - start
        if count <= leaf_size:
            node[nd, 0], node[nd, 1], node[nd, 2] = 1, start, count
            continue
        axis = 0
        for c in range(1, 3):
            if chi[c] - clo[c] > chi[axis] - clo[axis]:
                axis = c
        extent = chi[axis] - clo[axis]
        mid = start
        if extent > 0.0:
            for b in range(nb):
                bin_count[b] = 0
                for c in range(3):
                    bin_box[b, c], bin_box[b, 3 + c] = np.inf, -np.inf
            for k in range(start, end):
                it = order[k]
                b = min(nb - 1, int((cent[it, axis] - clo[axis]) / extent * nb))
                bin_count[b] += 1
                for c in range(3):
                    bin_box[b, c] = min(bin_box[b, c], item_box[it, c])
                    bin_box[b, 3 + c] = max(bin_box[b, 3 + c], item_box[it, 3 + c])
            best_cost, best_b = np.inf, -1
            for split in range(1, nb):
                cost = _side_cost(bin_box, bin_count, 0, split) + _side_cost(
                    bin_box, bin_count, split, nb)
                if cost < best_cost:
                    best_cost, best_b = cost, split
            if best_b > 0:                 # partition: the items of bins < best_b first
                left, right = start, 0
                for k in range(start, end):
                    it = order[k]
                    if min(nb - 1, int((cent[it, axis] - clo[axis]) / extent * nb)) < best_b:
                        order[left] = it
                        left += 1
                    else:
                        tmp[right] = it
                        right += 1
                for k in range(right):
                    order[left + k] = tmp[k]
                mid = left
        if mid <= start or mid >= end:     # no useful bin boundary: split at the median
            keys = np.empty(count)
            for k in range(count):
                keys[k] = cent[order[start + k], axis]
            perm = np.argsort(keys, kind="mergesort")
            for k in range(count):
                tmp[k] = order[start + perm[k]]
            for k in range(count):
                order[start + k] = tmp[k]
            mid = start + count // 2
        l, r = used, used + 1
        used += 2
        node[nd, 0], node[nd, 1], node[nd, 2] = 0, l, r
        stack[sp, 0], stack[sp, 1], stack[sp, 2] = l, start, mid
        stack[sp + 1, 0], stack[sp + 1, 1], stack[sp + 1, 2] = r, mid, end
        sp += 2
    return node_box[:used].copy(), node[:used].copy(), order


@kernel(inline="always")
def _side_cost(bin_box, bin_count, b0, b1):
    """SAH cost of bins [b0, b1) as one child: items x half the surface area of their
    box; inf when they hold no item (a split with an empty side is no split)."""
    lo0, lo1, lo2 = np.inf, np.inf, np.inf
    hi0, hi1, hi2 = -np.inf, -np.inf, -np.inf
    cnt = 0
    for b in range(b0, b1):
        if bin_count[b] == 0:
            continue
        cnt += bin_count[b]
        lo0, lo1, lo2 = min(lo0, bin_box[b, 0]), min(lo1, bin_box[b, 1]), min(lo2, bin_box[b, 2])
        hi0, hi1, hi2 = max(hi0, bin_box[b, 3]), max(hi1, bin_box[b, 4]), max(hi2, bin_box[b, 5])
    if cnt == 0:
        return np.inf
    ex, ey, ez = hi0 - lo0, hi1 - lo1, hi2 - lo2
    return cnt * (ex * ey + ey * ez + ez * ex)


@kernel
def max_under_nodes(node, item_value):
    """Per node the largest item_value (I,) of the items in its subtree (items in the
    hierarchy's order); children are numbered after their parent."""
    out = np.empty(node.shape[0])
    for nd in range(node.shape[0] - 1, -1, -1):
        if node[nd, 0] == 1:
            m = -np.inf
            for i in range(node[nd, 1], node[nd, 1] + node[nd, 2]):
                m = max(m, item_value[i])
            out[nd] = m
        else:
            out[nd] = max(out[node[nd, 1]], out[node[nd, 2]])
    return out


@kernel
def grow_boxes(box, amount):
    """Boxes (K, 6) grown by amount[k] on every side, in place."""
    for k in range(box.shape[0]):
        for c in range(3):
            box[k, c] -= amount[k]
            box[k, 3 + c] += amount[k]


@kernel(inline="always")
def box_magnitude(box, k):
    """The largest absolute coordinate of box k."""
    return max(abs(box[k, 0]), abs(box[k, 1]), abs(box[k, 2]),
               abs(box[k, 3]), abs(box[k, 4]), abs(box[k, 5]))


@kernel(inline="always")
def slab_setup(o, d, pad):
    """Per-axis constants of `slab_entry` for a ray with origin component o and direction
    component d, against boxes grown by pad: (1 / d, o / d, pad / |d|). A zero component
    is replaced by +-1e30, which gives the same answer: (box - o) * 1e30 is beyond any
    tmax unless the origin lies within the slab (grown by pad)."""
    i = 1.0 / d if abs(d) >= 1e-30 else (1e30 if d >= 0.0 else -1e30)
    return i, o * i, pad * abs(i)


@kernel(inline="always")
def slab_entry(box, k, ix, iy, iz, px, py, pz, qx, qy, qz, tmax):
    """Where the ray prepared by `slab_setup` enters box k grown by its pad, within
    [0, tmax]; inf when it does not cross the box there."""
    ax, bx = box[k, 0] * ix - px, box[k, 3] * ix - px
    ay, by = box[k, 1] * iy - py, box[k, 4] * iy - py
    az, bz = box[k, 2] * iz - pz, box[k, 5] * iz - pz
    t0 = max(max(min(ax, bx) - qx, min(ay, by) - qy), max(min(az, bz) - qz, 0.0))
    t1 = min(min(max(ax, bx) + qx, max(ay, by) + qy), min(max(az, bz) + qz, tmax))
    return t0 if t0 <= t1 else np.inf
