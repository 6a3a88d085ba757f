"""Next-event estimation at a surface vertex of the path tracer (path_vertex.shade's step
2): one light entry picked for the receiver (lights/tree.py), one point on it, the BSDF
evaluated towards it on the lobes the light is seen by, and one shadow ray queued with
the unoccluded contribution, weighted against BSDF sampling by multiple importance
sampling (path_weights.nee_weight). A light that casts no shadow adds its light at once.

The vertex is described by two records made in `shade`: the point (`SurfacePoint`)
and its shading frame (`ShadingFrame`: Cycles' normals at a hit, bent by a Normal Map
or a bump, or made a valid reflector on a smooth mesh)."""
from __future__ import annotations

from typing import NamedTuple

from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d, sample_2d
from . import light_tally as tl
from . import lights as lt
from . import ray_queues
from .bsdf import principled as bsdf
from .bsdf.state import S_WALTER
from .frame import dot, to_local
from .jit import kernel
from .pass_shares import NO_SHARES, light_shares
from .path_weights import DIFFUSE_BIT, GLOSSY_BIT, SHADOW_BIT, TRANSMISSION_BIT, nee_weight
from .terminator import shadow_origin
from .volume import V_HAS, stack_cross
from ..nodes.shading import bent_diffuse, bump_rejects


class SurfacePoint(NamedTuple):
    """Where a ray hit a triangle."""
    px: float               # the point
    py: float
    pz: float
    gx: float               # the geometric normal, facing the incoming ray
    gy: float
    gz: float
    scale: float            # the offset scale of its rays (surface.offset_origin)
    prim: int               # the triangle, its instance and barycentrics
    inst: int
    u: float
    v: float
    front: bool             # the ray met the triangle's front side
    material: int


class ShadingFrame(NamedTuple):
    """The normals the BSDF is shaded with at a point."""
    nx: float               # the shading frame's normal (lobes are local to it)
    ny: float
    nz: float
    rx: float               # a bent frame's raw normal (the diffuse lobe's)
    ry: float
    rz: float
    sx: float               # the surface's own normal, that bent lobes are shadowed
    sy: float               # against and shadow rays are lifted by (Cycles' sd->N)
    sz: float
    bent: bool              # a Normal Map or bump bent it
    correct: bool           # the material's bump correction


@kernel(allocates=False)
def next_event(cfg, paths, p, b, base, tally, lights, recv, state, wo, f, point, lobes,
               beta, geometry, vol, shadows, ns_out):
    """Path p's next-event estimate at `point` (SurfacePoint) with frame `f`
    (ShadingFrame) after b bounces: wo the view in the frame, state the BSDF set up
    there, recv the receiver the light is picked for, lobes (keep glossy, keep
    transmission, may diffuse, may glossy, may transmit: the lobes the BSDF may still
    sample, which its MIS weight counts), beta the throughput; base the bounce's first
    sampler dimension. Returns the shadow queue's new length."""
    kind, spp = cfg.sampler, cfg.spp
    pkey, index, time = paths.key, paths.index, paths.time[p]
    wox, woy, woz = wo
    keep_g, keep_t, ad, ag, at = lobes
    q = point
    br, bg, bb = beta
    nx, ny, nz = f.nx, f.ny, f.nz
    # (one light: nothing to pick, and no number drawn for it)
    u_pick = sample_1d(kind, pkey[p], spp, index[p], base + D.LIGHT_PICK) \
        if lt.n_entries(lights) > 1 else 0.0
    u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.LIGHT_POINT)
    k, wx, wy, wz, dist, lr, lg, lb, lpdf, delta, margin = lt.sample(
        lights, recv, u_pick, u1, u2, time)
    lx, ly, lz = to_local(wx, wy, wz, nx, ny, nz)
    # a uniform world, which Cycles never samples (its escaping rays find it):
    # refraction towards it on Walter's pairs, as those rays see it
    state[S_WALTER] = 1.0 if lt.is_uniform_world(lights, k) else 0.0
    seen = lt.entry_visibility(lights, k)
    see_d = (seen & DIFFUSE_BIT) != 0
    see_g = (seen & GLOSSY_BIT) != 0 and keep_g
    see_t = (seen & TRANSMISSION_BIT) != 0 and keep_t
    cosine = abs(lz)
    if f.bent:
        # a Normal Map's normal: specular lobes on its valid-reflection frame, the
        # diffuse lobe on the raw normal with bump shadowing (Cycles)
        fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, False, see_g, see_t)
        if bump_rejects(f.sx, f.sy, f.sz, nx, ny, nz, wx, wy, wz):
            cosine = 0.0
        fr, fg, fb = fr * cosine, fg * cosine, fb * cosine
        if see_d:
            dr, dg, db = bent_diffuse(state, wox, woy, woz, f.sx, f.sy, f.sz, f.rx, f.ry,
                                      f.rz, wx, wy, wz, f.correct)
            fr, fg, fb = fr + dr, fg + dg, fb + db
        cosine = 1.0
    else:
        fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, see_d, see_g, see_t)
    # as in Cycles, the lobes alone decide (on the shading normals): a light under the
    # triangle's own plane but above its smooth normal lights it, its shadow ray leaving
    # from the curved surface the normals describe
    if lpdf > 0.0 and max(lr, lg, lb) > 0.0 and max(fr, fg, fb) > 0.0:
        sox, soy, soz = shadow_origin(geometry[0], geometry[1], geometry[4], geometry[13],
                                      geometry[9], q.prim, q.inst, q.u, q.v, q.px,
                                      q.py, q.pz, q.gx, q.gy, q.gz, f.sx, f.sy, f.sz,
                                      q.scale, wx, wy, wz)
        sdx, sdy, sdz, far = ray_queues.towards(sox, soy, soz, q.px, q.py, q.pz, wx, wy,
                                                 wz, dist, margin, cfg.scene_radius)
        bpdf = bsdf.pdf_seen(state, wox, woy, woz, lx, ly, lz, ad, ag, at, see_d, see_g,
                             see_t)
        w = nee_weight(cfg.mis_mode, lpdf, bpdf, delta) / lpdf * cosine
        shares = NO_SHARES
        if b == 0 and tl.on(tally):
            shares = light_shares(state, wox, woy, woz, lx, ly, lz, see_d, see_g, see_t,
                                  f.bent, fr, fg, fb, f.sx, f.sy, f.sz, f.rx, f.ry, f.rz,
                                  wx, wy, wz, f.correct)
        group = tl.entry_group(tally, k)
        if not seen & SHADOW_BIT:          # a light casting no shadow: no shadow ray
            tl.lit(tally, p, b, br * fr * lr * w, bg * fg * lg * w, bb * fb * lb * w,
                   cfg.clamp_direct if b == 0 else cfg.clamp_indirect, shares, group)
        else:
            ns_out = ray_queues.push(shadows, ns_out, p, b, sox, soy, soz, sdx, sdy, sdz,
                                     far, br * fr * lr * w, bg * fg * lg * w,
                                     bb * fb * lb * w, paths.stacks)
            tl.queued(tally, ns_out - 1, p, b, shares, group)
            m = q.material
            if (vol.shape[0] > 0 and vol[m, V_HAS] != 0.0
                    and dot(wx, wy, wz, q.gx, q.gy, q.gz) < 0.0):
                # towards a light through the surface: the shadow ray enters or leaves
                # the material's volume there, as the refracted path does
                stack_cross(shadows.stack, ns_out - 1, m, q.front)
    state[S_WALTER] = 0.0
    return ns_out
