"""MikkTSpace tangents on a triangle mesh, as Cycles computes them for a tangent-space
Normal Map or Vector Displacement: on the render triangles (so n-gons have tangents too),
from the UV map, or without one from `map_to_sphere` of the object-space positions.

The steps are Mikkelsen's (Blender's mikktspace.hh, threshold 180 degrees, tangents only):
1. weld corners with the same position, normal and texture coordinate;
2. give every triangle its texture-space tangent and orientation (the sign of its UV area)
   (with map_to_sphere coordinates, u differences taken around the wrap from 1 to 0, as
   Cycles has taken them since its fix of Blender issue #139753);
3. pair each triangle edge with the reversed edge of a neighbour;
4. at each welded vertex, the triangles of one orientation connected through shared edges
   around it form a group, and each corner takes its group's tangent: the sum of the
   group's triangle tangents projected into the corner's tangent plane, weighted by the
   triangle's angle there, normalised;
5. degenerate triangles (two equal positions) copy a good corner of the same welded vertex.

Triangles with no UV area ('group with any' in Mikkelsen's code) take the orientation of
the first group that reaches them (_orient_any), found from connected components rather
than by Mikkelsen's recursive walk; where such triangles chain between groups of both
orientations the walk's order can decide otherwise."""
from __future__ import annotations

from typing import Optional

import numpy as np

FLT_MIN = np.float32(1.17549435e-38)


def map_to_sphere(p: np.ndarray) -> np.ndarray:
    """Cycles' map_to_sphere of object-space points (..., 3) float32 -> (..., 2)."""
    p = p.astype(np.float32)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    length2 = x * x + y * y + z * z
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where((x == 0) & (y == 0), np.float32(0),
                     np.float32(0.5) - np.arctan2(x, y) * np.float32(0.5 / np.pi))
        v = np.float32(1) - np.arccos(np.clip(z / np.sqrt(length2), -1, 1)) \
            * np.float32(1 / np.pi)
    inside = length2 > 0
    return np.stack([np.where(inside, u, 0), np.where(inside, v, 0)], -1).astype(np.float32)


def _normalize(v: np.ndarray) -> np.ndarray:
    """mikk's normalize: unchanged where the length is 0."""
    length = np.sqrt(np.einsum("...i,...i->...", v, v))[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length != 0, v * (np.float32(1) / length), v).astype(np.float32)


def _project(n: np.ndarray, v: np.ndarray) -> np.ndarray:
    return _normalize(v - n * np.einsum("...i,...i->...", n, v)[..., None])


def _fast_acos(x: np.ndarray) -> np.ndarray:
    """Cycles' fast_acosf, which mikk weights the corners by."""
    f = np.abs(x)
    m = np.where(f < 1, np.float32(1) - (np.float32(1) - f), np.float32(1))
    a = np.sqrt(np.float32(1) - m) * (np.float32(1.5707963267) + m * (np.float32(-0.213300989)
        + m * (np.float32(0.077980478) + m * np.float32(-0.02164095))))
    return np.where(x < 0, np.float32(np.pi) - a, a).astype(np.float32)


def face_normals(p: np.ndarray) -> np.ndarray:
    """Each triangle's own normal (T, 3), (1, 0, 0) where it has no area (Cycles'
    Triangle::compute_normal), for the corners of flat-shaded faces."""
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]).astype(np.float32)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length == 0, np.float32([1, 0, 0]), n / length).astype(np.float32)


def _weld(p, n, uv) -> np.ndarray:
    """Welded index per corner (3T,): corners equal in position, normal and texcoord.
    Rows are grouped by a 64-bit hash of their bits and checked equal within each group
    (np.unique on the rows where two differing rows share a hash)."""
    rows = np.concatenate([p.reshape(-1, 3), n.reshape(-1, 3), uv.reshape(-1, 2)], 1)
    rows = np.ascontiguousarray(rows.astype(np.float32) + np.float32(0))   # -0 == 0
    bits = rows.view(np.uint32)
    h = np.full(len(rows), 0xCBF29CE484222325, np.uint64)
    with np.errstate(over="ignore"):
        for k in range(bits.shape[1]):
            h = (h ^ bits[:, k].astype(np.uint64)) * np.uint64(0x100000001B3)
    order = np.argsort(h, kind="stable")
    sh = h[order]
    new = np.r_[True, sh[1:] != sh[:-1]]
    group = np.cumsum(new) - 1
    sorted_bits = bits[order]
    if not np.all(sorted_bits == sorted_bits[np.flatnonzero(new)[group]]):
        keys = rows.view(np.dtype((np.void, rows.dtype.itemsize * 8))).ravel()
        return np.unique(keys, return_inverse=True)[1].astype(np.int64).ravel()
    out = np.empty(len(rows), np.int64)
    out[order] = group
    return out


