"""Building the light tree: a binary hierarchy over the light set's entries, each node
bounding its lights' positions (a box), emission directions (a cone, tree_cone.py) and
energy, as Cycles builds its light tree (Conty Estevez and Kulla 2018, with Cycles'
additions: distant lights in a leaf of their own beside the local lights, at most eight
lights per leaf, splits by the surface area orientation heuristic over 12 buckets).

`tree_arrays(L, models)` gives the three arrays the kernels read (tree.py):

  nodes  float64 (n_nodes, N_NODE): node 0 is the root. Fields N_*: the box, the cone,
         the energy, the kind (INNER, LEAF or DISTANT, a leaf of suns and the world), for
         an inner node its two children (N_A, N_B), for a leaf its first slot and its
         count, and every node's parent (-1 for the root).
  slots  int64 (n_slots,): light entries in leaf order (a leaf holds slots[first:first +
         count]).
  emit   float64 (n_entries, N_EMIT): each entry's centroid, cone, energy and leaf (E_LEAF,
         -1 for an entry the tree leaves out: one of no energy, never picked).

Energies are Cycles': a point or spot lamp's intensity (strength / 4 pi), an area lamp's
or a triangle's radiance x area, a sun's irradiance, the world's radiance x pi; the mean
of the three channels. A lamp that moves during the shutter is bounded over all its
slices.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .pack import (C_AREA, C_AX, C_AXIS, C_AY, C_CENTER, C_COS_HALF, C_INTENSITY,
                   C_IS_SPOT, C_IRRADIANCE, C_NORMAL, C_ONE_MINUS, C_POS, C_RAD, C_RADIUS,
                   C_TAN_SPREAD, C_TO_LIGHT, C_TYPE, LAMP_SLICES, LAMPS, SLICE_OF, T_AREA,
                   T_DISC, T_POINT, T_SPHERE, T_SUN, T_SUN_DELTA, TRI_AREA, TRI_E1, TRI_E2,
                   TRI_NORMAL, TRI_RADIANCE, TRI_V0, TRI_VISIBILITY, NEE_BACK_OFF,
                   NEE_FRONT_OFF)
from .tree_cone import EMPTY, box_measure, measure, merge

PI = math.pi
MAX_IN_LEAF = 8
BUCKETS = 12

# ---------------------------------------------------------------- node fields
N_MIN = 0           # 3: the box
N_MAX = 3           # 3
N_AXIS = 6          # 3: the cone
N_THETA_O = 9
N_THETA_E = 10
N_ENERGY = 11
N_KIND = 12
N_A = 13            # inner: left child; leaf: first slot
N_B = 14            # inner: right child; leaf: count
N_PARENT = 15
N_CONE = 16         # 4: the cone's terms for the kernels (`cone_terms`)
N_NODE = 20
INNER = 0.0
LEAF = 1.0
DISTANT = 2.0

# ---------------------------------------------------------------- entry fields
E_CENTROID = 0      # 3
E_AXIS = 3          # 3
E_THETA_O = 6
E_THETA_E = 7
E_ENERGY = 8
E_LEAF = 9
E_MIN = 10          # 3: the entry's box
E_MAX = 13          # 3
E_CONE = 16         # 4: the cone's terms (`cone_terms`)
N_EMIT = 20


def cone_terms(theta_o, theta_e):
    """What the importance needs of cones (tree.importance), so that no kernel takes a
    cosine per node: (n, 4) of cos theta_o, sin theta_o, cos(theta_o + theta_e) (or -2
    when that sum passes pi: every direction is within reach), cos(theta_e - theta_o)
    (or 2 when theta_e < theta_o: no lower bound)."""
    theta_o, theta_e = np.asarray(theta_o, float), np.asarray(theta_e, float)
    return np.stack([np.cos(theta_o), np.sin(theta_o),
                     np.where(theta_o + theta_e > PI, -2.0, np.cos(theta_o + theta_e)),
                     np.where(theta_e < theta_o, 2.0, np.cos(theta_e - theta_o))], axis=-1)


def _rows(L, k):
    """Lamp k's rows: its slices when it moves, else its one row."""
    first, count = L[SLICE_OF][k]
    if count:
        return L[LAMP_SLICES][first:first + count]
    return L[LAMPS][k:k + 1]


