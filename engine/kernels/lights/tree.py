"""Picking a light with the light tree (tree_build.py), as Cycles' light tree picks one
(Conty Estevez and Kulla 2018 without splitting, with Cycles' bounds): from the root,
each inner node goes left or right in proportion to the two children's importance for
the receiving point, and a leaf picks one of its lights by theirs. The importance of a
cluster of lights is its energy over the squared distance, times the best cosines its
box and cone allow (`importance`); Cycles averages the probabilities from that upper
bound and from the matching lower bound, and so does this module.

The receiver is a tuple (px, py, pz, nx, ny, nz, mode): the shading point, its shading
normal and what the surface does with light from below it (`mode`):
  ONE_SIDED  an opaque surface: lights wholly below its plane get no importance;
  TWO_SIDED  a surface that transmits, or whose normal a bump bends: |cos|, none lost;
  OMNI       a point in a volume: no normal, no cosine.

`pick(L, receiver, u, time)` -> (entry, probability) and `pick_pdf(L, entry, receiver,
time)` give the same probability for the same receiver (the second walks up from the
entry's leaf), which is what multiple importance sampling needs when a BSDF-sampled ray
finds a light. Entries the tree leaves out (no energy) have probability 0.
"""
from __future__ import annotations

import math

from ..jit import kernel
from ..warp import smoothstep01
from .pack import (C_AX, C_AXIS, C_AY, C_CENTER, C_COS_HALF, C_IS_SPOT, C_NORMAL, C_POS,
                   C_RADIUS, C_SMOOTH, C_TO_LIGHT, C_TYPE, LAMP_SLICES, LAMPS, SLICE_OF,
                   T_AREA, T_ENV, T_ENV_MAP, T_SPHERE, T_SUN, T_SUN_DELTA, TREE_EMIT,
                   TREE_NODES, TREE_SLOTS, TRI_E1, TRI_E2, TRI_V0)
from .tree_build import (DISTANT, E_AXIS, E_CONE, E_ENERGY, E_LEAF, INNER, N_A, N_AXIS,
                         N_B, N_CONE, N_ENERGY, N_KIND, N_MAX, N_MIN, N_PARENT)

PI = math.pi
OMNI = 0.0
ONE_SIDED = 1.0
TWO_SIDED = 2.0
HUGE = 1e300
ONE_MINUS_EPS = 1.0 - 2.0 ** -53


@kernel(allocates=False)
def has_tree(L):
    """Whether L picks its lights with a tree (else by power alone)."""
    return L[TREE_NODES].shape[0] > 0


@kernel(allocates=False)
def receiver(px, py, pz, nx, ny, nz, mode):
    return (px, py, pz, nx, ny, nz, mode)


@kernel(allocates=False)
def _unit(x, y, z):
    d = math.sqrt(x * x + y * y + z * z)
    if d > 0.0:
        return x / d, y / d, z / d, d
    return 0.0, 0.0, 0.0, 0.0


@kernel(allocates=False)
def _sin(c):
    return math.sqrt(max(0.0, 1.0 - c * c))


@kernel(allocates=False)
def _bounded(x):
    """A finite, non-negative importance (a receiver on a light divides by 0)."""
    if not x >= 0.0:
        return 0.0
    return min(x, HUGE)