def _neighbours(w: np.ndarray) -> np.ndarray:
    """(G, 3) triangle across each edge i (corner i -> i+1), -1 where none: each directed
    edge pairs with its reverse, the k-th of one with the k-th of the other, as mikk's
    greedy pass in triangle order pairs them."""
    g = len(w)
    a = w.ravel().astype(np.int64)
    b = w[:, [1, 2, 0]].ravel().astype(np.int64)
    v = int(w.max()) + 1
    pair = a * v + b
    order = np.argsort(pair, kind="stable")          # within a pair: triangle order
    sp = pair[order]
    new = np.r_[True, sp[1:] != sp[:-1]]
    start = np.maximum.accumulate(np.where(new, np.arange(len(sp)), 0))
    rank = np.empty(3 * g, np.int64)
    rank[order] = np.arange(len(sp)) - start
    r = int(rank.max()) + 1
    sorted_key = sp * r + rank[order]
    want = (b * v + a) * r + rank
    by_want = np.argsort(want)                       # sorted needles search fast
    lo = np.empty(3 * g, np.int64)
    lo[by_want] = np.searchsorted(sorted_key, want[by_want])
    hit = np.minimum(lo, len(sorted_key) - 1)
    found = sorted_key[hit] == want
    out = np.full(3 * g, -1, np.int64)
    out[found] = order[hit[found]] // 3
    return out.reshape(g, 3)


def _corner_links(w, nb, ok):
    """Pairs of corners (t*3+i) at the same welded vertex across an edge incident to it,
    between neighbours for which ok(t, u) holds (arrays of triangles)."""
    g = len(w)
    node = np.arange(3 * g).reshape(g, 3)
    rows, cols = [], []
    for i in range(3):
        for edge in (i, (i + 2) % 3):
            u = nb[:, edge]
            t = np.flatnonzero(u >= 0)
            t = t[ok(t, u[t])]
            match = w[u[t]] == w[t, i][:, None]
            has = match.any(1)
            rows.append(node[t[has], i])
            cols.append(node[u[t[has]], match[has].argmax(1)])
    return np.concatenate(rows), np.concatenate(cols)


def _components(n, rows, cols):
    """A label per node (n,) of the graph with edges (rows, cols): the smallest node of
    its connected component, by min-label propagation with pointer jumping (the
    components here are fans of corners around one vertex, so few rounds; plain NumPy,
    as the extension bundles no SciPy)."""
    label = np.arange(n)
    while len(rows):
        low = np.minimum(label[rows], label[cols])
        new = label.copy()
        np.minimum.at(new, rows, low)
        np.minimum.at(new, cols, low)
        new = new[new]
        if np.array_equal(new, label):
            break
        label = new
    return label


def _orient_any(w, nb, orient, any_):
    """The orientation a triangle with no UV area takes: that of the first group to reach
    it, groups being seeded in corner order (t * 3 + i) at corners of triangles with UV
    area and spreading around their vertex through neighbours of their orientation (and
    through triangles with no UV area): per orientation, the lowest such corner connected
    to one of the triangle's corners. Where such triangles chain, each is taken to pass a
    group of either orientation on."""
    if not any_.any():
        return orient
    g = len(w)
    corner_any = np.repeat(any_, 3)
    first = []
    for o in (False, True):
        keep = any_ | (orient == o)
        rows, cols = _corner_links(w, nb, lambda t, u: keep[t] & keep[u])
        label = _components(3 * g, rows, cols)
        seeds = np.where(~corner_any & np.repeat(keep, 3), np.arange(3 * g), 3 * g)
        lowest = np.full(label.max() + 1, 3 * g)
        np.minimum.at(lowest, label, seeds)
        first.append(lowest[label].reshape(g, 3).min(1))
    out = orient.copy()
    out[any_] = (first[1] < first[0])[any_]
    return out