def _lamp_measure(L, k, models, e):
    """Fill e (N_EMIT) for lamp k; returns whether it is distant (a sun or the world)."""
    rows = _rows(L, k)
    row = L[LAMPS][k]
    kind = int(row[C_TYPE])
    e[E_AXIS:E_AXIS + 3] = 0.0, 0.0, 1.0
    if kind in (T_POINT, T_SPHERE, T_DISC):
        r = rows[:, C_RADIUS:C_RADIUS + 1]
        e[E_MIN:E_MIN + 3] = (rows[:, C_POS:C_POS + 3] - r).min(axis=0)
        e[E_MAX:E_MAX + 3] = (rows[:, C_POS:C_POS + 3] + r).max(axis=0)
        e[E_CENTROID:E_CENTROID + 3] = row[C_POS:C_POS + 3]
        e[E_ENERGY] = np.abs(row[C_INTENSITY:C_INTENSITY + 3]).mean()
        if row[C_IS_SPOT] != 0.0:
            e[E_THETA_O], e[E_THETA_E] = _slices_cone(rows, C_AXIS, 1.0,
                                                      min(math.acos(min(1.0, max(
                                                          -1.0, row[C_COS_HALF]))), PI / 2),
                                                      e)
        else:
            e[E_THETA_O], e[E_THETA_E] = PI, PI / 2
        return False
    if kind == T_AREA:
        corners = []
        for s in rows:
            for a in (-1.0, 1.0):
                for b in (-1.0, 1.0):
                    corners.append(s[C_CENTER:C_CENTER + 3] + a * s[C_AX:C_AX + 3]
                                   + b * s[C_AY:C_AY + 3])
        corners = np.array(corners)
        e[E_MIN:E_MIN + 3] = corners.min(axis=0)
        e[E_MAX:E_MAX + 3] = corners.max(axis=0)
        e[E_CENTROID:E_CENTROID + 3] = row[C_CENTER:C_CENTER + 3]
        e[E_ENERGY] = np.abs(row[C_RAD:C_RAD + 3]).mean() * row[C_AREA]
        # a Spread narrows each point's emission to its half angle (Cycles' theta_e)
        spread = math.atan(row[C_TAN_SPREAD]) if row[C_TAN_SPREAD] != 0.0 else PI / 2
        e[E_THETA_O], e[E_THETA_E] = _slices_cone(rows, C_NORMAL, -1.0, spread, e)
        return False
    if kind in (T_SUN, T_SUN_DELTA):
        half = 0.0 if kind == T_SUN_DELTA else 2.0 * math.asin(math.sqrt(
            max(0.0, min(1.0, 0.5 * row[C_ONE_MINUS]))))
        e[E_ENERGY] = np.abs(row[C_IRRADIANCE:C_IRRADIANCE + 3]).mean()
        e[E_THETA_O], e[E_THETA_E] = _slices_cone(rows, C_TO_LIGHT, -1.0, half, e)
        return True
    # the world (T_ENV, T_ENV_MAP): its mean radiance x pi
    e[E_ENERGY] = models[k].power(1.0) / PI
    e[E_THETA_O], e[E_THETA_E] = PI, 0.0
    return True


def _slices_cone(rows, column, sign, theta_e, e):
    """The cone of sign x each slice's direction in `column`, into e[E_AXIS]; returns
    (theta_o, theta_e)."""
    x, y, z, o, te = 0.0, 0.0, 1.0, EMPTY, 0.0
    for s in rows:
        d = sign * s[column:column + 3]
        d = d / max(np.linalg.norm(d), 1e-300)
        x, y, z, o, te = merge(x, y, z, o, te, d[0], d[1], d[2], 0.0, theta_e)
    e[E_AXIS:E_AXIS + 3] = x, y, z
    return o, te


