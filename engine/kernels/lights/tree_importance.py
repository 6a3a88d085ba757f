"""The light tree's importance (Conty Estevez and Kulla 2018, with Cycles' bounds): how
much a light, or a node of the tree holding several, may matter to a receiver, as an
upper and a lower bound (`emitter_importance`, `cluster_importance`), from its energy,
its distance and the best cosines its box and cone allow (`importance`, Cycles'
`light_tree_importance`). tree.py picks lights with it.

The receiver is a tuple (px, py, pz, nx, ny, nz, mode, t): the shading point, its
shading normal (Cycles' sd->N: the surface's, not a lobe's bent one) and what the
surface does with light from below it (`mode`):
  ONE_SIDED  an opaque surface: lights wholly below its plane get no importance (a lobe
             on a bent normal that reaches under it finds them by its own rays, at
             full weight, as in Cycles);
  TWO_SIDED  a surface that transmits: |cos|, none lost;
  OMNI       a point in a volume: no normal, no cosine;
  SEGMENT    a ray segment o + s d, s in [0, t], through a volume (p = o, n = d):
             Cycles' volume form (tree_segment.py); suns and the world, which no
             distance can be sampled towards, get none.
Every bound is conservative: a light that can reach the receiver has an upper bound
above zero (tests/test_light_tree.py).
"""
from __future__ import annotations

import math

from ..jit import kernel
from ..warp import smoothstep01
from .pack import (C_AX, C_AXIS, C_AY, C_CENTER, C_COS_HALF, C_IS_SPOT, C_NORMAL, C_POS,
                   C_RADIUS, C_SMOOTH, C_TO_LIGHT, C_TYPE, T_AREA, T_ENV, T_ENV_MAP,
                   T_SPHERE, T_SUN, T_SUN_DELTA)
from .tree_build import (DISTANT, E_AXIS, E_CONE, E_ENERGY, N_AXIS, N_CONE, N_ENERGY,
                         N_KIND, N_MAX, N_MIN)
from .tree_segment import closest, reaches_front, subtended, towards_segment

# The arrays of L the tree reads, as the tuple V = (L[TREE_NODES], L[TREE_SLOTS],
# L[TREE_EMIT], L[LAMPS], L[LAMP_SLICES], L[SLICE_OF], L[TRI_V0], L[TRI_E1], L[TRI_E2])
# that tree.py makes once per pick: a kernel's arguments are passed by value, and the
# 27 arrays of L would be copied (about 1.7 kB) into every call of the walk.
V_NODES, V_SLOTS, V_EMIT, V_LAMPS, V_SLICES, V_SLICE_OF, V_V0, V_E1, V_E2 = range(9)

PI = math.pi
OMNI = 0.0
ONE_SIDED = 1.0
TWO_SIDED = 2.0
SEGMENT = 3.0
HUGE = 1e300


@kernel(allocates=False)
def receiver(px, py, pz, nx, ny, nz, mode):
    """A point receiver (ONE_SIDED, TWO_SIDED or OMNI)."""
    return (px, py, pz, nx, ny, nz, mode, 0.0)


@kernel(allocates=False)
def segment_receiver(ox, oy, oz, dx, dy, dz, t):
    """The segment o + s d, s in [0, t] (t may be inf), as a receiver."""
    return (ox, oy, oz, dx, dy, dz, SEGMENT, t)


@kernel(allocates=False)
def _anchor(recv, cx, cy, cz):
    """(x, y, z, theta_d): where distances to a light at c are taken from (the point,
    or the segment's point nearest to c) and the segment's subtended angle (1 for a
    point)."""
    if recv[6] != SEGMENT:
        return recv[0], recv[1], recv[2], 1.0
    s, x, y, z, d = closest(recv, cx, cy, cz)
    return x, y, z, subtended(recv, s, d)


@kernel(allocates=False)
def _outgoing(recv, tx, ty, tz, cx, cy, cz, ax, ay, az):
    """The direction the importance takes towards the light: t for a point, and for
    a segment minus the direction from c to it nearest to the axis a."""
    if recv[6] != SEGMENT:
        return tx, ty, tz
    vx, vy, vz = towards_segment(recv, cx, cy, cz, ax, ay, az)
    return -vx, -vy, -vz


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


ON_AXIS = 1.0 - 1e-14      # cosines above this are the axis (angles under 1.5e-7 rad)


