"""Adaptive subdivision (Cycles' dicing) of a triangle mesh, before true displacement.

A mesh whose last modifier is a Subdivision modifier with Adaptive Subdivision on is
diced by Cycles so that its edges are about a dicing rate long: that many pixels on
screen (Pixel space, the rate scaled by the distance to the camera and coarser off
screen) or that length in object space (Object space). Cycles measures an edge by its
length over the size of a pixel there (Camera::world_to_raster_size), sampled at
`TEST_STEPS` points, and splits it into T = ceil((steps - 1) * longest step / rate)
segments, at most 2 ** max_level per edge of the cage (DiagSplit::T).

DRT receives the mesh at the modifier's render levels (Blender subdivides it when it is
read), so here each of its edges gets T segments by the same rule, capped at
2 ** (max_level - render levels), and each triangle is tessellated by its three edges'
factors: a regular grid where they agree; otherwise a regular interior grid stitched to
each edge's own points. Neighbouring triangles share their edge's points, so the result
is watertight. DRT never dices coarser than the render levels (Cycles starts from the
cage, so a distant mesh may come out coarser there).

The functions are NumPy, vectorised over the triangles that share one factor triple.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

TEST_STEPS = 3          # Cycles' SubdParams::test_steps


@dataclass(frozen=True)
class DicingCamera:
    """What Cycles' Camera::world_to_raster_size reads of a camera, in Blender's camera
    space (looking down -z): the world-to-camera matrix, the view plane's extent at
    z = -1 (half sizes and shift; for an orthographic camera in world units), the raster
    size in pixels and the offscreen dicing scale."""
    to_camera: np.ndarray          # (4, 4)
    half_x: float
    half_y: float
    shift_x: float
    shift_y: float
    width: int
    height: int
    orthographic: bool = False
    offscreen_scale: float = 4.0

    @staticmethod
    def from_model(model, offscreen_scale: float = 4.0) -> "DicingCamera":
        """From an engine.camera.CameraModel (its rotation, position and view plane)."""
        to_world = np.eye(4)
        to_world[:3, :3] = model.rotation
        to_world[:3, 3] = model.position
        return DicingCamera(np.linalg.inv(to_world), float(model.half_x),
                            float(model.half_y), float(model.shift[0]),
                            float(model.shift[1]), int(model.width), int(model.height),
                            model.camera.kind == "ORTHO", float(offscreen_scale))

    def raster_size(self, points: np.ndarray) -> np.ndarray:
        """The world size of a pixel at each point (n, 3), as Cycles' dicing measures it:
        at the point's distance, as if it lay straight ahead, grown off screen by the
        offscreen dicing scale."""
        p = points @ self.to_camera[:3, :3].T + self.to_camera[:3, 3]
        dx = 2.0 * self.half_x / max(self.width, 1)
        dy = 2.0 * self.half_y / max(self.height, 1)
        step = min(dx, dy)                        # Cycles takes the shorter pixel side
        grow = max(self.offscreen_scale - 1.0, 0.0)
        if self.orthographic:
            inside = np.stack([np.clip(p[:, 0], self.shift_x - self.half_x,
                                       self.shift_x + self.half_x),
                               np.clip(p[:, 1], self.shift_y - self.half_y,
                                       self.shift_y + self.half_y),
                               np.minimum(p[:, 2], 0.0)], axis=1)
            corner = np.sqrt(0.5 * (self.half_x ** 2 + self.half_y ** 2))
            outside = np.linalg.norm(p - inside, axis=1) / max(corner, 1e-300)
            return step * (1.0 + outside * grow)
        centre = np.array([self.shift_x, self.shift_y, -1.0])
        d = centre / np.linalg.norm(centre)
        side = np.array([1.0, 0.0, 0.0]) if dx <= dy else np.array([0.0, 1.0, 0.0])
        dd = (centre + step * side) / np.linalg.norm(centre + step * side) - d
        angle = np.linalg.norm(dd - np.dot(dd, d) * d)    # dD/dx across the view
        dist = np.linalg.norm(p, axis=1)
        return angle * dist + angle * self._outside(p, dist) * grow

    def _outside(self, p: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Cycles' approximate distance of each point from the view frustum."""
        xr, xl = self.shift_x + self.half_x, self.shift_x - self.half_x
        yt, yb = self.shift_y + self.half_y, self.shift_y - self.half_y
        normals = np.array([[1.0, 0.0, xr], [-1.0, 0.0, -xl],
                            [0.0, 1.0, yt], [0.0, -1.0, -yb]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        along = np.array([[xr, 0.0, -1.0], [xl, 0.0, -1.0], [0.0, yt, -1.0], [0.0, yb, -1.0]])
        d = p @ normals.T                                    # (n, 4) signed distances
        ahead = (p @ along.T) >= 0.0
        beside = d > 0.0
        f = np.max(np.where(beside & ahead, d, 0.0), axis=1)
        test_origin = np.any(beside & ~ahead, axis=1)
        f = np.where(test_origin, np.where(f > 0.0, np.minimum(f, dist), dist), f)
        f = np.where(np.all(beside, axis=1), dist, f)        # behind the camera
        return np.where(np.any(beside, axis=1), f, 0.0)


def edge_factors(a: np.ndarray, b: np.ndarray, rate: float, max_factor: int,
                 camera: DicingCamera | None = None) -> np.ndarray:
    """Segments (E,) int for the edges from a to b (E, 3): Cycles' DiagSplit::T, in
    pixels of `camera` (points in the world) or, without one, in the points' own units
    (Object space). `rate` is the wanted segment length; at most `max_factor`."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    with np.errstate(invalid="ignore", over="ignore"):     # non-finite: one segment
        longest = _longest(a, b, camera)
    t = np.ceil((TEST_STEPS - 1) * longest / max(rate, 1e-12))
    t = np.where(np.isfinite(t), t, 1.0)
    return np.clip(t, 1, max(int(max_factor), 1)).astype(np.int64)


def _longest(a, b, camera):
    """The longest of an edge's TEST_STEPS - 1 steps, in pixels with a camera."""
    longest = np.zeros(len(a))
    last = a
    for i in range(1, TEST_STEPS):
        t = i / (TEST_STEPS - 1)
        p = a + t * (b - a)
        length = np.linalg.norm(p - last, axis=1)
        if camera is not None:
            length = length / np.maximum(camera.raster_size(0.5 * (p + last)), 1e-300)
        longest = np.maximum(longest, length)
        last = p
    return longest


@dataclass(frozen=True)
class Template:
    """One triangle tessellated for a factor triple (m0, m1, m2) of its edges 0->1,
    1->2 and 2->0. Points are its corners, then each edge's inner points in order, then
    interior points; `weights` (P, 3) are their barycentric coordinates, `triangles`
    (K, 3) index the points, wound as the triangle is."""
    factors: tuple
    weights: np.ndarray
    triangles: np.ndarray

    @property
    def interior(self) -> int:
        return len(self.weights) - 3 - sum(m - 1 for m in self.factors)


def _lattice_triangles(idx: np.ndarray, n: int, low: int) -> np.ndarray:
    """The triangles (K, 3) of a barycentric lattice of size n, wound 0 -> 1 -> 2, whose
    points (w1, w2) all have w0, w1, w2 >= low, as indices idx[w1, w2]."""
    w1, w2 = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    up = (w1 >= low) & (w2 >= low) & (w1 + w2 <= n - 1 - low)
    down = (w1 >= low) & (w2 >= low) & (w1 + w2 <= n - 2 - low)
    a1, a2 = w1[up], w2[up]
    b1, b2 = w1[down], w2[down]
    return np.concatenate([
        np.stack([idx[a1, a2], idx[a1 + 1, a2], idx[a1, a2 + 1]], axis=1),
        np.stack([idx[b1 + 1, b2], idx[b1 + 1, b2 + 1], idx[b1, b2 + 1]], axis=1)])


@lru_cache(maxsize=64)
def template(m0: int, m1: int, m2: int) -> Template:
    """The tessellation of one triangle for edge factors (m0, m1, m2) (Template)."""
    ms = (m0, m1, m2)
    n = max(ms)
    corners = np.eye(3)
    weights = [corners]
    for k, m in enumerate(ms):          # each edge's inner points, from corner k on
        t = (np.arange(1, m) / m)[:, None]
        weights.append(corners[k] * (1.0 - t) + corners[(k + 1) % 3] * t)
    first = 3 + np.concatenate([[0], np.cumsum([m - 1 for m in ms])])
    size = n if m0 == m1 == m2 else max(n, 3)
    w1, w2 = np.meshgrid(np.arange(size + 1), np.arange(size + 1), indexing="ij")
    w0 = size - w1 - w2
    interior = (w0 >= 1) & (w1 >= 1) & (w2 >= 1)
    idx = np.full((size + 1, size + 1), -1, np.int64)
    idx[interior] = int(first[3]) + np.arange(int(interior.sum()))
    weights.append(np.stack([w0[interior], w1[interior], w2[interior]], 1) / size)
    weights = np.concatenate(weights)
    if m0 == m1 == m2:                   # a regular grid, its boundary the edges' points
        idx[0, 0], idx[n, 0], idx[0, n] = 0, 1, 2
        i = np.arange(1, n)
        idx[i, 0] = first[0] + i - 1     # edge 0: w2 = 0, w1 = i
        idx[n - i, i] = first[1] + i - 1     # edge 1: w0 = 0, w2 = i
        idx[0, n - i] = first[2] + i - 1     # edge 2: w1 = 0, w0 = i
        return Template(ms, weights, _lattice_triangles(idx, n, 0))
    # the interior: the lattice of size N >= 3 without its boundary, stitched to the
    # edges' own points
    tris = [_lattice_triangles(idx, size, 1)]
    outer = [0]                          # the boundary loop, counter-clockwise
    outer_u = [0.0]
    for k, m in enumerate(ms):
        outer += list(range(int(first[k]), int(first[k]) + m - 1)) + [(k + 1) % 3]
        outer_u += [k + i / m for i in range(1, m)] + [k + 1.0]
    ring, ring_u = _ring(size, idx)
    tris.append(np.array(_zip(outer[:-1], outer_u[:-1], ring, ring_u, weights),
                         np.int64).reshape(-1, 3))
    return Template(ms, weights, np.concatenate(tris))


def _ring(size, idx):
    """The interior lattice's boundary loop, counter-clockwise from the point nearest
    corner 0, and each point's parameter round it (side k, across from edge k, from
    k to k + 1)."""
    if size == 3:
        return [int(idx[1, 1])], [0.0]
    s = size - 3
    j = np.arange(s)
    ring = np.concatenate([idx[1 + j, 1],                  # across from edge 0
                           idx[size - 2 - j, 1 + j],       # edge 1
                           idx[1, size - 2 - j]])          # edge 2
    return [int(r) for r in ring], [k + i / s for k in range(3) for i in range(s)]


def _zip(outer, outer_u, ring, ring_u, weights):
    """Triangles between the boundary loop and the interior ring (both counter-clockwise,
    starting across from each other), advancing along whichever loop's next point comes
    first by its parameter round the boundary (0 to 3; at a corner, the step whose new
    edge is shorter), unless that makes a triangle of no area where the other does not."""
    w = np.asarray(weights)
    xy = np.stack([w[:, 1] + 0.5 * w[:, 2], w[:, 2] * np.sqrt(0.75)], axis=1).tolist()

    def area(a, b, c):
        (ax, ay), (bx, by), (cx, cy) = xy[a], xy[b], xy[c]
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    def length(a, b):
        return (xy[a][0] - xy[b][0]) ** 2 + (xy[a][1] - xy[b][1]) ** 2
    tris = []
    i = j = 0
    no, nr = len(outer), len(ring)
    while i < no or j < nr:
        o0, o1 = outer[i % no], outer[(i + 1) % no]
        r0, r1 = ring[j % nr], ring[(j + 1) % nr]
        if j >= nr:
            step_outer = True
        elif i >= no:
            step_outer = False
        else:
            next_o = outer_u[i + 1] if i + 1 < no else 3.0
            next_r = ring_u[j + 1] if j + 1 < nr else 3.0
            step_outer = next_o < next_r
            if next_o == next_r:          # at a corner: the shorter new edge
                step_outer = length(o1, r0) <= length(o0, r1)
            flat = 1e-12
            if step_outer and area(o0, o1, r0) <= flat < area(o0, r1, r0):
                step_outer = False
            elif not step_outer and area(o0, r1, r0) <= flat < area(o0, o1, r0):
                step_outer = True
        if step_outer:
            tris.append([o0, o1, r0])
            i += 1
        else:
            tris.append([o0, r1, r0])
            j += 1
    return [t for t in tris if len(set(t)) == 3]


@dataclass
class Diced:
    """A tessellated mesh: positions (V', 3), triangles (T', 3), each new triangle's
    parent triangle (T',) and its corners' barycentric weights in the parent (T', 3, 3),
    and each new vertex's parent-corner weights by vertex: `vertex_of` (V', 3) vertex
    indices into the old mesh and `vertex_weights` (V', 3)."""
    positions: np.ndarray
    triangles: np.ndarray
    parent: np.ndarray
    corner_weights: np.ndarray
    vertex_of: np.ndarray
    vertex_weights: np.ndarray


def unique_edges(triangles: np.ndarray):
    """The mesh's edges (E, 2), low vertex first, and each triangle corner's edge
    (T, 3) (edge k runs from corner k to corner k + 1)."""
    t = np.asarray(triangles, np.int64)
    pairs = np.stack([t, np.roll(t, -1, axis=1)], axis=2).reshape(-1, 2)
    edges, inverse = np.unique(np.sort(pairs, axis=1), axis=0, return_inverse=True)
    return edges, inverse.reshape(-1, 3)


def tessellation_size(triangles: np.ndarray, factors: np.ndarray) -> int:
    """Triangles that `dice` makes for per-edge `factors` (an upper bound)."""
    _, tri_edges = unique_edges(triangles)
    n = factors[tri_edges].max(axis=1)
    return int(np.sum(np.maximum(n, 3) ** 2 + 2 * np.maximum(n, 3)))


def dice(positions: np.ndarray, triangles: np.ndarray, factors: np.ndarray) -> Diced:
    """Tessellate `triangles` of `positions` (V, 3) with `factors` (E,) segments per
    edge of unique_edges(triangles) (template per factor triple)."""
    positions = np.asarray(positions, np.float64)
    t = np.asarray(triangles, np.int64)
    edges, tri_edges = unique_edges(t)
    factors = np.maximum(np.asarray(factors, np.int64), 1)
    # each edge's inner points, shared by its triangles: from the low vertex up
    inner = factors - 1
    edge_start = len(positions) + np.concatenate([[0], np.cumsum(inner)[:-1]])
    e_of = np.repeat(np.arange(len(edges)), inner)
    k = np.arange(len(e_of)) - np.repeat(edge_start - len(positions), inner) + 1
    s = (k / factors[e_of])[:, None]
    lo, hi = edges[e_of, 0], edges[e_of, 1]
    vertex_of = [np.stack([np.arange(len(positions))] * 3, 1),
                 np.stack([lo, hi, hi], 1)]
    vertex_weights = [np.tile([1.0, 0.0, 0.0], (len(positions), 1)),
                      np.concatenate([1.0 - s, s, np.zeros_like(s)], 1)]
    new_pos = [positions, positions[lo] * (1.0 - s) + positions[hi] * s]
    next_vertex = len(positions) + len(e_of)
    out_tris, out_parent, out_weights = [], [], []
    m = factors[tri_edges]                                    # (T, 3)
    keys, group = np.unique(m, axis=0, return_inverse=True)
    for g, key in enumerate(keys):
        members = np.flatnonzero(group.reshape(-1) == g)
        tp = template(*(int(x) for x in key))
        ids = np.empty((len(members), len(tp.weights)), np.int64)
        ids[:, :3] = t[members]
        col = 3
        for c in range(3):
            mc = int(key[c])
            if mc == 1:
                continue
            e = tri_edges[members, c]
            forward = edges[e, 0] == t[members, c]
            i = np.arange(1, mc)
            along = np.where(forward[:, None], i[None, :], mc - i[None, :])
            ids[:, col:col + mc - 1] = edge_start[e][:, None] + along - 1
            col += mc - 1
        ni = tp.interior
        if ni:
            ids[:, col:] = next_vertex + np.arange(len(members) * ni).reshape(-1, ni)
            next_vertex += len(members) * ni
            w = tp.weights[col:]                              # (ni, 3)
            corners = t[members]                              # (G, 3)
            new_pos.append(np.einsum("pc,gcx->gpx", w, positions[corners]).reshape(-1, 3))
            vertex_of.append(np.repeat(corners, ni, axis=0))
            vertex_weights.append(np.tile(w, (len(members), 1)))
        out_tris.append(ids[:, tp.triangles].reshape(-1, 3))
        out_parent.append(np.repeat(members, len(tp.triangles)))
        out_weights.append(np.tile(tp.weights[tp.triangles], (len(members), 1, 1)))
    order = np.argsort(np.concatenate(out_parent), kind="stable")
    return Diced(np.concatenate(new_pos), np.concatenate(out_tris)[order].astype(np.int32),
                 np.concatenate(out_parent)[order], np.concatenate(out_weights)[order],
                 np.concatenate(vertex_of), np.concatenate(vertex_weights))


def interpolate_corners(values: np.ndarray, diced: Diced) -> np.ndarray:
    """Per-corner values (T, 3, C) of the old triangles at the new corners (T', 3, C)."""
    v = np.asarray(values)
    out = np.einsum("tjc,tcx->tjx", diced.corner_weights.astype(np.float64),
                    v[diced.parent].astype(np.float64))
    return out.astype(v.dtype)


def interpolate_vertices(values: np.ndarray, diced: Diced) -> np.ndarray:
    """Per-vertex values (V, C) of the old mesh at the new vertices (V', C)."""
    v = np.asarray(values, np.float64)
    return np.einsum("vc,vcx->vx", diced.vertex_weights, v[diced.vertex_of])