def entry_measures(L, models):
    """(emit, distant): every entry's fields (N_EMIT columns, E_LEAF unset) and whether
    it is distant."""
    n_lamps = L[LAMPS].shape[0]
    n_tri = L[TRI_AREA].shape[0]
    emit = np.zeros((n_lamps + n_tri, N_EMIT))
    distant = np.zeros(n_lamps + n_tri, dtype=bool)
    for k in range(n_lamps):
        distant[k] = _lamp_measure(L, k, models, emit[k])
    if n_tri:
        v0, e1, e2 = L[TRI_V0], L[TRI_E1], L[TRI_E2]
        t = emit[n_lamps:]
        v1, v2 = v0 + e1, v0 + e2
        t[:, E_CENTROID:E_CENTROID + 3] = (v0 + v1 + v2) / 3.0
        t[:, E_MIN:E_MIN + 3] = np.minimum(np.minimum(v0, v1), v2)
        t[:, E_MAX:E_MAX + 3] = np.maximum(np.maximum(v0, v1), v2)
        n = np.linalg.norm(e1, axis=1, keepdims=True)
        t[:, E_AXIS:E_AXIS + 3] = -e1 / np.where(n > 0.0, n, 1.0)    # in the plane:
        t[:, E_THETA_O] = PI / 2                                     # two-sided
        t[:, E_THETA_E] = PI / 2
        # one side sampled (Emission Sampling Front or Back): the cone of its normal
        off = L[TRI_VISIBILITY] & (NEE_FRONT_OFF | NEE_BACK_OFF)
        for bit, sign in ((NEE_BACK_OFF, 1.0), (NEE_FRONT_OFF, -1.0)):
            one = off == bit
            t[one, E_AXIS:E_AXIS + 3] = sign * L[TRI_NORMAL][one]
            t[one, E_THETA_O] = 0.0
        t[:, E_ENERGY] = L[TRI_AREA] * np.abs(L[TRI_RADIANCE]).mean(axis=1)
    bad = ~np.isfinite(emit).all(axis=1)
    emit[bad, E_ENERGY] = 0.0
    emit[:, E_LEAF] = -1.0
    emit[:, E_CONE:E_CONE + 4] = cone_terms(emit[:, E_THETA_O], emit[:, E_THETA_E])
    return emit, distant


def tree_arrays(L, models):
    """The light tree of the packed light set L (see the module docstring)."""
    emit, distant = entry_measures(L, models)
    used = emit[:, E_ENERGY] > 0.0
    local = np.flatnonzero(used & ~distant).astype(np.int64)
    far = np.flatnonzero(used & distant).astype(np.int64)
    nodes = np.zeros((max(2 * len(local) + 2, 1), N_NODE))
    slots = np.zeros(len(local) + len(far), dtype=np.int64)
    count = _build(emit, local, far, nodes, slots)
    nodes = np.ascontiguousarray(nodes[:count])
    nodes[:, N_CONE:N_CONE + 4] = cone_terms(nodes[:, N_THETA_O], nodes[:, N_THETA_E])
    return nodes, slots, emit


@kernel
def _measure_of(emit, slots, start, end, out):
    """The union of slots[start:end]'s boxes, cones and energies into out (N_NODE)."""
    for c in range(3):
        out[N_MIN + c] = math.inf
        out[N_MAX + c] = -math.inf
    x, y, z, o, te, energy = 0.0, 0.0, 1.0, EMPTY, 0.0, 0.0
    for i in range(start, end):
        k = slots[i]
        for c in range(3):
            out[N_MIN + c] = min(out[N_MIN + c], emit[k, E_MIN + c])
            out[N_MAX + c] = max(out[N_MAX + c], emit[k, E_MAX + c])
        x, y, z, o, te = merge(x, y, z, o, te, emit[k, E_AXIS], emit[k, E_AXIS + 1],
                               emit[k, E_AXIS + 2], emit[k, E_THETA_O], emit[k, E_THETA_E])
        energy += emit[k, E_ENERGY]
    out[N_AXIS], out[N_AXIS + 1], out[N_AXIS + 2] = x, y, z
    out[N_THETA_O], out[N_THETA_E], out[N_ENERGY] = o, te, energy


@kernel
def _cost(box, cone, energy):
    if cone[3] < 0.0 or energy == 0.0:
        return 0.0
    return (energy * box_measure(box[0], box[1], box[2], box[3], box[4], box[5])
            * measure(cone[3], cone[4]))


