"""Rays against the moving objects through their hierarchy (`engine.kernels.motion_tlas`):
one compiled call per batch walks the TLAS for every ray, intersects the small units'
triangles on the spot (float64 Moeller-Trumbore through each unit's BLAS, the ray moved
into the unit's space at its own time) and lists the (ray, unit) pairs of the large
units for Embree (`engine.kernels.motion_pairs` groups them and merges Embree's hits).

The nearest hit follows the brute-force order's tie rule: at equal distance the static
hit wins, then the lower unit; so the answer does not depend on the order the hierarchy
visits the units in, and `use_tlas=False` (every ray against every unit, a deforming
object's units only for the slice of the ray's time) is the reference it must equal.
"""
from __future__ import annotations

import math

import numpy as np

from .box_hierarchy import slab_entry, slab_setup
from .jit import kernel
from .motion import DEFORM, I_KIND, I_NVERTS, I_SLICES, I_STEPS, I_VERT0, object_ray, step_of
from .motion_tlas import KERNEL_ROUNDING


@kernel(inline="always")
def triangle_hit(verts, vbase, tris, row, ox, oy, oz, dx, dy, dz):
    """Moeller-Trumbore in float64, both sides: (t, u, v) with u, v the weights of
    vertices 1 and 2 (Embree's convention); t = inf when the ray misses the triangle."""
    i0, i1, i2 = vbase + tris[row, 0], vbase + tris[row, 1], vbase + tris[row, 2]
    p0x, p0y, p0z = verts[i0, 0], verts[i0, 1], verts[i0, 2]
    e1x, e1y, e1z = verts[i1, 0] - p0x, verts[i1, 1] - p0y, verts[i1, 2] - p0z
    e2x, e2y, e2z = verts[i2, 0] - p0x, verts[i2, 1] - p0y, verts[i2, 2] - p0z
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0 or not math.isfinite(det):
        return np.inf, 0.0, 0.0
    inv = 1.0 / det
    sx, sy, sz = ox - p0x, oy - p0y, oz - p0z
    u = (sx * px + sy * py + sz * pz) * inv
    if not (u >= 0.0 and u <= 1.0):
        return np.inf, 0.0, 0.0
    qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if not (v >= 0.0 and u + v <= 1.0):
        return np.inf, 0.0, 0.0
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    if not t > 0.0:
        return np.inf, 0.0, 0.0
    return t, u, v


@kernel(inline="always")
def nearest_in_unit(blas_box, blas_node, blas_tri, verts, tris, vbase, row0, root,
                    ox, oy, oz, dx, dy, dz, tmax, inclusive, any_hit, stack):
    """The nearest triangle of a kernel unit (BLAS from node root; its triangle k has
    the vertex indices tris[row0 + k] + vbase) along a ray already in the unit's space,
    with t < tmax (t <= tmax when inclusive); any_hit stops at the first one. Returns
    (t, object-local triangle or -1, u, v)."""
    pad = KERNEL_ROUNDING * max(abs(ox), abs(oy), abs(oz))
    ix, px, qx = slab_setup(ox, dx, pad)
    iy, py, qy = slab_setup(oy, dy, pad)
    iz, pz, qz = slab_setup(oz, dz, pad)
    best_t, best_k, best_u, best_v = tmax, -1, 0.0, 0.0
    incl = inclusive
    if slab_entry(blas_box, root, ix, iy, iz, px, py, pz, qx, qy, qz, best_t) == np.inf:
        return np.inf, -1, 0.0, 0.0
    nd = root
    sp = 0
    while True:
        if blas_node[nd, 0] == 1:
            for j in range(blas_node[nd, 1], blas_node[nd, 1] + blas_node[nd, 2]):
                k = blas_tri[j]
                t, u, v = triangle_hit(verts, vbase, tris, row0 + k, ox, oy, oz, dx, dy, dz)
                if t < best_t or (incl and t == best_t):
                    best_t, best_k, best_u, best_v = t, k, u, v
                    incl = False
                    if any_hit:
                        return best_t, best_k, best_u, best_v
            if sp == 0:
                break
            sp -= 1
            nd = stack[sp]
            continue
        a = blas_node[nd, 1]
        b = a + 1
        ta = slab_entry(blas_box, a, ix, iy, iz, px, py, pz, qx, qy, qz, best_t)
        tb = slab_entry(blas_box, b, ix, iy, iz, px, py, pz, qx, qy, qz, best_t)
        if ta != np.inf and tb != np.inf:
            if tb < ta:
                a, b = b, a
            stack[sp] = b
            sp += 1
            nd = a
        elif ta != np.inf:
            nd = a
        elif tb != np.inf:
            nd = b
        else:
            if sp == 0:
                break
            sp -= 1
            nd = stack[sp]
    if best_k < 0:
        return np.inf, -1, 0.0, 0.0
    return best_t, best_k, best_u, best_v


