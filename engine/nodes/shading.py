"""The kernels' side of shader programs: run a hit's material program and read its
outputs into the Principled parameter row, emission and alpha.

geometry is the compiled path tracer's triangle tuple; its fields 8 to 12 are each
triangle's object (int32, empty when no mesh carries ObjectInfo), the object table
(context.O_* rows), the corner tangents and the corner colours ((T, 3, 4) float32 each,
empty without), and the packed render camera (engine.kernels.camera_rays.pack_camera;
empty without)."""
from __future__ import annotations

import math

import numpy as np

from ..kernels.bsdf import principled as bsdf
from ..kernels.jit import kernel
from ..kernels.textures import (I_TEXTURE, INPUTS, PLAIN, TEX_ALPHA, TEX_EMISSION,
                                textured_value)
from ..kernels.curve_hit import strand_info
from ..kernels.frame import to_local
from .context import (H_FLAT_FACE, H_HAIR_INTERCEPT, H_HAIR_IS_STRAND, H_HAIR_LENGTH,
                      H_HAIR_RANDOM, H_HAIR_TANGENT_NORMAL, H_HAIR_THICKNESS, H_MAP_NORMAL,
                      fill, set_undisplaced)
from .differentials import fill_differentials
from .interpreter import reads_differentials, run
from .tangent_frame import object_frame
from .pack import MIX, OUTS

OUT_BASE, OUT_METALLIC, OUT_ROUGHNESS, OUT_EMISSION, OUT_ALPHA, OUT_NORMAL, OUT_MIX = range(7)
OUT_VOL_SA, OUT_VOL_SS, OUT_VOL_EM = 7, 8, 9      # engine.kernels.medium_density
OUT_HAIR_COLOR, OUT_HAIR_MELANIN = 10, 11          # a Principled Hair's (hair_chiang.py)
OUT_SURFACE_NORMAL = 12                             # Cycles' sd->N, where set (surface_normal)
OUT_TRANSLUCENT = 13                                # a Translucent BSDF's colour (layers.py)
OUT_TANGENT, OUT_ANISO_ROT = 14, 15                 # anisotropic reflection (anisotropic.py)
OUT_COAT_NORMAL = 16                                # the Principled's Coat Normal


@kernel(allocates=False)
def program_hit(T, geometry, m, prim, inst, bu, bv, uu, vv, px, py, pz, gx, gy, gz, nx, ny,
                nz, dx, dy, dz, front, ray, depth, length, hit, regs):
    """Fill the hit row of a hit on triangle prim (material m) at barycentrics (bu, bv)
    and run m's program. inst: the instance's object row (engine.instancing), -1 for a
    mesh that is not instanced. A displaced triangle (geometry[14], its corners'
    undisplaced object-space points; NaN: not displaced) reads Generated coordinates there. The caller has written the row's path fields
    (context.path_fields; zeros: a path of no bounces and a ray without footprint); the
    differentials are filled only for a program that reads them (a Bump's)."""
    tri_object, objects, corner_tangents = geometry[8], geometry[9], geometry[10]
    obj = inst if inst >= 0 else (tri_object[prim] if tri_object.shape[0] > 0 else -1)
    tx = ty = tz = ts = mx = my = mz = 0.0
    if corner_tangents.shape[0] > 0:
        tx, ty, tz, ts, mx, my, mz = object_frame(corner_tangents, geometry[4], objects, prim,
                                                  inst, obj, bu, bv)
    cr = cg = cb = ca = 0.0
    colors = geometry[11]
    if colors.shape[0] > 0:
        b0 = 1.0 - bu - bv
        cr = b0 * colors[prim, 0, 0] + bu * colors[prim, 1, 0] + bv * colors[prim, 2, 0]
        cg = b0 * colors[prim, 0, 1] + bu * colors[prim, 1, 1] + bv * colors[prim, 2, 1]
        cb = b0 * colors[prim, 0, 2] + bu * colors[prim, 1, 2] + bv * colors[prim, 2, 2]
        ca = b0 * colors[prim, 0, 3] + bu * colors[prim, 1, 3] + bv * colors[prim, 2, 3]
    camera = geometry[12]
    fill(hit, px, py, pz, nx, ny, nz, gx, gy, gz, dx, dy, dz, uu, vv, front, ray, depth,
         length, objects, obj, camera, tx, ty, tz, ts, cr, cg, cb, ca)
    (hit[H_HAIR_IS_STRAND], hit[H_HAIR_INTERCEPT], hit[H_HAIR_LENGTH], hit[H_HAIR_THICKNESS],
     hit[H_HAIR_RANDOM], hit[H_HAIR_TANGENT_NORMAL], hit[H_HAIR_TANGENT_NORMAL + 1],
     hit[H_HAIR_TANGENT_NORMAL + 2]) = strand_info(geometry[15], prim, bu, -dx, -dy, -dz)
    hit[H_MAP_NORMAL], hit[H_MAP_NORMAL + 1], hit[H_MAP_NORMAL + 2] = mx, my, mz
    flat_faces = geometry[16]
    hit[H_FLAT_FACE] = 1.0 if flat_faces.shape[0] > 0 and flat_faces[prim] != 0 else 0.0
    undisplaced = geometry[14]
    if undisplaced.shape[0] > 0 and not math.isnan(undisplaced[prim, 0, 0]):
        b0 = 1.0 - bu - bv
        u = undisplaced
        set_undisplaced(hit, objects, obj,
                        b0 * u[prim, 0, 0] + bu * u[prim, 1, 0] + bv * u[prim, 2, 0],
                        b0 * u[prim, 0, 1] + bu * u[prim, 1, 1] + bv * u[prim, 2, 1],
                        b0 * u[prim, 0, 2] + bu * u[prim, 1, 2] + bv * u[prim, 2, 2])
    if reads_differentials(T, m):
        fill_differentials(hit, geometry, prim, obj, inst >= 0, camera)
    run(T, m, hit, regs)


