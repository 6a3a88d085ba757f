"""Emissive triangles as lights: soft shadows and low noise from emissive meshes.

Every scene triangle whose material has an emission (radiance, colour x strength) of
positive luminance and whose area is positive becomes a light entry of
`engine.lights.LightSet`, unless its material's Emission Sampling (Material > Settings;
engine.Material.emission_sampling, as Cycles decides it: drt_addon/export/
emission_sampling.py) is None. Emission is two-sided, as Cycles' Emission closure:
`emissive_simple_eval` returns 1 when |Ng . wi| > 0 (intern/cycles/kernel/closure/
emissive.h), and next-event estimation samples both sides, or the one side the setting
names (Front: where the triangle's normal points; `sides`). A side or a triangle not
sampled is found by BSDF rays alone, with MIS weight 1 (its light pdf is 0 there), as in
Cycles (SD_MIS_FRONT, SD_MIS_BACK).

Selection (done by the LightSet, jointly with the lamps): with the light tree off,
triangle j is picked in proportion to its area, as Cycles does (engine.light_distribution);
the tree weighs it by its estimated power  P_j = luminance(L_j) x pi x A_j,  the power one
side emits: a point in front of a two-sided triangle only ever receives one side's light,
so this is the same estimate an equally bright one-sided area lamp gets.

Sampling (engine/kernels/lights/triangles.py) a point on triangle (v0, v1, v2) from u in
[0,1)^2 uses Heitz's low-distortion map (E. Heitz, "A Low-Distortion Map Between Triangle and Square", 2019):
    if u1 > u0: s = u0 / 2, t = u1 - s    else: t = u1 / 2, s = u0 - t
    q = v0 + s (v1 - v0) + t (v2 - v0)
which is piecewise linear with constant Jacobian, hence uniform in area (pdf 1/A), and
continuous (both branches agree on u0 = u1), so stratified u stay stratified on the
triangle. Converted to solid angle at p:  pdf = |q - p|^2 / (A |cos theta_q|),
cos theta_q = n . (q - p) / |q - p|  (either side, emission being two-sided).

A BSDF-sampled ray that hits an emissive triangle (global primitive id g, as Embree
reports it) is weighted by multiple importance sampling against that same pdf times the
triangle's pick probability: `entry_of(g)` maps g to its light entry.

Coincident copies are one light. A mesh duplicated in place (a Solidify of thickness 0, a
copy never moved, a text curve extruded twice) holds emissive triangles with the same
three corners and the same radiance. A shadow ray towards a point on one copy passes the
other (both lie at its far end), so sampling each copy as its own light would add the
light of every copy, while a BSDF ray sees one surface and one radiance. So copies share
one entry: the first copy is sampled, and a BSDF ray that hits any copy is weighted with
that entry's pdf. (Copies of different radiance stay apart: which one a ray sees is then
the tracer's choice, as in Cycles.)

Only static triangles are light entries. Emissive triangles of objects that move during
the shutter (engine.accel traces them apart, after the static ones) are not sampled:
BSDF-sampled rays still find them, with MIS weight 1 (their light pdf is 0), which is
unbiased, only noisier.
"""
from __future__ import annotations

import numpy as np

from .luminance import luminance


def _coincident_copies(v0, v1, v2, radiance):
    """(first, copy_of): the indices of the first of each set of triangles with the same
    corners (in any order) and radiance, ascending, and for every triangle the position
    of its set's first one in `first`."""
    if not len(v0):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    c = [v0 + 0.0, v1 + 0.0, v2 + 0.0]                        # + 0.0: -0.0 is 0.0
    for i, j in ((0, 1), (1, 2), (0, 1)):                     # a sorting network of 3
        a, b = c[i], c[j]
        swap = ((b[:, 0] < a[:, 0]) | ((b[:, 0] == a[:, 0]) & (
            (b[:, 1] < a[:, 1]) | ((b[:, 1] == a[:, 1]) & (b[:, 2] < a[:, 2])))))[:, None]
        c[i], c[j] = np.where(swap, b, a), np.where(swap, a, b)
    key = np.concatenate(c + [radiance], axis=1)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    rank = np.argsort(first, kind="stable")           # sets in the order of their first
    position = np.empty_like(rank)
    position[rank] = np.arange(len(rank))
    return first[rank], position[inverse.reshape(-1)]


# the sides of an emissive triangle that next-event estimation samples (`sides`)
FRONT, BACK = 1, 2
SIDES = {"NONE": 0, "FRONT": FRONT, "BACK": BACK, "FRONT_BACK": FRONT | BACK}