@kernel(allocates=False)
def importance(recv, tx, ty, tz, cos_u, ax, ay, az, cos_o, sin_o, cos_oe, cos_eo, d_max,
               d_min, energy, theta_d):
    """(max, min) importance of lights of `energy` seen from the receiver in the unit
    direction t towards their centre, within the cone of half-angle theta_u = acos(cos_u)
    about t, at distances d_min..d_max, emitting within the cone of axis a whose terms
    are (cos_o, sin_o, cos_oe, cos_eo) (tree_build.cone_terms) (Cycles'
    `light_tree_importance`; OMNI drops the receiver's cosine, SEGMENT too and weighs
    by the subtended angle theta_d over the distance, with no lower bound)."""
    nx, ny, nz, mode = recv[3], recv[4], recv[5], recv[6]
    sin_u = _sin(cos_u)
    cos_in_min = 1.0                  # cos(max(theta_i - theta_u, 0))
    cos_in_max = 1.0                  # cos(min(theta_i + theta_u, pi)), clamped at 0
    if mode != OMNI and mode != SEGMENT:
        ci = tx * nx + ty * ny + tz * nz
        if mode == TWO_SIDED:
            ci = abs(ci)
        si = _sin(ci)
        cos_in_min = 1.0 if ci >= cos_u else ci * cos_u + si * sin_u
        if mode == ONE_SIDED and cos_in_min < 0.0:
            return 0.0, 0.0           # wholly below an opaque surface
        cos_in_max = max(ci * cos_u - si * sin_u, 0.0)
    cos_t = min(1.0, max(-1.0, -(ax * tx + ay * ty + az * tz)))
    if cos_t > ON_AXIS:
        # on the axis but for rounding: a delta sun (theta_o = theta_e = 0) whose unit
        # direction is an ulp short has cos_t = |t|^2 < 1 = cos_o, and would be outside
        # its own cone; bounds that err on the inclusive side bias nothing
        cos_t = 1.0
    sin_t = _sin(cos_t)
    cos_t_minus_u = cos_t * cos_u + sin_t * sin_u
    if cos_t >= cos_u or cos_t_minus_u >= cos_o:
        cos_out_min = 1.0
    elif cos_t_minus_u > cos_oe:
        cos_out_min = cos_t_minus_u * cos_o + _sin(cos_t_minus_u) * sin_o
    else:
        return 0.0, 0.0               # the receiver is outside every emitter's cone
    if mode == SEGMENT:
        return _bounded(abs(energy * cos_out_min * theta_d / max(d_min, 1e-300))), 0.0
    dmin2 = max(d_min * d_min, 1e-300)
    i_max = _bounded(abs(cos_in_min * energy * cos_out_min / dmin2))
    cos_t_plus_u = cos_t * cos_u - sin_t * sin_u
    if cos_t < 0.0 or cos_u < 0.0 or cos_t_plus_u < cos_eo:
        return i_max, 0.0
    cos_out_max = cos_t_plus_u * cos_o - _sin(cos_t_plus_u) * sin_o
    dmax2 = max(d_max * d_max, 1e-300)
    return i_max, _bounded(abs(cos_in_max * energy * cos_out_max / dmax2))


@kernel(allocates=False)
def _corner(recv, rx, ry, rz, tx, ty, tz, cx, cy, cz):
    """(cos of the angle between t and the corner c seen from r, its distance, whether c
    is above the receiver's plane)."""
    ux, uy, uz, d = _unit(cx - rx, cy - ry, cz - rz)
    above = ux * recv[3] + uy * recv[4] + uz * recv[5] > 0.0
    return tx * ux + ty * uy + tz * uz, d, above


@kernel(allocates=False)
def _triangle_importance(V, j, recv, em, k):
    v0, e1, e2 = V[V_V0], V[V_E1], V[V_E2]
    cx = v0[j, 0] + (e1[j, 0] + e2[j, 0]) / 3.0
    cy = v0[j, 1] + (e1[j, 1] + e2[j, 1]) / 3.0
    cz = v0[j, 2] + (e1[j, 2] + e2[j, 2]) / 3.0
    rx, ry, rz, theta_d = _anchor(recv, cx, cy, cz)
    tx, ty, tz, d = _unit(cx - rx, cy - ry, cz - rz)
    cos_u, d_max, above = math.inf, d, False
    for i in range(3):
        qx, qy, qz = v0[j, 0], v0[j, 1], v0[j, 2]
        if i == 1:
            qx, qy, qz = qx + e1[j, 0], qy + e1[j, 1], qz + e1[j, 2]
        elif i == 2:
            qx, qy, qz = qx + e2[j, 0], qy + e2[j, 1], qz + e2[j, 2]
        c, dc, up = _corner(recv, rx, ry, rz, tx, ty, tz, qx, qy, qz)
        cos_u, d_max, above = min(cos_u, c), max(d_max, dc), above or up
    if recv[6] == ONE_SIDED and not above:
        return 0.0, 0.0
    ax, ay, az = em[k, E_AXIS], em[k, E_AXIS + 1], em[k, E_AXIS + 2]
    tx, ty, tz = _outgoing(recv, tx, ty, tz, cx, cy, cz, ax, ay, az)
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, em[k, E_CONE], em[k, E_CONE + 1],
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d, em[k, E_ENERGY],
                      theta_d)