@kernel
def _grow(box, cone, energy, emit, k):
    """Add entry k to a bucket's (box 6, cone 5) and return its energy."""
    for c in range(3):
        box[c] = min(box[c], emit[k, E_MIN + c])
        box[3 + c] = max(box[3 + c], emit[k, E_MAX + c])
    cone[0], cone[1], cone[2], cone[3], cone[4] = merge(
        cone[0], cone[1], cone[2], cone[3], cone[4], emit[k, E_AXIS], emit[k, E_AXIS + 1],
        emit[k, E_AXIS + 2], emit[k, E_THETA_O], emit[k, E_THETA_E])
    return energy + emit[k, E_ENERGY]


@kernel
def _union(box, cone, energy, box2, cone2, energy2):
    for c in range(3):
        box[c] = min(box[c], box2[c])
        box[3 + c] = max(box[3 + c], box2[3 + c])
    cone[0], cone[1], cone[2], cone[3], cone[4] = merge(
        cone[0], cone[1], cone[2], cone[3], cone[4], cone2[0], cone2[1], cone2[2],
        cone2[3], cone2[4])
    return energy + energy2


@kernel
def _empty(box, cone):
    for c in range(3):
        box[c] = math.inf
        box[3 + c] = -math.inf
    cone[0], cone[1], cone[2], cone[3], cone[4] = 0.0, 0.0, 1.0, EMPTY, 0.0


@kernel
def _split(emit, slots, start, end, node):
    """Cycles' split of slots[start:end] (node holds their measure): sorts the range
    along the best axis and returns the middle, or -1 for a leaf."""
    n = end - start
    if n < 2:
        return -1
    lo = np.full(3, math.inf)
    hi = np.full(3, -math.inf)
    for i in range(start, end):
        for c in range(3):
            lo[c] = min(lo[c], emit[slots[i], E_CENTROID + c])
            hi[c] = max(hi[c], emit[slots[i], E_CENTROID + c])
    extent = hi - lo
    max_extent = max(extent[0], extent[1], extent[2], 0.0)
    total = _cost(node[N_MIN:N_MIN + 6], node[N_AXIS:N_AXIS + 5], node[N_ENERGY])
    best_dim, best_bucket, best = -1, -1, math.inf
    box = np.empty((BUCKETS, 6))
    cone = np.empty((BUCKETS, 5))
    energy = np.zeros(BUCKETS)
    lbox, lcone = np.empty((BUCKETS, 6)), np.empty((BUCKETS, 5))
    rbox, rcone = np.empty((BUCKETS, 6)), np.empty((BUCKETS, 5))
    lenergy, renergy = np.zeros(BUCKETS), np.zeros(BUCKETS)
    if total > 0.0:
        for dim in range(3):
            if not extent[dim] > 0.0:
                continue
            for b in range(BUCKETS):
                _empty(box[b], cone[b])
                energy[b] = 0.0
            inv = 1.0 / extent[dim]
            for i in range(start, end):
                k = slots[i]
                b = min(max(int(BUCKETS * (emit[k, E_CENTROID + dim] - lo[dim]) * inv), 0),
                        BUCKETS - 1)
                energy[b] = _grow(box[b], cone[b], energy[b], emit, k)
            _empty(lbox[0], lcone[0])
            lenergy[0] = _union(lbox[0], lcone[0], 0.0, box[0], cone[0], energy[0])
            for b in range(1, BUCKETS - 1):
                lbox[b, :] = lbox[b - 1, :]
                lcone[b, :] = lcone[b - 1, :]
                lenergy[b] = _union(lbox[b], lcone[b], lenergy[b - 1], box[b], cone[b],
                                    energy[b])
            _empty(rbox[BUCKETS - 2], rcone[BUCKETS - 2])
            renergy[BUCKETS - 2] = _union(rbox[BUCKETS - 2], rcone[BUCKETS - 2], 0.0,
                                          box[BUCKETS - 1], cone[BUCKETS - 1],
                                          energy[BUCKETS - 1])
            for b in range(BUCKETS - 3, -1, -1):
                rbox[b, :] = rbox[b + 1, :]
                rcone[b, :] = rcone[b + 1, :]
                renergy[b] = _union(rbox[b], rcone[b], renergy[b + 1], box[b + 1],
                                    cone[b + 1], energy[b + 1])
            reg = max_extent * inv
            for b in range(BUCKETS - 1):
                cost = reg * (_cost(lbox[b], lcone[b], lenergy[b])
                              + _cost(rbox[b], rcone[b], renergy[b]))
                if cost < total and cost < best:
                    best, best_dim, best_bucket = cost, dim, b
    if best_dim < 0:
        if n <= MAX_IN_LEAF:
            return -1
        # too many lights for one leaf and no split pays: halves along the longest axis
        best_dim = 0
        for c in range(1, 3):
            if extent[c] > extent[best_dim]:
                best_dim = c
        best_bucket = -1
    keys = np.empty(n)
    for i in range(n):
        keys[i] = emit[slots[start + i], E_CENTROID + best_dim]
    order = np.argsort(keys, kind="mergesort")
    part = slots[start:end][order]
    slots[start:end] = part
    if best_bucket < 0:
        return start + n // 2
    inv = 1.0 / extent[best_dim]
    middle = start
    for i in range(start, end):
        b = min(max(int(BUCKETS * (emit[slots[i], E_CENTROID + best_dim] - lo[best_dim])
                        * inv), 0), BUCKETS - 1)
        if b <= best_bucket:
            middle = i + 1
    if middle <= start or middle >= end:
        middle = start + n // 2
    return middle


