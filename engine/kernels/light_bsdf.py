"""What a surface's BSDF gives a light sample (next-event estimation, path_vertex):
f(wo, wi) and |cos| of the lobes of the kinds the light is seen by.

A Normal Map's bent normal: the specular lobes on its valid-reflection frame, the diffuse
lobe on the raw normal with bump shadowing (Cycles' bent diffuse), the translucent one on
the frame with bump shadowing; a direction the bump rejects has no cosine."""
from __future__ import annotations

from .bsdf import principled as bsdf
from .jit import kernel
from ..nodes.shading import bent_diffuse_lobes, bump_rejects


@kernel(allocates=False)
def lit_bsdf(state, bent, wox, woy, woz, lx, ly, lz, see_d, see_g, see_t, s0x, s0y, s0z,
             nx, ny, nz, rx, ry, rz, wx, wy, wz, correct):
    """(f, the cosine that multiplies it) for the lobes seen (see_d diffuse, see_g glossy,
    see_t transmission) toward the light at local direction l (world w): with a bent
    normal f includes the cosine and the second value is 1. s0: the surface's own
    normal, n the shading frame's, r the raw bent normal."""
    cosine = abs(lz)
    if not bent:
        fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, see_d, see_g, see_t)
        return fr, fg, fb, cosine
    fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, False, see_g, see_t)
    if bump_rejects(s0x, s0y, s0z, nx, ny, nz, wx, wy, wz):
        cosine = 0.0
    fr, fg, fb = fr * cosine, fg * cosine, fb * cosine
    if see_d:
        dr, dg, db = bent_diffuse_lobes(state, wox, woy, woz, s0x, s0y, s0z, nx, ny, nz, rx,
                                        ry, rz, wx, wy, wz, correct)
        fr, fg, fb = fr + dr, fg + dg, fb + db
    return fr, fg, fb, 1.0
