"""What the vertex kernels (path_vertex.shade, whitted_vertex.shade_whitted) do at a
surface before they shade it: run the material's shader program (its outputs, the closure
a Mix Shader picks, the normal it bends), read the emission, and fill the hit's material
row. `programs` is None in a scene without shader programs (engine.nodes.shading), and
Numba then compiles these without that code."""
from __future__ import annotations

from .bsdf.layered_emission import LAYERS, TINT, dimmed
from .bsdf.params import (P_ANISO_KIND, P_ANISO_ROT, P_BASE, P_BUMP_CORRECTION,
                          P_CHIANG_COLOR, P_CHIANG_MELANIN, P_COAT_N, P_COAT_WEIGHT,
                          P_EMISSION_DIM, P_HAIR, P_LAYERS, P_METALLIC, P_ROUGHNESS,
                          P_TANGENT, P_TRANSLUCENT)
from .frame import to_local
from .jit import kernel
from .textures import apply_to_row, emission_at
from ..nodes.context import path_fields
from ..nodes.differentials import cone_at
from ..nodes.pack import OUTS
from ..nodes.shading import (OUT_COAT_NORMAL, apply_anisotropy, apply_hair, apply_rows,
                             apply_translucent, coat_normal, pick_closure,
                             valid_reflection_normal,
                             program_emission, program_hit, program_normal)


@kernel(allocates=False)
def run_program(programs, params, geometry, counts, path_info, p, m, prim, inst, hu, hv, uu, vv,
                px, py, pz, gx, gy, gz, nx, ny, nz, dx, dy, dz, front, ray_bit, b, t_geom,
                hit_row, regs, u_lobe):
    """Run material m's program at the hit of path p (what its Light Path and geometry
    nodes read: the path's counts, its ray cone at t_geom, the hit), leaving its outputs
    in regs (inst: the hit's instance, engine.instancing). Returns (the material shaded (a Mix Shader's pick with u_lobe), u_lobe
    rescaled, the shading normal s, the raw bent normal r, bent: s or r differ from n,
    correct: the material's Bump Map Correction)."""
    path_fields(hit_row, counts, path_info[0], p, cone_at(path_info[1], p, t_geom))
    program_hit(programs, geometry, m, prim, inst, hu, hv, uu, vv, px, py, pz, gx, gy, gz, nx, ny,
                nz, dx, dy, dz, front, ray_bit, b, t_geom, hit_row, regs)
    ms, u_lobe = pick_closure(programs, m, regs, u_lobe, uu, vv)
    correct = params[ms, P_BUMP_CORRECTION] != 0.0
    sx, sy, sz, rx, ry, rz = program_normal(programs, ms, regs, nx, ny, nz, gx, gy, gz, -dx,
                                            -dy, -dz, correct)
    bent = sx != nx or sy != ny or sz != nz or rx != nx or ry != ny or rz != nz
    return ms, u_lobe, sx, sy, sz, rx, ry, rz, bent, correct


@kernel(allocates=False)
def surface_emission(programs, textures, emission, params, dims, m, uu, vv, regs,
                     programmed, cos, layered):
    """Material m's emitted radiance at the hit: its (textured) emission, or what its
    program (run by `run_program` when `programmed`) says, as its coat and sheen dim it
    seen at cosine cos to the surface's normal (bsdf.layered_emission; dims: the light
    table's L[EMIT_DIM]): by their albedos and the coat's tint where `layered`, else by
    the tint alone (on a path whose budget is spent)."""
    er, eg, eb = emission_at(textures, emission, m, uu, vv)
    if programs is not None and programmed:
        er, eg, eb = program_emission(programs, m, regs, er, eg, eb)
    row = params[m, P_EMISSION_DIM]
    if row >= 0.0 and (er != 0.0 or eg != 0.0 or eb != 0.0):
        er, eg, eb = dimmed(dims, int(row), LAYERS if layered else TINT, cos, er, eg,
                            eb)
    return er, eg, eb


@kernel(allocates=False)
def material_row(params, textures, programs, ms, uu, vv, regs, programmed, row):
    """Fill `row` with material ms's parameters at the hit: its plain row, its textures
    at (uu, vv), its program's outputs."""
    for c in range(row.shape[0]):
        row[c] = params[ms, c]
    if textures[1].shape[0] > 0:
        apply_to_row(textures, ms, uu, vv, row, P_BASE, P_METALLIC, P_ROUGHNESS)
    if programs is not None and programmed:
        apply_rows(programs, ms, regs, row, P_BASE, P_METALLIC, P_ROUGHNESS)
        if row[P_LAYERS] != 0.0:     # a Translucent BSDF's colour, per hit
            apply_translucent(programs, ms, regs, row, P_TRANSLUCENT)
        if row[P_HAIR] != 0.0:       # a Principled Hair's colour and Melanin, per hit
            apply_hair(programs, ms, regs, row, P_CHIANG_COLOR, P_CHIANG_MELANIN)
        if row[P_ANISO_KIND] != 0.0:  # an anisotropic lobe's tangent (world) and Rotation
            apply_anisotropy(programs, ms, regs, row, P_TANGENT, P_ANISO_ROT)


@kernel(allocates=False)
def coat_frame(programs, ms, regs, row, bent, s0x, s0y, s0z, gx, gy, gz, ix, iy, iz, nx, ny,
               nz):
    """Where the program bent the shading frame to n or gives a Coat Normal, write
    row[P_COAT_N]: the coat's own normal (its Coat Normal, or the surface's s0, Cycles'
    sd->N), made a valid reflector for the view I as Cycles' coat closure makes it, local
    to n's frame. Nothing without a coat."""
    if row[P_LAYERS] == 0.0 or not row[P_COAT_WEIGHT] > 0.0:
        return
    if not bent and programs[OUTS][ms, OUT_COAT_NORMAL] < 0:
        return
    cx, cy, cz = coat_normal(programs, ms, regs, s0x, s0y, s0z)
    cx, cy, cz = valid_reflection_normal(gx, gy, gz, ix, iy, iz, cx, cy, cz)
    row[P_COAT_N], row[P_COAT_N + 1], row[P_COAT_N + 2] = to_local(cx, cy, cz, nx, ny, nz)