def tangents(positions: np.ndarray, triangles: np.ndarray, normals: np.ndarray,
             uvs: Optional[np.ndarray]) -> np.ndarray:
    """(T, 3, 4) float32 tangent and bitangent sign per triangle corner, object space.

    positions (V, 3), triangles (T, 3), normals (T, 3, 3) per corner (the smooth normal of
    smooth faces, the triangle's own of flat ones), uvs (T, 3, 2) or None (map_to_sphere)."""
    tris = np.asarray(triangles, np.int64)
    nt = len(tris)
    out = np.zeros((nt, 3, 4), np.float32)
    out[..., 0], out[..., 3] = 1, -1                     # mikk's default tangent space
    if nt == 0:
        return out
    p = np.asarray(positions, np.float32)[tris]
    n = np.asarray(normals, np.float32)
    uv = map_to_sphere(p) if uvs is None else np.asarray(uvs, np.float32)
    w = _weld(p, n, uv).reshape(nt, 3)
    degenerate = (np.all(p[:, 0] == p[:, 1], 1) | np.all(p[:, 0] == p[:, 2], 1)
                  | np.all(p[:, 1] == p[:, 2], 1))
    # a non-finite position, normal or texcoord: left out like a degenerate triangle, so
    # that no NaN reaches a good corner's group
    degenerate |= ~(np.isfinite(p).all((1, 2)) & np.isfinite(n).all((1, 2))
                    & np.isfinite(uv).all((1, 2)))
    good = np.flatnonzero(~degenerate)
    if len(good):
        _good_tangents(out, good, p[good], n[good], uv[good], w[good], uvs is None)
    _copy_to_degenerate(out, good, np.flatnonzero(degenerate), w)
    bad = ~np.isfinite(out).all(-1)
    out[bad] = (1.0, 0.0, 0.0, -1.0)
    return out


def _good_tangents(out, good, p, n, uv, w, sphere) -> None:
    g = len(good)
    t21, t31 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    if sphere:        # map_to_sphere's u wraps from 1 to 0: its differences do too (Cycles)
        for d in (t21, t31):
            d[:, 0] -= np.floor(d[:, 0] + np.float32(0.5))
    d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area2 = t21[:, 0] * t31[:, 1] - t21[:, 1] * t31[:, 0]
    v_os = t31[:, 1, None] * d1 - t21[:, 1, None] * d2
    v_ot = -t31[:, 0, None] * d1 + t21[:, 0, None] * d2
    orient = area2 > 0
    len_os2 = np.einsum("ij,ij->i", v_os, v_os)
    len_ot2 = np.einsum("ij,ij->i", v_ot, v_ot)
    has_area = np.abs(area2) > FLT_MIN
    with np.errstate(invalid="ignore", divide="ignore"):
        sign = np.where(orient, np.float32(1), np.float32(-1))
        tangent = np.where((has_area & (len_os2 > FLT_MIN))[:, None],
                           v_os * (sign / np.sqrt(len_os2))[:, None], 0).astype(np.float32)
    any_ = ~(has_area & (len_os2 > FLT_MIN) & (len_ot2 > FLT_MIN))
    nb = _neighbours(w)
    orient = _orient_any(w, nb, orient, any_)
    rows, cols = _corner_links(w, nb, lambda t, u: orient[t] == orient[u])
    label = _components(3 * g, rows, cols)
    node = np.arange(3 * g).reshape(g, 3)
    # a group forms only around a corner of a triangle with UV area (mikk's seeds)
    seeded = np.zeros(label.max() + 1, bool)
    seeded[label[np.repeat(~any_, 3)]] = True
    grouped = seeded[label]
    # accumulate: projected tangent times the corner's angle, from triangles with UV area
    acc = np.zeros((label.max() + 1, 3), np.float32)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        cos = np.einsum("ij,ij->i", _project(n[:, i], p[:, j] - p[:, i]),
                        _project(n[:, i], p[:, k] - p[:, i]))
        contrib = _project(n[:, i], tangent) * _fast_acos(np.clip(cos, -1, 1))[:, None]
        src = ~any_
        np.add.at(acc, label[node[src, i]], contrib[src])
    acc = _normalize(acc)
    corner = grouped.reshape(g, 3)
    res = out[good]
    res[..., :3] = np.where(corner[..., None], acc[label].reshape(g, 3, 3), res[..., :3])
    res[..., 3] = np.where(corner, np.where(orient, 1, -1)[:, None], res[..., 3])
    out[good] = res


def _copy_to_degenerate(out, good, degenerate, w) -> None:
    """A degenerate triangle's corners take the tangent space of the first good corner
    (in triangle order) with the same welded vertex, else keep the default."""
    if len(degenerate) == 0 or len(good) == 0:
        return
    gw = w[good].ravel()
    src = (good[:, None] * 3 + np.arange(3)).ravel()
    uniq, idx = np.unique(gw, return_index=True)
    first = dict(zip(uniq.tolist(), src[idx].tolist()))
    flat = out.reshape(-1, 4)
    for t in degenerate:
        for i in range(3):
            s = first.get(int(w[t, i]))
            if s is not None:
                flat[t * 3 + i] = flat[s]
