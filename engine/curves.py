"""Hair: strands drawn as round tubes along a smooth curve through their keys, as Cycles
draws them with its default curve shape (Curves > Shape "3D Curves"; Blender's
`render.hair_type` STRAND).

Each strand is a Catmull-Rom spline through its keys, its radius interpolated by the
same basis, and its surface is the sweep of a sphere of that radius along the spline:
Embree's round Catmull-Rom curve, which Embree intersects exactly (`engine.accel`), as
Cycles' CPU kernels do. As Cycles does, the first and the last key are repeated, so the
spline starts at the root and ends at the tip; a strand of k keys is k - 1 segments.

`HairCurves` is a scene element beside the triangle meshes (`Scene.curves`). Its
segments are primitives like triangles: each has a global id (after the static
triangles, `engine.accel`), a material, an object, visibility and a texture coordinate,
and the per-primitive tables (`engine.surface.SurfaceBuilder`) take a segment as a
triangle whose corners are its two end keys (`triangles`), so a texture or colour
attribute read at any point of a segment is its strand's. Only the hit point and its
normal are a curve's own (`engine.kernels.curve_hit`). Curves are not light sources:
an emissive strand is seen by camera and BSDF rays, not sampled, as in Cycles.
"""
from __future__ import annotations

from functools import cached_property
from typing import Optional

import numpy as np


class HairCurves:
    """Strands of one object, in world space.

    keys: (K, 3) key positions; radii: (K,) each key's radius (metres);
    curve_keys: (C + 1,) offsets, strand c's keys being rows curve_keys[c]:curve_keys[c+1]
    (at least 2 each); materials: (C,) or one index into Scene.materials;
    uvs: optional (C, 2) each strand's texture coordinate (its root's on the emitter);
    colors: optional (C, 4) a colour attribute per strand.
    What the Hair Info node reads (as Cycles has them, in the object's own space):
    intercepts: optional (K,) each key's fraction of its strand's length, lengths:
    optional (C,) each strand's length (both measured along the keys in world space when
    not given); first_index: the strands' first index in the object, for Random;
    strand_index: optional (C,) each strand's index after first_index (default 0, 1, ...:
    a strand's place among its object's curves, which a left-out curve does not close up).
    The per-segment tables (`triangles`, `material_indices`, `uvs`, `colors`) are
    computed once."""

    # what a triangle mesh may have and strands have not
    corner_normals = None
    tangents = None
    undisplaced = None
    motion = None
    instances = None
    terminator_offset = 0.0

    def __init__(self, name: str, keys, radii, curve_keys, materials=0, uvs=None,
                 colors=None, holdout: bool = False, visibility: int = 31,
                 object_info: Optional[object] = None, pass_index: int = 0,
                 object_name: str = "", asset_name: str = "", intercepts=None,
                 lengths=None, first_index: int = 0, strand_index=None):
        self.name = name
        self.keys = np.ascontiguousarray(keys, np.float64).reshape(-1, 3)
        self.radii = np.ascontiguousarray(radii, np.float64).reshape(-1)
        self.curve_keys = np.ascontiguousarray(curve_keys, np.int64).reshape(-1)
        if len(self.radii) != len(self.keys):
            raise ValueError(f"hair {name!r}: {len(self.radii)} radii for "
                             f"{len(self.keys)} keys")
        if len(self.curve_keys) < 1 or self.curve_keys[0] != 0 \
                or self.curve_keys[-1] != len(self.keys):
            raise ValueError(f"hair {name!r}: curve offsets must run from 0 to the key count")
        lengths = np.diff(self.curve_keys)
        if np.any(lengths < 2):
            raise ValueError(f"hair {name!r}: a strand needs at least 2 keys")
        if not np.all(np.isfinite(self.keys)):
            raise ValueError(f"hair {name!r} has non-finite (NaN or Inf) key positions")
        if not np.all(np.isfinite(self.radii)) or np.any(self.radii < 0):
            raise ValueError(f"hair {name!r} has a negative or non-finite radius")
        n = len(lengths)
        mats = np.ascontiguousarray(materials, np.int32).reshape(-1)
        self.curve_materials = np.full(n, mats[0], np.int32) if mats.size == 1 else mats
        if len(self.curve_materials) != n:
            raise ValueError(f"hair {name!r}: {len(self.curve_materials)} materials for "
                             f"{n} strands")
        self.curve_uvs = None if uvs is None else np.asarray(uvs, np.float32).reshape(n, 2)
        self.curve_colors = None if colors is None else \
            np.asarray(colors, np.float32).reshape(n, 4)
        self.holdout, self.visibility = holdout, visibility
        self.object_info, self.pass_index = object_info, pass_index
        self.object_name, self.asset_name = object_name, asset_name
        self.intercepts, self.lengths = _along(self.keys, self.curve_keys)
        if intercepts is not None:
            self.intercepts = np.asarray(intercepts, np.float64).reshape(len(self.keys))
        if lengths is not None:
            self.lengths = np.asarray(lengths, np.float64).reshape(n)
        self.first_index = int(first_index)
        # each strand's index for the Hair Info node's Random: its place among its
        # object's curves (Cycles counts the one-point curves the export leaves out)
        own = np.arange(n, dtype=np.int64) if strand_index is None \
            else np.asarray(strand_index, np.int64).reshape(-1)
        if len(own) != n or (n and own.min() < 0):
            raise ValueError(f"hair {name!r}: {len(own)} strand indices for {n} strands "
                             "(each >= 0)")
        self.strand_index = self.first_index + own
        # the strand of each segment, and the key each segment starts at
        self.segment_curve = np.repeat(np.arange(n, dtype=np.int64), lengths - 1)
        starts = np.repeat(self.curve_keys[:-1], lengths - 1)
        self.segment_key = starts + (np.arange(len(starts)) - np.repeat(
            np.cumsum(lengths - 1) - (lengths - 1), lengths - 1))

    @property
    def segment_count(self) -> int:
        return len(self.segment_key)

    @property
    def curve_count(self) -> int:
        return len(self.curve_keys) - 1

    # -- what the per-primitive tables read (a segment as a triangle: its two end keys) --
    @property
    def positions(self) -> np.ndarray:
        return self.keys

    @cached_property
    def triangles(self) -> np.ndarray:
        a = self.segment_key.astype(np.int32)
        return np.stack([a, a + 1, a + 1], axis=1)

    @cached_property
    def material_indices(self) -> np.ndarray:
        return self.curve_materials[self.segment_curve]

    @cached_property
    def uvs(self):
        if self.curve_uvs is None:
            return None
        return np.repeat(self.curve_uvs[self.segment_curve][:, None, :], 3, axis=1)

    @cached_property
    def colors(self):
        if self.curve_colors is None:
            return None
        return np.repeat(self.curve_colors[self.segment_curve][:, None, :], 3, axis=1)

    # -- what Embree and the kernels read ------------------------------------------------
    def control_points(self) -> tuple[np.ndarray, np.ndarray]:
        """((K + 2C, 4) x, y, z, radius: each strand's keys with its first and last key
        repeated, (S,) each segment's first control point (Embree reads 4 from it))."""
        n = self.curve_count
        rows = np.empty((len(self.keys) + 2 * n, 4))
        # strand c's control points start at curve_keys[c] + 2c: root, keys..., tip
        shift = self.curve_keys[:-1] + 2 * np.arange(n)
        lengths = np.diff(self.curve_keys)
        dest = np.arange(len(self.keys)) + 1 + 2 * np.repeat(np.arange(n), lengths)
        rows[dest, :3], rows[dest, 3] = self.keys, self.radii
        rows[shift] = rows[shift + 1]
        tips = shift + lengths + 1
        rows[tips] = rows[tips - 1]
        first = self.segment_key + 2 * self.segment_curve
        return rows, first