@kernel(allocates=False)
def _slice(V, k, time):
    """(sliced, row): lamp k's row at shutter time `time` (light_set.lamp_row)."""
    count = V[V_SLICE_OF][k, 1]
    if count == 0:
        return False, k
    return True, V[V_SLICE_OF][k, 0] + min(max(int(time * count), 0), count - 1)


@kernel(allocates=False)
def _point_importance(lamps, row, recv, em, k):
    """A point, sphere or disc lamp, or a spot (Cycles' point and spot parameters)."""
    cx, cy, cz = lamps[row, C_POS], lamps[row, C_POS + 1], lamps[row, C_POS + 2]
    rx, ry, rz, theta_d = _anchor(recv, cx, cy, cz)
    tx, ty, tz, d = _unit(cx - rx, cy - ry, cz - rz)
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
                          d_max, d_min, energy, theta_d)
    ax, ay, az = lamps[row, C_AXIS], lamps[row, C_AXIS + 1], lamps[row, C_AXIS + 2]
    tx, ty, tz = _outgoing(recv, tx, ty, tz, cx, cy, cz, ax, ay, az)
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
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d_min, energy, theta_d)


@kernel(allocates=False)
def _area_importance(lamps, row, recv, em, k):
    cx, cy, cz = lamps[row, C_CENTER], lamps[row, C_CENTER + 1], lamps[row, C_CENTER + 2]
    ax, ay, az = -lamps[row, C_NORMAL], -lamps[row, C_NORMAL + 1], -lamps[row, C_NORMAL + 2]
    if recv[6] == SEGMENT:
        if not reaches_front(recv, cx, cy, cz, ax, ay, az):
            return 0.0, 0.0
    elif not ax * (recv[0] - cx) + ay * (recv[1] - cy) + az * (recv[2] - cz) > 0.0:
        return 0.0, 0.0                # behind the lamp, which emits along -Z only
    rx, ry, rz, theta_d = _anchor(recv, cx, cy, cz)
    tx, ty, tz, d = _unit(cx - rx, cy - ry, cz - rz)
    ux, uy, uz = lamps[row, C_AX], lamps[row, C_AX + 1], lamps[row, C_AX + 2]
    vx, vy, vz = lamps[row, C_AY], lamps[row, C_AY + 1], lamps[row, C_AY + 2]
    if recv[6] == ONE_SIDED:
        nx, ny, nz = recv[3], recv[4], recv[5]
        reach = (nx * (cx - rx) + ny * (cy - ry) + nz * (cz - rz)
                 + 2.0 * abs(nx * ux + ny * uy + nz * uz)
                 + 2.0 * abs(nx * vx + ny * vy + nz * vz))
        if not reach > 0.0:
            return 0.0, 0.0
    cos_u, d_max = math.inf, d
    for i in range(4):
        a = 1.0 if i & 1 else -1.0
        b = 1.0 if i & 2 else -1.0
        c, dc, _ = _corner(recv, rx, ry, rz, tx, ty, tz, cx + a * ux + b * vx,
                           cy + a * uy + b * vy, cz + a * uz + b * vz)
        cos_u, d_max = min(cos_u, c), max(d_max, dc)
    tx, ty, tz = _outgoing(recv, tx, ty, tz, cx, cy, cz, ax, ay, az)
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, em[k, E_CONE], em[k, E_CONE + 1],
                      em[k, E_CONE + 2], em[k, E_CONE + 3], d_max, d, em[k, E_ENERGY],
                      theta_d)