@kernel(allocates=False)
def apply_rows(T, m, regs, row, P_BASE, P_METALLIC, P_ROUGHNESS):
    """Write the program's base colour, metallic and roughness into the parameter row."""
    outs = T[OUTS]
    r = outs[m, OUT_BASE]
    if r >= 0:
        row[P_BASE] = max(regs[r], 0.0)
        row[P_BASE + 1] = max(regs[r + 1], 0.0)
        row[P_BASE + 2] = max(regs[r + 2], 0.0)
    r = outs[m, OUT_METALLIC]
    if r >= 0:
        row[P_METALLIC] = min(max(regs[r], 0.0), 1.0)
    r = outs[m, OUT_ROUGHNESS]
    if r >= 0:
        row[P_ROUGHNESS] = min(max(regs[r], 0.0), 1.0)


@kernel(allocates=False)
def apply_hair(T, m, regs, row, P_COLOR, P_MELANIN):
    """Write the program's Principled Hair colour and Melanin into the parameter row."""
    outs = T[OUTS]
    r = outs[m, OUT_HAIR_COLOR]
    if r >= 0:
        row[P_COLOR] = regs[r]
        row[P_COLOR + 1] = regs[r + 1]
        row[P_COLOR + 2] = regs[r + 2]
    r = outs[m, OUT_HAIR_MELANIN]
    if r >= 0:
        row[P_MELANIN] = regs[r]


@kernel(allocates=False)
def apply_translucent(T, m, regs, row, P_TRANSLUCENT):
    """Write the program's Translucent BSDF colour (weight included) into the row."""
    r = T[OUTS][m, OUT_TRANSLUCENT]
    if r >= 0:
        row[P_TRANSLUCENT] = max(regs[r], 0.0)
        row[P_TRANSLUCENT + 1] = max(regs[r + 1], 0.0)
        row[P_TRANSLUCENT + 2] = max(regs[r + 2], 0.0)


@kernel(allocates=False)
def apply_anisotropy(T, m, regs, row, P_TANGENT, P_ANISO_ROT):
    """Write the program's tangent (world space) and Rotation into the row."""
    outs = T[OUTS]
    r = outs[m, OUT_TANGENT]
    if r >= 0:
        row[P_TANGENT] = regs[r]
        row[P_TANGENT + 1] = regs[r + 1]
        row[P_TANGENT + 2] = regs[r + 2]
    r = outs[m, OUT_ANISO_ROT]
    if r >= 0:
        row[P_ANISO_ROT] = regs[r]


@kernel(allocates=False)
def coat_normal(T, m, regs, sx, sy, sz):
    """The coat's normal: the program's Coat Normal (unit), else s, the surface's own
    shading normal (Cycles' sd->N, which an unlinked Coat Normal reads)."""
    r = T[OUTS][m, OUT_COAT_NORMAL]
    if r < 0:
        return sx, sy, sz
    x, y, z = regs[r], regs[r + 1], regs[r + 2]
    ln = math.sqrt(x * x + y * y + z * z)
    if not (ln > 0.0 and ln < math.inf):
        return sx, sy, sz
    return x / ln, y / ln, z / ln