def _along(keys, curve_keys):
    """(each key's fraction of its strand's length, each strand's length), measured
    along the keys."""
    step = np.linalg.norm(np.diff(keys, axis=0), axis=1)
    run = np.concatenate([[0.0], np.cumsum(step)])
    start = run[np.repeat(curve_keys[:-1], np.diff(curve_keys))]
    lengths = run[curve_keys[1:] - 1] - run[curve_keys[:-1]]
    total = np.repeat(lengths, np.diff(curve_keys))
    along = np.divide(run - start, total, out=np.zeros_like(run), where=total > 0)
    return along, lengths


def pack_curves(curves: list, first_prim: int):
    """The strands of a scene as the kernels read them (engine.kernels.curve_hit):
    every object's control points one after the other, each segment's first control
    point, what the Hair Info node reads of it (its keys' intercepts, its strand's
    length and Random) and the global ids the segments take (first_prim on)."""
    from .kernels.curve_hit import PackedCurves, strand_randoms
    points, first, info, base = [], [], [], 0
    for c in curves:
        rows, f = c.control_points()
        points.append(rows)
        first.append(f + base)
        base += len(rows)
        lo = int(c.strand_index.min()) if c.curve_count else 0
        span = np.empty(int(c.strand_index.max()) + 1 - lo if c.curve_count else 0)
        strand_randoms(lo, span)
        rand = span[c.strand_index - lo]
        k = c.segment_key
        info.append(np.stack([c.intercepts[k], c.intercepts[k + 1],
                              c.lengths[c.segment_curve], rand[c.segment_curve]], axis=1))
    count = sum(len(f) for f in first)
    return PackedCurves(np.array([first_prim, first_prim + count], np.int64),
                        np.concatenate(points) if points else np.zeros((0, 4)),
                        np.concatenate(first).astype(np.int64) if first
                        else np.zeros(0, np.int64),
                        np.concatenate(info) if info else np.zeros((0, 4)))