@kernel(allocates=False)
def importance(recv, tx, ty, tz, cos_u, ax, ay, az, cos_o, sin_o, cos_oe, cos_eo, d_max,
               d_min, energy):
    """(max, min) importance of lights of `energy` seen from the receiver in the unit
    direction t towards their centre, within the cone of half-angle theta_u = acos(cos_u)
    about t, at distances d_min..d_max, emitting within the cone of axis a whose terms
    are (cos_o, sin_o, cos_oe, cos_eo) (tree_build.cone_terms) (Cycles'
    `light_tree_importance`, surface form; OMNI drops the receiver's cosine)."""
    nx, ny, nz, mode = recv[3], recv[4], recv[5], recv[6]
    sin_u = _sin(cos_u)
    cos_in_min = 1.0                  # cos(max(theta_i - theta_u, 0))
    cos_in_max = 1.0                  # cos(min(theta_i + theta_u, pi)), clamped at 0
    if mode != OMNI:
        ci = tx * nx + ty * ny + tz * nz
        if mode == TWO_SIDED:
            ci = abs(ci)
        si = _sin(ci)
        cos_in_min = 1.0 if ci >= cos_u else ci * cos_u + si * sin_u
        if mode == ONE_SIDED and cos_in_min < 0.0:
            return 0.0, 0.0           # wholly below an opaque surface
        cos_in_max = max(ci * cos_u - si * sin_u, 0.0)
    cos_t = min(1.0, max(-1.0, -(ax * tx + ay * ty + az * tz)))
    sin_t = _sin(cos_t)
    cos_t_minus_u = cos_t * cos_u + sin_t * sin_u
    if cos_t >= cos_u or cos_t_minus_u >= cos_o:
        cos_out_min = 1.0
    elif cos_t_minus_u > cos_oe:
        cos_out_min = cos_t_minus_u * cos_o + _sin(cos_t_minus_u) * sin_o
    else:
        return 0.0, 0.0               # the receiver is outside every emitter's cone
    dmin2 = max(d_min * d_min, 1e-300)
    i_max = _bounded(abs(cos_in_min * energy * cos_out_min / dmin2))
    cos_t_plus_u = cos_t * cos_u - sin_t * sin_u
    if cos_t < 0.0 or cos_u < 0.0 or cos_t_plus_u < cos_eo:
        return i_max, 0.0
    cos_out_max = cos_t_plus_u * cos_o - _sin(cos_t_plus_u) * sin_o
    dmax2 = max(d_max * d_max, 1e-300)
    return i_max, _bounded(abs(cos_in_max * energy * cos_out_max / dmax2))


@kernel(allocates=False)
def _corner(recv, tx, ty, tz, cx, cy, cz):
    """(cos of the angle between t and the corner c, its distance, whether c is above
    the receiver's plane)."""
    ux, uy, uz, d = _unit(cx - recv[0], cy - recv[1], cz - recv[2])
    above = ux * recv[3] + uy * recv[4] + uz * recv[5] > 0.0
    return tx * ux + ty * uy + tz * uz, d, above


@kernel(allocates=False)
def _triangle_importance(L, j, recv, em, k):
    v0, e1, e2 = L[TRI_V0], L[TRI_E1], L[TRI_E2]
    cx = v0[j, 0] + (e1[j, 0] + e2[j, 0]) / 3.0
    cy = v0[j, 1] + (e1[j, 1] + e2[j, 1]) / 3.0
    cz = v0[j, 2] + (e1[j, 2] + e2[j, 2]) / 3.0
    tx, ty, tz, d = _unit(cx - recv[0], cy - recv[1], cz - recv[2])
    cos_u, d_max, above = math.inf, d, False
    for i in range(3):
        qx, qy, qz = v0[j, 0], v0[j, 1], v0[j, 2]
        if i == 1:
            qx, qy, qz = qx + e1[j, 0], qy + e1[j, 1], qz + e1[j, 2]
        elif i == 2:
            qx, qy, qz = qx + e2[j, 0], qy + e2[j, 1], qz + e2[j, 2]
        c, dc, up = _corner(recv, tx, ty, tz, qx, qy, qz)
        cos_u, d_max, above = min(cos_u, c), max(d_max, dc), above or up
    if recv[6] == ONE_SIDED and not above:
        return 0.0, 0.0
    return importance(recv, tx, ty, tz, cos_u, em[k, E_AXIS], em[k, E_AXIS + 1],
                      em[k, E_AXIS + 2], em[k, E_CONE], em[k, E_CONE + 1],
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d, em[k, E_ENERGY])


@kernel(allocates=False)
def _slice(L, k, time):
    """(sliced, row): lamp k's row at shutter time `time` (light_set.lamp_row)."""
    count = L[SLICE_OF][k, 1]
    if count == 0:
        return False, k
    return True, L[SLICE_OF][k, 0] + min(max(int(time * count), 0), count - 1)


