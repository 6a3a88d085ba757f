"""Light a path's ray finds without a surface to shade: the area and sphere lamps it
passes before what it hits (the ray passes through lamps, as in Cycles), and the world
and sun discs when it escapes. Each is weighted by multiple importance sampling against
the light sample that could have found it (path_weights.hit_weight), and added through
the light tally (light_tally.found) under the path's clamp."""
from __future__ import annotations

from . import light_tally as tl
from . import lights as lt
from .frame import length
from .jit import kernel
from .path_weights import hit_weight, previous_receiver
from .volume import passed


@kernel(allocates=False)
def lamps_in_front(tally, lights, paths, p, b, ox, oy, oz, dx, dy, dz, t_end, medium, has_vol,
                   mode, br, bg, bb, clamp):
    """The lamps path p's ray (o + t d, throughput b before any medium, after b bounces)
    meets before t_end. medium: (vmode, sigma_t RGB, the distance sampling's channel
    weights RGB, a heterogeneous segment's factor RGB) of the segment it crosses
    (volume.passed; vmode 3: the heterogeneous factor, taken at the nearest lamp);
    has_vol: the scene has media (the lamp's distance is then from the path's last
    vertex, as the ray may start past volume boundaries)."""
    vmode, str_, stg, stb, wcr, wcg, wcb, mfr, mfg, mfb = medium
    prev_pos, time = paths.prev_pos, paths.time[p]
    for k in range(lt.n_lamps(lights)):
        t_l, lr, lg, lb = lt.lamp_hit(lights, k, ox, oy, oz, dx, dy, dz, paths.ray_bits[p],
                                      time)
        if not t_l < t_end:
            continue
        if vmode == 3:
            fr, fg, fb = mfr, mfg, mfb
        else:
            fr, fg, fb = passed(vmode, str_, stg, stb, wcr, wcg, wcb, t_l)
        if has_vol:
            t_l = length(ox + dx * t_l - prev_pos[p, 0], oy + dy * t_l - prev_pos[p, 1],
                         oz + dz * t_l - prev_pos[p, 2])
        lpdf = lt.lamp_pdf(lights, k, previous_receiver(prev_pos, p), dx, dy, dz, t_l, time)
        w = hit_weight(mode, paths.prev_pdf[p], lpdf)
        tl.found(tally, p, b, br * fr * lr * w, bg * fg * lg * w, bb * fb * lb * w, clamp,
                 False, tl.entry_group(tally, k))


@kernel(allocates=False)
def escaped(tally, lights, world, paths, p, b, dx, dy, dz, mode, br, bg, bb, clamp):
    """Path p's ray along d (throughput b, after b bounces) escaped: the world (an
    environment map's or the uniform `world` radiance) and the sun discs it sees. What a
    camera ray sees here, sun discs included, is the Environment pass; each source goes
    to its light group, with the clamp's factor of the whole."""
    recv = previous_receiver(paths.prev_pos, p)
    time, prev_pdf = paths.time[p], paths.prev_pdf[p]
    er, eg, eb, epdf = lt.world_escaped(lights, world, paths.ray_bits[p], dx, dy, dz, recv,
                                        time)
    w = hit_weight(mode, prev_pdf, epdf)
    er, eg, eb = er * w, eg * w, eb * w
    wr, wg, wb = er, eg, eb                   # the world's own part
    for s in range(lt.n_suns(lights)):
        sr, sg, sb, spdf = lt.sun_escaped(lights, s, dx, dy, dz, recv, time)
        w = hit_weight(mode, prev_pdf, spdf)
        er += sr * w
        eg += sg * w
        eb += sb * w
    world_only = wr == er and wg == eg and wb == eb
    kr, kg, kb = tl.found(tally, p, b, br * er, bg * eg, bb * eb, clamp, True,
                          tally.world_group[0] if world_only else -1)
    if tl.grouped(tally) and not world_only:
        tl.to_group(tally, p, tally.world_group[0], br * wr * kr, bg * wg * kg, bb * wb * kb)
        for s in range(lt.n_suns(lights)):
            sr, sg, sb, spdf = lt.sun_escaped(lights, s, dx, dy, dz, recv, time)
            w = hit_weight(mode, prev_pdf, spdf)
            tl.to_group(tally, p, tl.entry_group(tally, lt.sun_entry(lights, s)),
                        br * sr * w * kr, bg * sg * w * kg, bb * sb * w * kb)


@kernel(allocates=False)
def background(tally, lights, world, paths, p, dx, dy, dz, br, bg, bb):
    """A camera ray on a transparent film escaped (throughput b): no colour in Combined,
    but what it sees of the world and sun discs is the Environment pass and the light of
    their groups, as Cycles writes them (only when those are asked for)."""
    if not (tl.on(tally) or tl.grouped(tally)):
        return
    recv = previous_receiver(paths.prev_pos, p)
    time = paths.time[p]
    wr, wg, wb, _ = lt.world_escaped(lights, world, paths.ray_bits[p], dx, dy, dz, recv,
                                     time)
    tl.hidden(tally, p, br * wr, bg * wg, bb * wb, tally.world_group[0])
    for s in range(lt.n_suns(lights)):
        sr, sg, sb, _ = lt.sun_escaped(lights, s, dx, dy, dz, recv, time)
        tl.hidden(tally, p, br * sr, bg * sg, bb * sb,
                  tl.entry_group(tally, lt.sun_entry(lights, s)))