@kernel(inline="always")
def unit_ray(unit_obj, inverses, info, times, trans, quat, stretch, linear, unit, t,
             ox, oy, oz, dx, dy, dz):
    """The ray as unit's geometry sees it: moved into a rigid object's space at time t
    (engine.kernels.motion.object_ray; over an interval that only translates, through
    the precomputed inverse `MotionTLAS.translation_inverse`), unchanged for a deforming
    object's slice (world space)."""
    obj = unit_obj[unit]
    if info[obj, I_KIND] == DEFORM:
        return ox, oy, oz, dx, dy, dz
    a, f = step_of(info, times, obj, t)
    if info[obj, I_STEPS] < 2 or inverses[a, 0] == 0.0:
        return object_ray(info, times, trans, quat, stretch, linear, obj, t,
                          ox, oy, oz, dx, dy, dz)
    qx = ox - (trans[a, 0] + f * (trans[a + 1, 0] - trans[a, 0]))
    qy = oy - (trans[a, 1] + f * (trans[a + 1, 1] - trans[a, 1]))
    qz = oz - (trans[a, 2] + f * (trans[a + 1, 2] - trans[a, 2]))
    inv = inverses
    return (inv[a, 1] * qx + inv[a, 2] * qy + inv[a, 3] * qz,
            inv[a, 4] * qx + inv[a, 5] * qy + inv[a, 6] * qz,
            inv[a, 7] * qx + inv[a, 8] * qy + inv[a, 9] * qz,
            inv[a, 1] * dx + inv[a, 2] * dy + inv[a, 3] * dz,
            inv[a, 4] * dx + inv[a, 5] * dy + inv[a, 6] * dz,
            inv[a, 7] * dx + inv[a, 8] * dy + inv[a, 9] * dz)


@kernel(inline="always")
def _visit_unit(TU, MU, unit, r, tt, ox, oy, oz, dx, dy, dz, best, t, prim, u, v, hit_unit,
                blocked, occlusion, bstack):
    """Kernel unit `unit` against ray r: updates the ray's nearest hit (tie rule of the
    module docstring) or its occlusion. Returns True when an occlusion ray got blocked.
    TU and MU are the tuples of arrays trace_moving unpacks (see there)."""
    unit_obj, unit_slice, unit_root, blas_box, blas_node, blas_tri, inverses = TU
    prim_start, info, times, trans, quat, stretch, linear, verts, tris = MU
    obj = unit_obj[unit]
    vbase = info[obj, I_VERT0]
    if info[obj, I_KIND] == DEFORM:
        vbase += unit_slice[unit] * info[obj, I_NVERTS]
    a, b, c, e, f, g = unit_ray(unit_obj, inverses, info, times, trans, quat, stretch, linear,
                                unit, tt, ox, oy, oz, dx, dy, dz)
    th, k, uu, vv = nearest_in_unit(blas_box, blas_node, blas_tri, verts, tris, vbase,
                                    prim_start[obj] - prim_start[0], unit_root[unit],
                                    a, b, c, e, f, g, best[r], hit_unit[r] > unit, occlusion,
                                    bstack)
    if k < 0:
        return False
    if occlusion:
        blocked[r] = True
        return True
    best[r], t[r], prim[r], u[r], v[r] = th, th, prim_start[obj] + k, uu, vv
    hit_unit[r] = unit
    return False


@kernel(inline="always")
def _pop_nearer(stack, stack_t, sp, lim):
    """Pops pending nodes until one whose entry is not beyond lim: (node or -1, sp)."""
    while sp > 0:
        sp -= 1
        if stack_t[sp] <= lim:
            return stack[sp], sp
    return -1, sp