@kernel
def _build(emit, local, far, nodes, slots):
    """Build the tree into nodes (capacity 2 n + 2) and slots; returns the node count."""
    n_local, n_far = local.shape[0], far.shape[0]
    for i in range(n_local):
        slots[i] = local[i]
    for i in range(n_far):
        slots[n_local + i] = far[i]
    if n_local + n_far == 0:
        return 0
    count = 1
    nodes[0, N_PARENT] = -1.0
    local_root = 0
    if n_local > 0 and n_far > 0:
        # the root: local lights on the left, the distant leaf on the right
        nodes[0, N_KIND], nodes[0, N_A], nodes[0, N_B] = INNER, 1.0, 2.0
        local_root = 1
        far_node = 2
        nodes[1, N_PARENT] = nodes[2, N_PARENT] = 0.0
        count = 3
    elif n_local == 0:
        far_node = 0
    else:
        far_node = -1
    if far_node >= 0:
        _measure_of(emit, slots, n_local, n_local + n_far, nodes[far_node])
        nodes[far_node, N_KIND] = DISTANT
        nodes[far_node, N_A], nodes[far_node, N_B] = float(n_local), float(n_far)
        for i in range(n_local, n_local + n_far):
            emit[slots[i], E_LEAF] = far_node
    if n_local > 0:
        stack = np.empty((2 * n_local + 2, 3), dtype=np.int64)
        stack[0, 0], stack[0, 1], stack[0, 2] = local_root, 0, n_local
        top = 1
        while top > 0:
            top -= 1
            node, start, end = stack[top, 0], stack[top, 1], stack[top, 2]
            _measure_of(emit, slots, start, end, nodes[node])
            middle = _split(emit, slots, start, end, nodes[node])
            if middle < 0:
                nodes[node, N_KIND] = LEAF
                nodes[node, N_A], nodes[node, N_B] = float(start), float(end - start)
                for i in range(start, end):
                    emit[slots[i], E_LEAF] = node
                continue
            left, right = count, count + 1
            count += 2
            nodes[node, N_KIND], nodes[node, N_A], nodes[node, N_B] = \
                INNER, float(left), float(right)
            nodes[left, N_PARENT] = nodes[right, N_PARENT] = float(node)
            stack[top, 0], stack[top, 1], stack[top, 2] = left, start, middle
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = right, middle, end
            top += 2
    if n_local > 0 and n_far > 0:
        n0 = nodes[0]
        for c in range(3):
            n0[N_MIN + c] = nodes[1, N_MIN + c]
            n0[N_MAX + c] = nodes[1, N_MAX + c]
        n0[N_ENERGY] = nodes[1, N_ENERGY] + nodes[2, N_ENERGY]
        n0[N_AXIS], n0[N_AXIS + 1], n0[N_AXIS + 2], n0[N_THETA_O], n0[N_THETA_E] = merge(
            nodes[1, N_AXIS], nodes[1, N_AXIS + 1], nodes[1, N_AXIS + 2],
            nodes[1, N_THETA_O], nodes[1, N_THETA_E], nodes[2, N_AXIS],
            nodes[2, N_AXIS + 1], nodes[2, N_AXIS + 2], nodes[2, N_THETA_O],
            nodes[2, N_THETA_E])
    return count