@kernel(allocates=False)
def _point_importance(lamps, row, recv, em, k):
    """A point, sphere or disc lamp, or a spot (Cycles' point and spot parameters)."""
    tx, ty, tz, d = _unit(lamps[row, C_POS] - recv[0], lamps[row, C_POS + 1] - recv[1],
                          lamps[row, C_POS + 2] - recv[2])
    r = lamps[row, C_RADIUS]
    if lamps[row, C_TYPE] == T_SPHERE:
        if d > r:
            cos_u = _sin(r / d)
            d_max, d_min = d / max(cos_u, 1e-300), d
        else:
            cos_u = -1.0
            d_max = d_min = r / math.sqrt(2.0)
    else:
        hyp = math.sqrt(r * r + d * d)
        cos_u = d / hyp if hyp > 0.0 else 1.0
        d_max, d_min = hyp, d
    energy = em[k, E_ENERGY]
    if lamps[row, C_IS_SPOT] == 0.0:
        # an omnidirectional lamp: a cone (theta_o 0, theta_e pi/2) facing the receiver
        return importance(recv, tx, ty, tz, cos_u, -tx, -ty, -tz, 1.0, 0.0, 0.0, 0.0,
                          d_max, d_min, energy)
    ax, ay, az = lamps[row, C_AXIS], lamps[row, C_AXIS + 1], lamps[row, C_AXIS + 2]
    # the spot's blend at the smallest angle to its axis the lamp's extent allows:
    # cos(max(theta - theta_u, 0)) of cos theta = -a.t
    c = min(1.0, max(-1.0, -(ax * tx + ay * ty + az * tz)))
    if c < cos_u:
        c = c * cos_u + _sin(c) * _sin(cos_u)
    else:
        c = 1.0
    smooth = lamps[row, C_SMOOTH]
    if smooth > 0.0:
        energy *= smoothstep01((c - lamps[row, C_COS_HALF]) / smooth)
    elif not c > lamps[row, C_COS_HALF]:
        return 0.0, 0.0
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, em[k, E_CONE], em[k, E_CONE + 1],
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d_min, energy)


@kernel(allocates=False)
def _area_importance(lamps, row, recv, em, k):
    cx, cy, cz = lamps[row, C_CENTER], lamps[row, C_CENTER + 1], lamps[row, C_CENTER + 2]
    tx, ty, tz, d = _unit(cx - recv[0], cy - recv[1], cz - recv[2])
    ax, ay, az = -lamps[row, C_NORMAL], -lamps[row, C_NORMAL + 1], -lamps[row, C_NORMAL + 2]
    if not ax * tx + ay * ty + az * tz < 0.0:
        return 0.0, 0.0                # behind the lamp, which emits along -Z only
    ux, uy, uz = lamps[row, C_AX], lamps[row, C_AX + 1], lamps[row, C_AX + 2]
    vx, vy, vz = lamps[row, C_AY], lamps[row, C_AY + 1], lamps[row, C_AY + 2]
    if recv[6] == ONE_SIDED:
        nx, ny, nz = recv[3], recv[4], recv[5]
        reach = (nx * (cx - recv[0]) + ny * (cy - recv[1]) + nz * (cz - recv[2])
                 + 2.0 * abs(nx * ux + ny * uy + nz * uz)
                 + 2.0 * abs(nx * vx + ny * vy + nz * vz))
        if not reach > 0.0:
            return 0.0, 0.0
    cos_u, d_max = math.inf, d
    for i in range(4):
        a = 1.0 if i & 1 else -1.0
        b = 1.0 if i & 2 else -1.0
        c, dc, _ = _corner(recv, tx, ty, tz, cx + a * ux + b * vx, cy + a * uy + b * vy,
                           cz + a * uz + b * vz)
        cos_u, d_max = min(cos_u, c), max(d_max, dc)
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, em[k, E_CONE], em[k, E_CONE + 1],
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d, em[k, E_ENERGY])


