"""Where a path's light goes: the Combined sum, and when a render asks for them, Cycles'
light passes and light groups (its film/light_passes.h, read for definitions).

Every contribution a path adds is one of two kinds:
  - light *found* by a ray: emission of a lamp, a surface or a medium, the world and sun
    discs for escaped rays (`found`);
  - light *sampled* at a vertex by next-event estimation (`lit` when the light casts no
    shadow, else `queued` with the shadow ray and `arrived` when it gets through).

Light passes (slots of `LightTally.passes`, Cycles' pass names):
  - found by a camera ray (bounce 0; through transparent surfaces too): Emission, or
    Environment for the world and sun discs (on a transparent film too, where Combined
    has none of it: `hidden`);
  - anything else is split over the kind of the path's first scattering: Diffuse,
    Glossy, Transmission or Volume, each Direct (next-event estimation at the first
    vertex, and light found by the ray leaving it) or Indirect (the rest). The split is
    by *shares*, per channel: at a surface, each lobe kind's part of the BSDF's value
    in the direction concerned (Cycles' pass_diffuse_weight / pass_glossy_weight; glass
    reflection counts as Glossy, refraction as Transmission, sheen and translucency as
    Diffuse, a subsurface walk as Diffuse; a delta lobe's share is its kind's alone); at
    a scattering in a medium, Volume alone. Shares sum to 1, so the passes sum to
    Combined exactly, clamp included (each slot gets the clamped value).
  - Diffuse, Glossy and Transmission Color: what the first surface's lobes of each kind
    weigh, times the throughput that reached it (Cycles writes the closures' weights;
    `colours`). Blender's Diffuse Direct is the slot divided by Diffuse Color (the
    add-on divides, as Cycles' film does).
Light groups (`LightTally.groups`): each contribution also goes to the group of the
light it came from (a lamp's, an emissive object's, the world's; -1: none); so does
the background a transparent film leaves out of Combined (Cycles': the groups then
exceed Combined there). Emission of
a medium belongs to no group (docs/passes.md names this gap).

With passes and groups off (`LightTally.passes` and `.groups` with no rows) every
function adds to Combined alone, at the cost of two branches.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .jit import kernel
from .path_weights import _add

# the kinds of a path's first scattering (the share tuples' order)
DIFFUSE_CLASS, GLOSSY_CLASS, TRANSMISSION_CLASS, VOLUME_CLASS = 0, 1, 2, 3
N_CLASSES = 4
# the shares of a scattering of one kind (a subsurface walk's exit: diffuse; a medium)
DIFFUSE_SHARES = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
VOLUME_SHARES = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
# slots: kind c's Direct is 2c, its Indirect 2c + 1
(DIFFUSE_DIRECT, DIFFUSE_INDIRECT, GLOSSY_DIRECT, GLOSSY_INDIRECT, TRANSMISSION_DIRECT,
 TRANSMISSION_INDIRECT, VOLUME_DIRECT, VOLUME_INDIRECT) = range(8)
EMISSION, ENVIRONMENT = 8, 9
DIFFUSE_COLOR, GLOSSY_COLOR, TRANSMISSION_COLOR = 10, 11, 12
N_SLOTS = 13
SLOT_NAMES = ("diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect",
              "transmission_direct", "transmission_indirect", "volume_direct",
              "volume_indirect", "emission", "environment", "diffuse_color",
              "glossy_color", "transmission_color")
# the slots whose sum is Combined (the colours are weights, not light; on a transparent
# film Environment also holds the background Combined leaves out)
LIGHT_SLOTS = tuple(range(10))


class LightTally(NamedTuple):
    """What one batch of paths adds up. Per path: L (n, 3) Combined; passes (n, N_SLOTS,
    3) or no rows; groups (n, G, 3) or no rows; shares (n, N_CLASSES, 3) the first
    scattering's shares in the direction the path left by. Per shadow ray: sh_shares
    (ns, N_CLASSES, 3) and sh_group (ns,). Per light: entry_group (a light entry's group,
    engine.kernels.lights), entry_world (1 for the world's entries: the world and its sky's
    sun), prim_group (an emissive triangle's group, by global triangle), world_group."""
    L: np.ndarray
    passes: np.ndarray
    groups: np.ndarray
    shares: np.ndarray
    sh_shares: np.ndarray
    sh_group: np.ndarray
    entry_group: np.ndarray
    entry_world: np.ndarray
    prim_group: np.ndarray
    world_group: np.ndarray


@kernel(allocates=False)
def on(t):
    """Whether the render asks for light passes."""
    return t.passes.shape[0] > 0


@kernel(allocates=False)
def grouped(t):
    """Whether the render asks for light groups."""
    return t.groups.shape[0] > 0


@kernel(allocates=False)
def entry_group(t, k):
    return t.entry_group[k] if 0 <= k < t.entry_group.shape[0] else -1


@kernel(allocates=False)
def prim_group(t, prim):
    return t.prim_group[prim] if 0 <= prim < t.prim_group.shape[0] else -1


@kernel(allocates=False)
def is_world_entry(t, k):
    return 0 <= k < t.entry_world.shape[0] and t.entry_world[k] != 0


@kernel(allocates=False)
def one_class(c):
    """The shares of a scattering of kind c alone (a delta lobe, a medium)."""
    d = 1.0 if c == DIFFUSE_CLASS else 0.0
    g = 1.0 if c == GLOSSY_CLASS else 0.0
    s = 1.0 if c == TRANSMISSION_CLASS else 0.0
    v = 1.0 if c == VOLUME_CLASS else 0.0
    return (d, d, d, g, g, g, s, s, s, v, v, v)


@kernel(allocates=False)
def _share(part, total):
    return min(max(part / total, 0.0), 1.0) if total > 0.0 else 0.0


@kernel(allocates=False)
def surface_shares(dr, dg, db, gr, gg, gb, fr, fg, fb, fallback):
    """The shares of a surface's value f (per channel) whose diffuse part is d and
    glossy part g (transmission: the rest, as Cycles takes it); where f is 0 in a
    channel, kind `fallback`'s alone."""
    sd_r, sd_g, sd_b = _share(dr, fr), _share(dg, fg), _share(db, fb)
    sg_r = min(_share(gr, fr), 1.0 - sd_r)
    sg_g = min(_share(gg, fg), 1.0 - sd_g)
    sg_b = min(_share(gb, fb), 1.0 - sd_b)
    one = one_class(fallback)
    if not fr > 0.0:
        sd_r, sg_r = one[0], one[3]
    if not fg > 0.0:
        sd_g, sg_g = one[1], one[4]
    if not fb > 0.0:
        sd_b, sg_b = one[2], one[5]
    return (sd_r, sd_g, sd_b, sg_r, sg_g, sg_b, 1.0 - sd_r - sg_r, 1.0 - sd_g - sg_g,
            1.0 - sd_b - sg_b, 0.0, 0.0, 0.0)


@kernel(allocates=False)
def _split(passes, p, shares, row, indirect, ar, ag, ab):
    """Add (ar, ag, ab) to path p's kinds by the shares in shares[row]."""
    o = 1 if indirect else 0
    for c in range(N_CLASSES):
        passes[p, 2 * c + o, 0] += shares[row, c, 0] * ar
        passes[p, 2 * c + o, 1] += shares[row, c, 1] * ag
        passes[p, 2 * c + o, 2] += shares[row, c, 2] * ab


@kernel(allocates=False)
def to_group(t, p, group, r, g, b):
    """Add light already in Combined to path p's light group (none: -1)."""
    if group >= 0 and t.groups.shape[0] > 0:
        t.groups[p, group, 0] += r
        t.groups[p, group, 1] += g
        t.groups[p, group, 2] += b


@kernel(allocates=False)
def _factor(added, raw):
    return added / raw if raw != 0.0 else 1.0


@kernel(allocates=False)
def found(t, p, b, r, g, bl, limit, world, group):
    """Light (r, g, bl) found by path p's ray after b bounces, under the clamp `limit`,
    from the world (world True) or not, of light group `group`. Returns the factor per
    channel the clamp left of it (for a caller that splits it over groups itself, with
    group -1 here)."""
    ar, ag, ab = _add(t.L, p, r, g, bl, limit)
    if t.passes.shape[0] > 0:
        if b == 0:
            slot = ENVIRONMENT if world else EMISSION
            t.passes[p, slot, 0] += ar
            t.passes[p, slot, 1] += ag
            t.passes[p, slot, 2] += ab
        else:
            _split(t.passes, p, t.shares, p, b > 1, ar, ag, ab)
    to_group(t, p, group, ar, ag, ab)
    return _factor(ar, r), _factor(ag, g), _factor(ab, bl)


@kernel(allocates=False)
def hidden(t, p, r, g, bl, group):
    """The background a camera ray sees on a transparent film: not in Combined, but in
    the Environment pass and its light group, as Cycles keeps it."""
    if t.passes.shape[0] > 0:
        t.passes[p, ENVIRONMENT, 0] += r
        t.passes[p, ENVIRONMENT, 1] += g
        t.passes[p, ENVIRONMENT, 2] += bl
    to_group(t, p, group, r, g, bl)


@kernel(allocates=False)
def lit(t, p, b, r, g, bl, limit, shares, group):
    """Light sampled at path p's vertex after b bounces that needs no shadow ray; shares:
    the vertex's own (used at the first vertex, b = 0)."""
    ar, ag, ab = _add(t.L, p, r, g, bl, limit)
    if t.passes.shape[0] > 0:
        if b == 0:
            for c in range(N_CLASSES):
                t.passes[p, 2 * c, 0] += shares[3 * c] * ar
                t.passes[p, 2 * c, 1] += shares[3 * c + 1] * ag
                t.passes[p, 2 * c, 2] += shares[3 * c + 2] * ab
        else:
            _split(t.passes, p, t.shares, p, True, ar, ag, ab)
    to_group(t, p, group, ar, ag, ab)


@kernel(allocates=False)
def queued(t, i, p, b, shares, group):
    """Shadow ray i of path p (after b bounces) was queued: keep what its light will be
    split by (the vertex's shares at the first vertex, else the path's)."""
    if t.passes.shape[0] > 0:
        for c in range(N_CLASSES):
            for ch in range(3):
                t.sh_shares[i, c, ch] = shares[3 * c + ch] if b == 0 else t.shares[p, c, ch]
    if t.groups.shape[0] > 0:
        t.sh_group[i] = group


@kernel(allocates=False)
def arrived(t, i, p, sh_bounce, r, g, bl, limit):
    """Shadow ray i of path p got (r, g, bl) through."""
    ar, ag, ab = _add(t.L, p, r, g, bl, limit)
    if t.passes.shape[0] > 0:
        _split(t.passes, p, t.sh_shares, i, sh_bounce != 0, ar, ag, ab)
    if t.groups.shape[0] > 0:
        to_group(t, p, t.sh_group[i], ar, ag, ab)


@kernel(allocates=False)
def left_first(t, p, shares):
    """Path p leaves its first scattering: later light is split by these shares."""
    if t.passes.shape[0] > 0:
        for c in range(N_CLASSES):
            for ch in range(3):
                t.shares[p, c, ch] = shares[3 * c + ch]


@kernel(allocates=False)
def colours(t, p, br, bg, bb, d, g, s):
    """The first surface of path p (reached with throughput b): what its diffuse,
    glossy and transmission lobes weigh (RGB tuples d, g, s)."""
    if t.passes.shape[0] > 0:
        t.passes[p, DIFFUSE_COLOR, 0] += br * d[0]
        t.passes[p, DIFFUSE_COLOR, 1] += bg * d[1]
        t.passes[p, DIFFUSE_COLOR, 2] += bb * d[2]
        t.passes[p, GLOSSY_COLOR, 0] += br * g[0]
        t.passes[p, GLOSSY_COLOR, 1] += bg * g[1]
        t.passes[p, GLOSSY_COLOR, 2] += bb * g[2]
        t.passes[p, TRANSMISSION_COLOR, 0] += br * s[0]
        t.passes[p, TRANSMISSION_COLOR, 1] += bg * s[1]
        t.passes[p, TRANSMISSION_COLOR, 2] += bb * s[2]


@kernel(allocates=False)
def add_unoccluded(t, sh_path, sh_contrib, blocked, sh_bounce, clamp_direct, clamp_indirect):
    """Add the light of the shadow rays that reached it, clamped (the direct clamp for
    shadow rays of a path's first vertex, sh_bounce 0)."""
    for i in range(sh_path.shape[0]):
        if not blocked[i]:
            arrived(t, i, sh_path[i], sh_bounce[i], sh_contrib[i, 0], sh_contrib[i, 1],
                    sh_contrib[i, 2], clamp_direct if sh_bounce[i] == 0 else clamp_indirect)


@kernel(allocates=False)
def add_transmitted(t, sh_path, sh_contrib, trans, sh_bounce, clamp_direct, clamp_indirect):
    """Add the light of shadow rays times their transmittance, clamped."""
    for i in range(sh_path.shape[0]):
        if trans[i, 0] > 0.0 or trans[i, 1] > 0.0 or trans[i, 2] > 0.0:
            arrived(t, i, sh_path[i], sh_bounce[i], sh_contrib[i, 0] * trans[i, 0],
                    sh_contrib[i, 1] * trans[i, 1], sh_contrib[i, 2] * trans[i, 2],
                    clamp_direct if sh_bounce[i] == 0 else clamp_indirect)


def new_tally(n: int, n_shadow: int, passes: bool, n_groups: int, groups_of) -> LightTally:
    """The tally of a batch of n paths with at most n_shadow shadow rays per bounce;
    groups_of: (entry_group, entry_world, prim_group, world_group) arrays, or None."""
    rows = n if passes else 0
    sh_rows = n_shadow if passes else 0
    g_rows = n if n_groups > 0 else 0
    if groups_of is None:
        groups_of = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64),
                     np.full(1, -1, np.int64))
    return LightTally(np.zeros((n, 3)), np.zeros((rows, N_SLOTS, 3)),
                      np.zeros((g_rows, max(n_groups, 0), 3)),
                      np.zeros((rows, N_CLASSES, 3)), np.zeros((sh_rows, N_CLASSES, 3)),
                      np.full(n_shadow if n_groups > 0 else 0, -1, np.int64), *groups_of)