@kernel(allocates=False)
def program_emission(T, m, regs, r, g, b):
    """The program's emission, or (r, g, b) when it does not drive it."""
    k = T[OUTS][m, OUT_EMISSION]
    if k < 0:
        return r, g, b
    return regs[k], regs[k + 1], regs[k + 2]


@kernel(allocates=False)
def may_emit(T, emission_table, m):
    """Whether a hit of material m can find emission: its program drives it, a texture
    does, or its constant emission is not black."""
    if T[OUTS][m, OUT_EMISSION] >= 0 or T[INPUTS][m, TEX_EMISSION, I_TEXTURE] >= 0:
        return True
    return (emission_table[m, 0] != 0.0 or emission_table[m, 1] != 0.0
            or emission_table[m, 2] != 0.0)


@kernel(allocates=False)
def program_alpha(T, m, regs, a):
    """The program's alpha clipped to [0, 1], or a when it does not drive it."""
    k = T[OUTS][m, OUT_ALPHA]
    if k < 0:
        return a
    return min(max(regs[k], 0.0), 1.0)


@kernel(allocates=False)
def valid_reflection_normal(gx, gy, gz, ix, iy, iz, x, y, z):
    """Cycles' ensure_valid_specular_reflection: the normal n (unit) tilted towards the
    geometric normal g (facing the viewer I) just enough that I mirrored about it leaves
    above the surface (at least min(0.9 I.g, 0.01)); n itself when it already does."""
    ndi = x * ix + y * iy + z * iz
    iz_ = ix * gx + iy * gy + iz * gz
    rz = 2.0 * ndi * (x * gx + y * gy + z * gz) - iz_
    threshold = min(0.9 * iz_, 0.01)
    if rz >= threshold:
        return x, y, z
    ndg = x * gx + y * gy + z * gz
    ax, ay, az = x - ndg * gx, y - ndg * gy, z - ndg * gz
    ln = math.sqrt(ax * ax + ay * ay + az * az)
    if ln > 0.0:
        ax, ay, az = ax / ln, ay / ln, az / ln
    else:
        ax, ay, az = x, y, z
    i_x = ix * ax + iy * ay + iz * az
    a = i_x * i_x + iz_ * iz_
    if not a > 0.0:
        return gx, gy, gz
    b = 2.0 * (a + iz_ * threshold)
    c = (threshold + iz_) ** 2
    root = math.sqrt(max(b * b - 4.0 * a * c, 0.0))
    nz2 = 0.25 * (b + root) / a if i_x < 0.0 else 0.25 * (b - root) / a
    nz2 = min(max(nz2, 0.0), 1.0)
    nx_, nz_ = math.sqrt(1.0 - nz2), math.sqrt(nz2)
    return nx_ * ax + nz_ * gx, nx_ * ay + nz_ * gy, nx_ * az + nz_ * gz


@kernel(allocates=False)
def program_normal(T, m, regs, nx, ny, nz, gx, gy, gz, ix, iy, iz, correct):
    """The program's shading normal (a Normal Map's or a Bump's), normalised, twice: as Cycles'
    Principled BSDF uses it for its specular lobes, made a valid specular reflector for
    the view direction I (valid_reflection_normal) when `correct` (the material's Bump
    Map Correction), then as its diffuse lobe uses it, unchanged. Both are n when the
    program does not set one."""
    x, y, z, ok = _unit_output(T, m, OUT_NORMAL, regs)
    if not ok:
        return nx, ny, nz, nx, ny, nz
    if not correct:
        return x, y, z, x, y, z
    vx, vy, vz = valid_reflection_normal(gx, gy, gz, ix, iy, iz, x, y, z)
    return vx, vy, vz, x, y, z


@kernel(allocates=False)
def _unit_output(T, m, out, regs):
    """Material m's program output `out` (a direction) normalised, and whether it has one
    (an output it does not set, or of zero or non-finite length, has none)."""
    k = T[OUTS][m, out]
    if k < 0:
        return 0.0, 0.0, 1.0, False
    x, y, z = regs[k], regs[k + 1], regs[k + 2]
    ln = math.sqrt(x * x + y * y + z * z)
    if not ln > 0.0 or not math.isfinite(ln):
        return 0.0, 0.0, 1.0, False
    return x / ln, y / ln, z / ln, True