@kernel
def trace_moving(T, M, origins, dirs, time, best, t, prim, u, v, hit_unit, blocked,
                 occlusion, use_tlas, out_ray, out_unit, visits):
    """The moving objects against a batch of rays, in one call.

    Closest hit (occlusion=False): best[r] is the ray's current limit (its static hit or
    tmax); kernel units' hits nearer than it replace (t, prim, u, v, hit_unit, best).
    Occlusion: rays with blocked[r] or best[r] <= 0 are skipped; a kernel unit's hit
    before best[r] sets blocked[r] (and drops the ray's pairs listed so far).
    Units left to Embree are listed as (ray, unit) pairs in out_ray/out_unit (up to
    their length; the total count is returned: call again with larger arrays when it
    exceeds them, which is safe: a second call finds nothing the first did not, so it
    lists at most as many pairs). visits[0] counts the (ray, unit) pairs examined:
    kernel units intersected plus pairs listed.

    use_tlas=True walks the hierarchy nearest box first, pruning boxes beyond the
    current hit; use_tlas=False is the brute-force reference."""
    node_box, node, item_box, item_unit = T.node_box, T.node, T.item_box, T.item_unit
    item_slices, item_slice, item_time = T.item_slices, T.item_slice, T.item_time
    unit_obj, unit_slice, unit_root = T.unit_obj, T.unit_slice, T.unit_root
    blas_box, blas_node, blas_tri, inverses = T.blas_box, T.blas_node, T.blas_tri, \
        T.translation_inverse
    prim_start, info, times, trans, quat, stretch, linear, verts, tris = M
    TU = (unit_obj, unit_slice, unit_root, blas_box, blas_node, blas_tri, inverses)
    MU = (prim_start, info, times, trans, quat, stretch, linear, verts, tris)
    cap = out_ray.shape[0]
    n_nodes = node.shape[0]
    if n_nodes == 0 or origins.shape[0] == 0:
        return 0
    stack = np.empty(n_nodes + 1, np.int64)
    stack_t = np.empty(n_nodes + 1)
    bstack = np.empty(blas_node.shape[0] + 1, np.int64)
    count = 0
    visited = 0
    for r in range(origins.shape[0]):
        if (occlusion and blocked[r]) or not best[r] > 0.0:
            continue
        first = count
        ox, oy, oz = origins[r, 0], origins[r, 1], origins[r, 2]
        dx, dy, dz = dirs[r, 0], dirs[r, 1], dirs[r, 2]
        tt = time[r]
        done = False
        if not use_tlas:
            for un in range(unit_obj.shape[0]):
                obj = unit_obj[un]
                if info[obj, I_KIND] == DEFORM:
                    sl = info[obj, I_SLICES]
                    if min(max(int(tt * sl), 0), sl - 1) != unit_slice[un]:
                        continue
                visited += 1
                if unit_root[un] < 0:
                    if count < cap:
                        out_ray[count], out_unit[count] = r, un
                    count += 1
                elif _visit_unit(TU, MU, un, r, tt, ox, oy, oz, dx, dy, dz, best, t, prim,
                                 u, v, hit_unit, blocked, occlusion, bstack):
                    done = True
                    break
            if done:
                count = first
            continue
        pad = T.ray_pad * max(abs(ox), abs(oy), abs(oz))
        ix, px, qx = slab_setup(ox, dx, pad)
        iy, py, qy = slab_setup(oy, dy, pad)
        iz, pz, qz = slab_setup(oz, dz, pad)
        lim = best[r]
        if slab_entry(node_box, 0, ix, iy, iz, px, py, pz, qx, qy, qz, lim) == np.inf:
            continue
        nd = 0
        sp = 0
        while nd >= 0:
            if node[nd, 0] == 0:                   # inner node: nearer child first
                a = node[nd, 1]
                b = a + 1
                ta = slab_entry(node_box, a, ix, iy, iz, px, py, pz, qx, qy, qz, lim)
                tb = slab_entry(node_box, b, ix, iy, iz, px, py, pz, qx, qy, qz, lim)
                if ta != np.inf and tb != np.inf:
                    if tb < ta:
                        a, b, ta, tb = b, a, tb, ta
                    stack[sp], stack_t[sp] = b, tb
                    sp += 1
                    nd = a
                elif ta != np.inf:
                    nd = a
                elif tb != np.inf:
                    nd = b
                else:
                    nd, sp = _pop_nearer(stack, stack_t, sp, lim)
                continue
            for it in range(node[nd, 1], node[nd, 1] + node[nd, 2]):
                sl = item_slices[it]
                if sl > 0:
                    if min(max(int(tt * sl), 0), sl - 1) != item_slice[it]:
                        continue
                elif not (item_time[it, 0] <= tt and tt < item_time[it, 1]):
                    continue
                if slab_entry(item_box, it, ix, iy, iz, px, py, pz, qx, qy, qz, lim) == np.inf:
                    continue
                un = item_unit[it]
                visited += 1
                if unit_root[un] < 0:
                    if count < cap:
                        out_ray[count], out_unit[count] = r, un
                    count += 1
                elif _visit_unit(TU, MU, un, r, tt, ox, oy, oz, dx, dy, dz, best, t,
                                 prim, u, v, hit_unit, blocked, occlusion, bstack):
                    done = True
                    break
                else:
                    lim = best[r]
            if done:
                break
            nd, sp = _pop_nearer(stack, stack_t, sp, lim)
        if done:                      # blocked: its Embree pairs are not needed
            count = first
    visits[0] += visited
    return count