@kernel(allocates=False)
def emitter_importance(L, k, recv, time):
    """(max, min) importance of light entry k for the receiver at shutter time `time`."""
    em = L[TREE_EMIT]
    n_lamps = L[LAMPS].shape[0]
    if k >= n_lamps:
        return _triangle_importance(L, k - n_lamps, recv, em, k)
    kind = L[LAMPS][k, C_TYPE]
    if kind == T_ENV or kind == T_ENV_MAP:
        return em[k, E_ENERGY], 0.0    # the whole sphere: no cosine bounds it
    sliced, row = _slice(L, k, time)
    table = L[LAMP_SLICES] if sliced else L[LAMPS]
    if kind == T_SUN or kind == T_SUN_DELTA:
        # a disc one unit away (Cycles' distant light): theta_u = theta_e
        tx, ty, tz = table[row, C_TO_LIGHT], table[row, C_TO_LIGHT + 1], \
            table[row, C_TO_LIGHT + 2]
        cos_u = em[k, E_CONE + 3]        # cos(theta_e - 0)
        return importance(recv, tx, ty, tz, cos_u, -tx, -ty, -tz, 1.0, 0.0,
                          em[k, E_CONE + 2], cos_u, 1.0 / max(cos_u, 1e-300), 1.0,
                          em[k, E_ENERGY])
    if kind == T_AREA:
        return _area_importance(table, row, recv, em, k)
    return _point_importance(table, row, recv, em, k)


@kernel(allocates=False)
def _cluster_importance(L, node, recv):
    """(max, min) importance of a node holding several lights (Cycles' node form)."""
    nd = L[TREE_NODES]
    ax, ay, az = nd[node, N_AXIS], nd[node, N_AXIS + 1], nd[node, N_AXIS + 2]
    cos_o, sin_o = nd[node, N_CONE], nd[node, N_CONE + 1]
    cos_oe, cos_eo, energy = nd[node, N_CONE + 2], nd[node, N_CONE + 3], nd[node, N_ENERGY]
    if nd[node, N_KIND] == DISTANT:
        # directions within theta_o + theta_e of the axis
        return importance(recv, -ax, -ay, -az, max(cos_oe, -1.0), ax, ay, az, cos_o, sin_o,
                          cos_oe, cos_eo, 1.0, 1.0, energy)
    cx = 0.5 * (nd[node, N_MIN] + nd[node, N_MAX])
    cy = 0.5 * (nd[node, N_MIN + 1] + nd[node, N_MAX + 1])
    cz = 0.5 * (nd[node, N_MIN + 2] + nd[node, N_MAX + 2])
    ex, ey, ez = nd[node, N_MAX] - cx, nd[node, N_MAX + 1] - cy, nd[node, N_MAX + 2] - cz
    if recv[6] == ONE_SIDED:
        nx, ny, nz = recv[3], recv[4], recv[5]
        if not (nx * (cx - recv[0]) + ny * (cy - recv[1]) + nz * (cz - recv[2])
                + abs(nx) * abs(ex) + abs(ny) * abs(ey) + abs(nz) * abs(ez)) > 0.0:
            return 0.0, 0.0            # the box is wholly below an opaque surface
    tx, ty, tz, d = _unit(cx - recv[0], cy - recv[1], cz - recv[2])
    r2 = ex * ex + ey * ey + ez * ez
    cos_u = -1.0 if d * d <= r2 else math.sqrt(max(0.0, 1.0 - r2 / (d * d)))
    d = max(0.5 * math.sqrt(r2), d)
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, cos_o, sin_o, cos_oe, cos_eo, d,
                      d, energy)


@kernel(allocates=False)
def _child_importance(L, node, recv, time):
    nd = L[TREE_NODES]
    if nd[node, N_KIND] != INNER and nd[node, N_B] == 1.0:
        return emitter_importance(L, L[TREE_SLOTS][int(nd[node, N_A])], recv, time)
    return _cluster_importance(L, node, recv)


@kernel(allocates=False)
def left_probability(L, node, recv, time):
    """(ok, p): the probability that inner node `node` goes to its left child; ok False
    when neither child matters to the receiver."""
    nd = L[TREE_NODES]
    l_max, l_min = _child_importance(L, int(nd[node, N_A]), recv, time)
    r_max, r_min = _child_importance(L, int(nd[node, N_B]), recv, time)
    total_max = l_max + r_max
    if not total_max > 0.0:
        return False, 0.0
    total_min = l_min + r_min
    p_max = l_max / total_max
    if total_min > 0.0:
        p_min = l_min / total_min
    else:
        p_min = 0.5 * ((1.0 if l_max > 0.0 else 0.0) + (1.0 if r_max == 0.0 else 0.0))
    return True, 0.5 * (p_max + p_min)