@kernel(allocates=False)
def emitter_importance(V, k, recv, time):
    """(max, min) importance of light entry k for the receiver at shutter time `time`
    (V: the tree's view of L, above)."""
    em = V[V_EMIT]
    n_lamps = V[V_LAMPS].shape[0]
    if k >= n_lamps:
        return _triangle_importance(V, k - n_lamps, recv, em, k)
    kind = V[V_LAMPS][k, C_TYPE]
    distant = kind == T_ENV or kind == T_ENV_MAP or kind == T_SUN or kind == T_SUN_DELTA
    if distant and recv[6] == SEGMENT:
        return 0.0, 0.0                # no distance to sample towards
    if kind == T_ENV or kind == T_ENV_MAP:
        return em[k, E_ENERGY], 0.0    # the whole sphere: no cosine bounds it
    sliced, row = _slice(V, k, time)
    table = V[V_SLICES] if sliced else V[V_LAMPS]
    if kind == T_SUN or kind == T_SUN_DELTA:
        # a disc one unit away (Cycles' distant light): theta_u = theta_e
        tx, ty, tz = table[row, C_TO_LIGHT], table[row, C_TO_LIGHT + 1], \
            table[row, C_TO_LIGHT + 2]
        cos_u = em[k, E_CONE + 3]        # cos(theta_e - 0)
        return importance(recv, tx, ty, tz, cos_u, -tx, -ty, -tz, 1.0, 0.0,
                          em[k, E_CONE + 2], cos_u, 1.0 / max(cos_u, 1e-300), 1.0,
                          em[k, E_ENERGY], 1.0)
    if kind == T_AREA:
        return _area_importance(table, row, recv, em, k)
    return _point_importance(table, row, recv, em, k)


@kernel(allocates=False)
def cluster_importance(V, node, recv):
    """(max, min) importance of a node holding several lights (Cycles' node form)."""
    nd = V[V_NODES]
    ax, ay, az = nd[node, N_AXIS], nd[node, N_AXIS + 1], nd[node, N_AXIS + 2]
    cos_o, sin_o = nd[node, N_CONE], nd[node, N_CONE + 1]
    cos_oe, cos_eo, energy = nd[node, N_CONE + 2], nd[node, N_CONE + 3], nd[node, N_ENERGY]
    if nd[node, N_KIND] == DISTANT:
        if recv[6] == SEGMENT:
            return 0.0, 0.0
        # directions within theta_o + theta_e of the axis
        return importance(recv, -ax, -ay, -az, max(cos_oe, -1.0), ax, ay, az, cos_o, sin_o,
                          cos_oe, cos_eo, 1.0, 1.0, energy, 1.0)
    cx = 0.5 * (nd[node, N_MIN] + nd[node, N_MAX])
    cy = 0.5 * (nd[node, N_MIN + 1] + nd[node, N_MAX + 1])
    cz = 0.5 * (nd[node, N_MIN + 2] + nd[node, N_MAX + 2])
    ex, ey, ez = nd[node, N_MAX] - cx, nd[node, N_MAX + 1] - cy, nd[node, N_MAX + 2] - cz
    if recv[6] == ONE_SIDED:
        nx, ny, nz = recv[3], recv[4], recv[5]
        if not (nx * (cx - recv[0]) + ny * (cy - recv[1]) + nz * (cz - recv[2])
                + abs(nx) * abs(ex) + abs(ny) * abs(ey) + abs(nz) * abs(ez)) > 0.0:
            return 0.0, 0.0            # the box is wholly below an opaque surface
    theta_d = 1.0
    if recv[6] == SEGMENT:
        s, rx, ry, rz, d_line = closest(recv, cx, cy, cz)
        theta_d = subtended(recv, s, d_line)
        tx, ty, tz = _outgoing(recv, 0.0, 0.0, 0.0, cx, cy, cz, ax, ay, az)
        d = d_line
        qx, qy, qz = cx - rx, cy - ry, cz - rz
        dq2 = qx * qx + qy * qy + qz * qz          # the bound is seen from the nearest point
    else:
        tx, ty, tz, d = _unit(cx - recv[0], cy - recv[1], cz - recv[2])
        dq2 = d * d
    r2 = ex * ex + ey * ey + ez * ez
    cos_u = -1.0 if dq2 <= r2 else math.sqrt(max(0.0, 1.0 - r2 / dq2))
    d = max(0.5 * math.sqrt(r2), d)
    return importance(recv, tx, ty, tz, cos_u, ax, ay, az, cos_o, sin_o, cos_oe, cos_eo, d,
                      d, energy, theta_d)