class EmissiveTriangles:
    def __init__(self, v0, v1, v2, radiance, prim_ids, n_prims_total: int, sides=None,
                 shaded=None):
        """sides: FRONT, BACK or both (the default) per triangle, the sides sampled.
        shaded: per triangle, 0, or its material's index + 1 where its emission varies
        over the surface: `radiance` is then an estimate (its average), and a light
        sample evaluates the material where it lands (engine.kernels.shaded_emitter)."""
        v0, v1, v2 = (np.asarray(v, dtype=np.float64).reshape(-1, 3) for v in (v0, v1, v2))
        radiance = np.asarray(radiance, dtype=np.float64).reshape(-1, 3)
        prim_ids = np.asarray(prim_ids, dtype=np.int64).reshape(-1)
        sides = (np.full(len(prim_ids), FRONT | BACK, np.int64) if sides is None
                 else np.asarray(sides, np.int64).reshape(-1))
        shaded = (np.zeros(len(prim_ids), np.int64) if shaded is None
                  else np.asarray(shaded, np.int64).reshape(-1))
        e1, e2 = v1 - v0, v2 - v0
        cr = np.cross(e1, e2)
        norm = np.linalg.norm(cr, axis=1)
        area = 0.5 * norm
        power = luminance(np.maximum(radiance, 0.0)) * np.pi * area
        keep = np.isfinite(power) & (power > 0) & (norm > 0) & (sides != 0)
        self.v0, self.e1, self.e2 = v0[keep], e1[keep], e2[keep]
        self.normal = cr[keep] / norm[keep, None]
        self.area = area[keep]
        self.radiance = radiance[keep]
        self.power = power[keep]
        self.prim = prim_ids[keep]
        self.sides = sides[keep]
        self.shaded = shaded[keep]
        # (copies sampled on other sides, or of other varying emissions, stay apart)
        first, copy_of = _coincident_copies(v0[keep], v1[keep], v2[keep],
                                              np.column_stack([self.radiance, self.sides,
                                                               self.shaded]))
        self.entry = np.full(max(int(n_prims_total), 1), -1, dtype=np.int64)
        self.entry[self.prim] = copy_of
        for name in ("v0", "e1", "e2", "normal", "area", "radiance", "power", "prim",
                     "sides", "shaded"):
            setattr(self, name, getattr(self, name)[first])

    @classmethod
    def from_scene(cls, scene, accel, emission=None, only=None,
                   shaded=None) -> "EmissiveTriangles":
        """The emissive triangles of `scene`, with the global ids of `accel`
        (engine.accel.Accelerator: static triangles first, ids 0..len(accel.triangles)-1).
        `emission`: (materials, 3) radiance table, by default the materials' `emission`;
        the renderer passes the one its integrator adds at hits, so both agree. `only`:
        a flag per global triangle, the ones that may be lights (None: all). `shaded`: a
        flag per material whose emission varies over the surface (`emission` then holds
        its average, an estimate)."""
        tri = accel.triangles
        if not len(tri) or not scene.materials:
            return cls(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                       np.zeros((0, 3)), np.zeros(0, np.int64), 0)
        if emission is None:
            emission = [tuple(m.emission[:3]) for m in scene.materials]
        emission = np.asarray(emission, dtype=np.float64).reshape(-1, 3)
        # Only the static triangles (the accelerator's first `static_count` ids) are
        # light-sampled: a moving emissive mesh is still seen, blurred, by camera and BSDF
        # rays (with MIS weight 1), just not sampled directly.
        # (getattr: an accelerator without motion support has all meshes, in scene order)
        # (instanced meshes, after the static ones, emit nothing: engine.instancing)
        ordered = list(getattr(accel, "ordered_meshes", scene.meshes))
        static_meshes = ordered[:getattr(accel, "static_meshes", len(ordered))]
        mat = np.concatenate([m.material_indices for m in static_meshes])
        emissive = np.nonzero((emission.max(axis=1) > 0)[mat])[0]
        if only is not None:
            emissive = emissive[np.asarray(only, bool)[emissive]]
        p = accel.positions
        t = tri[emissive]
        sides = np.full(len(emission), FRONT | BACK, np.int64)
        sides[:len(scene.materials)] = [
            SIDES.get(getattr(m, "emission_sampling", "FRONT_BACK"), FRONT | BACK)
            for m in scene.materials][:len(emission)]
        varies = np.zeros(len(emission), np.int64)
        if shaded is not None:
            flags = np.asarray(shaded, bool)[:len(emission)]
            varies[:len(flags)] = np.where(flags, np.arange(len(flags)) + 1, 0)
        return cls(p[t[:, 0]], p[t[:, 1]], p[t[:, 2]], emission[mat[emissive]], emissive,
                   len(tri), sides[mat[emissive]], varies[mat[emissive]])

    def __len__(self):
        return len(self.area)

    def entry_of(self, prim):
        """Light entry (0..len-1) of global triangle ids, -1 for non-lights and misses."""
        prim = np.asarray(prim, dtype=np.int64)
        ok = (prim >= 0) & (prim < len(self.entry))
        return np.where(ok, self.entry[np.where(ok, prim, 0)], -1)