@kernel(allocates=False)
def _in_leaf(i_max, i_min, s_max, s_min, n_has):
    """The probability a leaf picks a light of importance (i_max, i_min): Cycles' mean
    of picking by the upper bounds and by the lower ones (uniformly among the lights
    that matter when no lower bound is positive)."""
    if not i_max > 0.0:
        return 0.0
    p_min = i_min / s_min if s_min > 0.0 else 1.0 / n_has
    return 0.5 * (i_max / s_max + p_min)


@kernel(allocates=False)
def _leaf_pick(L, node, recv, time, u):
    """(entry, probability in the leaf) with u in [0, 1): half of u picks by the upper
    bounds, half by the lower ones, each by reservoir sampling in one pass over the
    leaf's lights (Cycles' `light_tree_cluster_select_emitter`)."""
    nd, slots = L[TREE_NODES], L[TREE_SLOTS]
    first, count = int(nd[node, N_A]), int(nd[node, N_B])
    by_max = u >= 0.5
    u = 2.0 * u - (1.0 if by_max else 0.0)
    s_max, s_min, n_has = 0.0, 0.0, 0
    chosen, c_max, c_min, total = -1, 0.0, 0.0, 0.0
    for i in range(first, first + count):
        i_max, i_min = emitter_importance(L, slots[i], recv, time)
        if i_max > 0.0:
            n_has += 1
        s_max += i_max
        s_min += i_min
        w = i_max if by_max else i_min
        if w > 0.0:
            total += w
            q = w / total
            if u < q:
                chosen, c_max, c_min, u = slots[i], i_max, i_min, u / q
            else:
                u = (u - q) / (1.0 - q)
            u = min(max(u, 0.0), ONE_MINUS_EPS)
    if not s_max > 0.0:
        return -1, 0.0
    if not by_max and not s_min > 0.0:
        # no lower bound: uniformly among the lights that matter (a second pass)
        target = int(u * n_has)
        seen = 0
        for i in range(first, first + count):
            i_max, i_min = emitter_importance(L, slots[i], recv, time)
            if i_max > 0.0:
                if seen == target or seen == n_has - 1:
                    chosen, c_max, c_min = slots[i], i_max, i_min
                    break
                seen += 1
    return chosen, _in_leaf(c_max, c_min, s_max, s_min, n_has)


@kernel(allocates=False)
def pick(L, recv, u, time):
    """(entry, probability): a light entry for the receiver picked with u in [0, 1);
    (-1, 0) when no light matters to it."""
    nd = L[TREE_NODES]
    node, prob = 0, 1.0
    while nd[node, N_KIND] == INNER:
        ok, p_left = left_probability(L, node, recv, time)
        if not ok:
            return -1, 0.0
        if u < p_left:
            node, prob, u = int(nd[node, N_A]), prob * p_left, u / p_left
        else:
            node, prob, u = int(nd[node, N_B]), prob * (1.0 - p_left), \
                (u - p_left) / (1.0 - p_left)
        u = min(max(u, 0.0), ONE_MINUS_EPS)
    k, p_leaf = _leaf_pick(L, node, recv, time, u)
    return k, prob * p_leaf


@kernel(allocates=False)
def pick_pdf(L, k, recv, time):
    """The probability that `pick` gives entry k for the receiver."""
    nd, slots = L[TREE_NODES], L[TREE_SLOTS]
    leaf = int(L[TREE_EMIT][k, E_LEAF])
    if leaf < 0:
        return 0.0
    first, count = int(nd[leaf, N_A]), int(nd[leaf, N_B])
    s_max, s_min, n_has, k_max, k_min = 0.0, 0.0, 0, 0.0, 0.0
    for i in range(first, first + count):
        i_max, i_min = emitter_importance(L, slots[i], recv, time)
        if i_max > 0.0:
            n_has += 1
        s_max += i_max
        s_min += i_min
        if slots[i] == k:
            k_max, k_min = i_max, i_min
    prob = _in_leaf(k_max, k_min, s_max, s_min, n_has)
    node = leaf
    while prob > 0.0:
        parent = int(nd[node, N_PARENT])
        if parent < 0:
            break
        ok, p_left = left_probability(L, parent, recv, time)
        if not ok:
            return 0.0
        prob *= p_left if int(nd[parent, N_A]) == node else 1.0 - p_left
        node = parent
    return prob
