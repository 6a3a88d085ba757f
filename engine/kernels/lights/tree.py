"""Picking a light with the light tree (tree_build.py), as Cycles' light tree picks one
(Conty Estevez and Kulla 2018 without splitting): from the root, each inner node goes
left or right in proportion to the two children's importance for the receiver
(tree_importance.py), and a leaf picks one of its lights by theirs. Cycles averages the
probabilities from the importance's upper bound and from its lower bound, and so does
this module.

`pick(L, receiver, u, time)` -> (entry, probability) and `pick_pdf(L, entry, receiver,
time)` give the same probability for the same receiver (the second walks up from the
entry's leaf), which is what multiple importance sampling needs when a BSDF-sampled ray
finds a light. Entries the tree leaves out (no energy) have probability 0.
"""
from __future__ import annotations

from ..jit import kernel
from .pack import (LAMP_SLICES, LAMPS, SLICE_OF, TREE_EMIT, TREE_NODES, TREE_SLOTS, TRI_E1,
                   TRI_E2, TRI_V0)
from .tree_build import E_LEAF, INNER, N_A, N_B, N_KIND, N_PARENT
from .tree_importance import (OMNI, ONE_SIDED, SEGMENT, TWO_SIDED, V_EMIT, V_NODES,
                              V_SLOTS, cluster_importance, emitter_importance, receiver,
                              segment_receiver)

ONE_MINUS_EPS = 1.0 - 2.0 ** -53

__all__ = ["OMNI", "ONE_SIDED", "TWO_SIDED", "SEGMENT", "receiver", "segment_receiver",
           "has_tree", "pick", "pick_pdf", "left_probability", "entry_importance"]


@kernel(allocates=False)
def has_tree(L):
    """Whether L picks its lights with a tree (else by L[SELECT_PDF]: Cycles' light distribution)."""
    return L[TREE_NODES].shape[0] > 0


@kernel(allocates=False)
def entry_importance(L, k, recv, time):
    """(max, min) importance of light entry k for the receiver (tree_importance)."""
    V = (L[TREE_NODES], L[TREE_SLOTS], L[TREE_EMIT], L[LAMPS], L[LAMP_SLICES],
         L[SLICE_OF], L[TRI_V0], L[TRI_E1], L[TRI_E2])       # (a kernel cannot return it)
    return emitter_importance(V, k, recv, time)


@kernel(allocates=False)
def _child_importance(V, node, recv, time):
    nd = V[V_NODES]
    if nd[node, N_KIND] != INNER and nd[node, N_B] == 1.0:
        return emitter_importance(V, V[V_SLOTS][int(nd[node, N_A])], recv, time)
    return cluster_importance(V, node, recv)


@kernel(allocates=False)
def left_probability(V, node, recv, time):
    """(ok, p): the probability that inner node `node` goes to its left child; ok False
    when neither child matters to the receiver."""
    nd = V[V_NODES]
    l_max, l_min = _child_importance(V, int(nd[node, N_A]), recv, time)
    r_max, r_min = _child_importance(V, int(nd[node, N_B]), recv, time)
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
def _leaf_pick(V, node, recv, time, u):
    """(entry, probability in the leaf) with u in [0, 1): half of u picks by the upper
    bounds, half by the lower ones, each by reservoir sampling in one pass over the
    leaf's lights (Cycles' `light_tree_cluster_select_emitter`)."""
    nd, slots = V[V_NODES], V[V_SLOTS]
    first, count = int(nd[node, N_A]), int(nd[node, N_B])
    by_max = u >= 0.5
    u = 2.0 * u - (1.0 if by_max else 0.0)
    s_max, s_min, n_has = 0.0, 0.0, 0
    chosen, c_max, c_min, total = -1, 0.0, 0.0, 0.0
    for i in range(first, first + count):
        i_max, i_min = emitter_importance(V, slots[i], recv, time)
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
            i_max, i_min = emitter_importance(V, slots[i], recv, time)
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
    V = (L[TREE_NODES], L[TREE_SLOTS], L[TREE_EMIT], L[LAMPS], L[LAMP_SLICES],
         L[SLICE_OF], L[TRI_V0], L[TRI_E1], L[TRI_E2])       # tree_importance.V_*
    nd = V[V_NODES]
    node, prob = 0, 1.0
    while nd[node, N_KIND] == INNER:
        ok, p_left = left_probability(V, node, recv, time)
        if not ok:
            return -1, 0.0
        if u < p_left:
            node, prob, u = int(nd[node, N_A]), prob * p_left, u / p_left
        else:
            node, prob, u = int(nd[node, N_B]), prob * (1.0 - p_left), \
                (u - p_left) / (1.0 - p_left)
        u = min(max(u, 0.0), ONE_MINUS_EPS)
    k, p_leaf = _leaf_pick(V, node, recv, time, u)
    return k, prob * p_leaf


@kernel(allocates=False)
def pick_pdf(L, k, recv, time):
    """The probability that `pick` gives entry k for the receiver."""
    V = (L[TREE_NODES], L[TREE_SLOTS], L[TREE_EMIT], L[LAMPS], L[LAMP_SLICES],
         L[SLICE_OF], L[TRI_V0], L[TRI_E1], L[TRI_E2])       # tree_importance.V_*
    nd, slots = V[V_NODES], V[V_SLOTS]
    leaf = int(V[V_EMIT][k, E_LEAF])
    if leaf < 0:
        return 0.0
    first, count = int(nd[leaf, N_A]), int(nd[leaf, N_B])
    s_max, s_min, n_has, k_max, k_min = 0.0, 0.0, 0, 0.0, 0.0
    for i in range(first, first + count):
        i_max, i_min = emitter_importance(V, slots[i], recv, time)
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
        ok, p_left = left_probability(V, parent, recv, time)
        if not ok:
            return 0.0
        prob *= p_left if int(nd[parent, N_A]) == node else 1.0 - p_left
        node = parent
    return prob
