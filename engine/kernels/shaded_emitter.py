"""Emissive triangles whose emission varies over the surface (an image, a node program,
a Mix Shader's per-hit Fac, a Layer Weight) as lights, evaluated where they are sampled.

Cycles light-samples every emissive mesh and evaluates its shader at the sampled point
(light_sample_shader_eval: the shader run for a ray of no visibility kind,
PATH_RAY_EMISSION, that arrives from the receiver). DRT does the same: such a triangle is
a light entry whose radiance (L[TRI_RADIANCE]) is only an estimate, the material's
average emission, which the light tree and the pick probabilities weigh; its entry is
marked EMISSION_SHADED (a bit of L[TRI_VISIBILITY]), and a vertex that samples it runs the
material's program at the sampled point here (`radiance`) for the radiance it carries.
Before, such surfaces were found by BSDF rays alone (MIS weight 1): unbiased, but a neon
tube lighting a wall was a handful of fireflies.

The point's barycentrics come from its position on the entry's triangle (the sampler
returns the direction and distance), the hit row from the triangle as a ray along the
sampled direction would find it (surface.rebuild_at_time): its side, normals, UV,
object. The program writes into buffers of its own (`EmitterShading.hit_row`, `regs`),
since the receiver's program outputs are still in use. A scene without such emitters
passes None and compiles none of this (principle 3)."""
from __future__ import annotations

from typing import NamedTuple

from .jit import kernel
from .lights.pack import EMISSION_SHADED, EMIT_DIM, TRI_E1, TRI_E2, TRI_V0, TRI_VISIBILITY
from .lights.triangles import triangle_entry
from .surface import hit_uv, rebuild_at_time
from .surface_hit import surface_emission
from ..nodes.context import path_fields
from ..nodes.differentials import cone_at
from ..nodes.interpreter import has_program
from ..nodes.shading import program_hit


class EmitterShading(NamedTuple):
    """What `radiance` reads: the shading tables (None: no programs, only textures), the
    material rows, the geometry, the textures, the emission table, and the buffers the
    emitter's program writes."""
    programs: object
    params: object
    geometry: object
    textures: object
    emission: object
    hit_row: object
    regs: object


@kernel(allocates=False)
def barycentrics(L, j, qx, qy, qz):
    """(u, v) of point q on light entry j's triangle v0 + u e1 + v e2 (least squares:
    q lies on it up to rounding), clamped into the triangle."""
    v0, e1, e2 = L[TRI_V0], L[TRI_E1], L[TRI_E2]
    rx, ry, rz = qx - v0[j, 0], qy - v0[j, 1], qz - v0[j, 2]
    a = e1[j, 0] * e1[j, 0] + e1[j, 1] * e1[j, 1] + e1[j, 2] * e1[j, 2]
    b = e1[j, 0] * e2[j, 0] + e1[j, 1] * e2[j, 1] + e1[j, 2] * e2[j, 2]
    c = e2[j, 0] * e2[j, 0] + e2[j, 1] * e2[j, 1] + e2[j, 2] * e2[j, 2]
    d = rx * e1[j, 0] + ry * e1[j, 1] + rz * e1[j, 2]
    e = rx * e2[j, 0] + ry * e2[j, 1] + rz * e2[j, 2]
    det = a * c - b * b
    if not det > 0.0:
        return 1.0 / 3.0, 1.0 / 3.0
    u = min(max((c * d - b * e) / det, 0.0), 1.0)
    v = min(max((a * e - b * d) / det, 0.0), 1.0 - u)
    return u, v


@kernel(allocates=False)
def radiance(es, L, prim, counts, path_info, p, b, px, py, pz, wx, wy, wz, dist, time,
             lr, lg, lb):
    """The radiance a light sample of triangle prim (-1: a lamp or the world) carries
    from the point it sampled, at distance dist along the unit direction w from the
    receiver p (path p at bounce b: what its Light Path nodes read): (lr, lg, lb), the
    sample's own, unless the triangle's entry is EMISSION_SHADED, whose material then says it at
    that point. es: an EmitterShading, or None in a scene without such emitters."""
    if es is None:
        return lr, lg, lb
    j = triangle_entry(L, prim)
    if j < 0 or (L[TRI_VISIBILITY][j] & EMISSION_SHADED) == 0:
        return lr, lg, lb
    geometry = es.geometry
    qx, qy, qz = px + wx * dist, py + wy * dist, pz + wz * dist
    u, v = barycentrics(L, j, qx, qy, qz)
    hx, hy, hz, gx, gy, gz, nx, ny, nz, front, _ = rebuild_at_time(geometry, prim, -1, u, v,
                                                                   wx, wy, wz, time)
    m = geometry[3][prim]
    uu, vv = hit_uv(geometry[6], prim, u, v)
    programs = es.programs
    programmed = programs is not None and has_program(programs, m)
    if programmed:
        path_fields(es.hit_row, counts, path_info[0], p, cone_at(path_info[1], p, dist))
        program_hit(programs, geometry, m, prim, -1, u, v, uu, vv, hx, hy, hz, gx, gy, gz,
                    nx, ny, nz, wx, wy, wz, front, 0, b, dist, es.hit_row, es.regs)
    return surface_emission(programs, es.textures, es.emission, es.params, L[EMIT_DIM], m,
                            uu, vv, es.regs, programmed, wx * nx + wy * ny + wz * nz, False)