@kernel(allocates=False)
def surface_normal(T, m, regs, rx, ry, rz):
    """Cycles' sd->N where material m's program sets it (its Material Output's
    Displacement as a bump, Cycles' Set Normal): the program's surface_normal output
    where a shader also has a Normal of its own (which its lobes use), else r, the
    program's normal as program_normal gives it raw. Bent lobes are shadowed against
    it, lights picked for it and shadow rays lifted by it."""
    x, y, z, ok = _unit_output(T, m, OUT_SURFACE_NORMAL, regs)
    if ok:
        return x, y, z
    return rx, ry, rz


@kernel(allocates=False)
def normal_rows(T, material, regs, ns, ng, incoming, correct):
    """`program_normal` (its specular normal) for hits given as arrays, for the NumPy
    reference: (n, 3). correct: each hit's Bump Map Correction."""
    out = np.empty_like(ns)
    for i in range(material.shape[0]):
        x, y, z, _, _, _ = program_normal(T, material[i], regs[i], ns[i, 0], ns[i, 1],
                                          ns[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                                          incoming[i, 0], incoming[i, 1], incoming[i, 2],
                                          correct[i])
        out[i, 0], out[i, 1], out[i, 2] = x, y, z
    return out


@kernel(allocates=False)
def bent_diffuse(state, wox, woy, woz, sx, sy, sz, rx, ry, rz, lx, ly, lz, ix, iy, iz,
                 soften):
    """The diffuse and sheen lobes' f x cos towards world direction l (i in the local
    frame) under the raw bent normal r (Cycles: Lambert, and its sheen, on the node's
    normal, times bump_shadowing against the surface's own shading normal s, softened
    when the material's Bump Map Correction is on), with the diffuse lobe's (direction-
    independent) value read from the BSDF set up on the specular frame, and the sheen's
    about r (principled.setup_about)."""
    cos_d = rx * lx + ry * ly + rz * lz
    if not cos_d > 0.0:
        return 0.0, 0.0, 0.0
    fr, fg, fb = bsdf.base_diffuse(state, wox, woy, woz)
    sr, sg, sb = bsdf.sheen_seen(state, woz, ix, iy, iz)
    k = cos_d * bump_shadowing(sx, sy, sz, rx, ry, rz, lx, ly, lz, soften)
    return (fr + sr) * k, (fg + sg) * k, (fb + sb) * k


@kernel(allocates=False)
def bent_translucent(state, sx, sy, sz, nx, ny, nz, lx, ly, lz, soften):
    """The translucent lobe's f x |cos| towards world direction l on the bent frame's
    normal n: Cycles puts its Translucent closure on the valid reflection normal, as it
    does the microfacet lobes, and evaluates it towards lights with a diffuse closure's
    bump shadowing against the surface's own shading normal s (its sampled directions
    carry none)."""
    cos_n = nx * lx + ny * ly + nz * lz
    tr, tg, tb = bsdf.translucent_seen(state, cos_n)
    if not max(tr, tg, tb) > 0.0:
        return 0.0, 0.0, 0.0
    k = -cos_n * bump_shadowing(sx, sy, sz, nx, ny, nz, lx, ly, lz, soften)
    return tr * k, tg * k, tb * k


@kernel(allocates=False)
def bent_diffuse_lobes(state, wox, woy, woz, sx, sy, sz, nx, ny, nz, rx, ry, rz, lx, ly, lz,
                       soften):
    """f x cos of the diffuse-kind lobes towards a light at world direction l on a bent
    frame (normal n, raw normal r, the surface's own s): `bent_diffuse` and
    `bent_translucent`."""
    ix, iy, iz = to_local(lx, ly, lz, nx, ny, nz)
    dr, dg, db = bent_diffuse(state, wox, woy, woz, sx, sy, sz, rx, ry, rz, lx, ly, lz, ix,
                              iy, iz, soften)
    tr, tg, tb = bent_translucent(state, sx, sy, sz, nx, ny, nz, lx, ly, lz, soften)
    return dr + tr, dg + tg, db + tb


@kernel(allocates=False)
def bump_rejects(sx, sy, sz, nx, ny, nz, lx, ly, lz):
    """Cycles 5.0's test of a lobe on a normal n that is not the surface's own shading
    normal s: light from direction l is refused when l and n lie on opposite sides of
    the surface s describes in a way the lobe cannot bridge, i.e. when
    (s.l)(s.n)(n.l) < 0 (a reflection reaching under s, or a refraction staying above).
    It applies to every lobe Cycles evaluates towards a light, and to the directions its
    diffuse lobes sample."""
    s_l = sx * lx + sy * ly + sz * lz
    s_n = sx * nx + sy * ny + sz * nz
    n_l = nx * lx + ny * ly + nz * lz
    return s_l * s_n * n_l < 0.0


@kernel(allocates=False)
def bump_shadowing(sx, sy, sz, nx, ny, nz, lx, ly, lz, soften):
    """Cycles 5.0's bump_shadowing_term for a diffuse lobe on a normal n bent away from the
    surface's shading normal s (Conty Estevez, Lecocq and Stein, "A Microfacet-Based
    Shadowing Function to Solve the Bump Terminator Problem"): 0 where bump_rejects,
    else the GGX shadowing G1 of the light's angle to s, for a roughness that grows with
    the bend: alpha^2 = min(tan^2(s, n) / 8, 1). 1 when n is s, and (where not refused)
    when not `soften` (Bump Map Correction off)."""
    if sx == nx and sy == ny and sz == nz:
        return 1.0
    if bump_rejects(sx, sy, sz, nx, ny, nz, lx, ly, lz):
        return 0.0
    if not soften:
        return 1.0
    cos_i = abs(sx * lx + sy * ly + sz * lz)
    cos_d = abs(sx * nx + sy * ny + sz * nz)
    if cos_d >= 1.0 or cos_i >= 1.0:
        return 1.0
    if cos_i < 1e-6:
        return 0.0
    alpha2 = min(max(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0), 1.0)
    tan2_i = max(1.0 / (cos_i * cos_i) - 1.0, 0.0)
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * tan2_i))


@kernel(allocates=False)
def mix_factor(T, m, regs):
    """Material m's Mix Shader Fac at this hit, clamped to [0, 1] (0.5 where no program
    output drives it), as pick_closure reads it."""
    k = T[OUTS][m, OUT_MIX]
    return min(max(regs[k], 0.0), 1.0) if k >= 0 else 0.5


@kernel(allocates=False)
def coverage(T, m, regs, u, v):
    """Material m's alpha at a hit whose program ran into regs (its opaque share: 1 - the
    weight of its transparent closure): the program's Alpha, else its texture's or its
    constant, clipped to [0, 1]."""
    if T[INPUTS][m, TEX_ALPHA, I_TEXTURE] >= 0:
        a = textured_value(T, m, TEX_ALPHA, u, v)[0]
    else:
        a = T[PLAIN][m, TEX_ALPHA, 0]
    return program_alpha(T, m, regs, min(max(a, 0.0), 1.0))


@kernel(allocates=False)
def pick_closure(T, m, regs, u, uu, vv):
    """Cycles' Mix Shader sums its two shaders weighted 1 - Fac and Fac. The transparent
    part of that sum is taken before shading, by the transparency passes
    (engine.kernels.transparency); what is shaded is its opaque part, (1 - Fac) alpha0
    shader0 + Fac alpha1 shader1 (alpha: each shader's `coverage` at the hit, (uu, vv)
    its UV). DRT picks one shader per hit with those weights (an unbiased estimate of the
    sum: the picked shader is the hit's BSDF for its light sample and its next
    direction). Nested mixes pick in turn. Returns (the material shaded, u rescaled to
    [0, 1) for the lobe choice)."""
    children = T[MIX]
    outs = T[OUTS]
    for _ in range(32):
        if m < 0 or m >= children.shape[0] or children[m, 0] < 0:
            break
        k = outs[m, OUT_MIX]
        f = min(max(regs[k], 0.0), 1.0) if k >= 0 else 0.5
        w0 = (1.0 - f) * coverage(T, children[m, 0], regs, uu, vv)
        w1 = f * coverage(T, children[m, 1], regs, uu, vv)
        if w0 + w1 > 0.0:
            f = w1 / (w0 + w1)
        if u < 1.0 - f:
            u = u / max(1.0 - f, 1e-300)
            m = children[m, 0]
        else:
            u = (u - (1.0 - f)) / max(f, 1e-300)
            m = children[m, 1]
        u = min(max(u, 0.0), 0.9999999999999999)
    return m, u
