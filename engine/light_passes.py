"""Cycles' light passes and light groups of a render: what the path tracer is asked to
split (engine.kernels.light_tally says how it splits), the tables that name each light's
group, and the images read back from the film.

The film keeps, per pixel, the sums of `channels(ctx)` RGB channels besides Combined:
the 13 slots of light_tally (ten of light, which sum to Combined, and three Color
weights), then one per light group in Scene.light_groups' order."""
from __future__ import annotations

import numpy as np

from .kernels.light_tally import LIGHT_SLOTS, N_SLOTS, SLOT_NAMES
from .lights import WORLD


def wanted(ctx) -> tuple[bool, tuple]:
    """(light passes asked for, the light groups' names) of a render."""
    return bool(getattr(ctx.settings, "light_passes", False)), \
        tuple(getattr(ctx.scene, "light_groups", ()) or ())


def channels(ctx) -> int:
    """RGB channels the film keeps besides Combined: 0 when nothing is asked."""
    passes, groups = wanted(ctx)
    if not passes and not groups:
        return 0
    return N_SLOTS + len(groups)


def group_tables(ctx, names: tuple) -> tuple:
    """(entry_group, entry_world, prim_group, world_group) for light_tally: the group
    index (-1: none) of every light entry of ctx.lights and of every global triangle, and
    the world's, for the groups `names`."""
    index = {name: i for i, name in enumerate(names)}

    def group(thing) -> int:
        return index.get(getattr(thing, "lightgroup", "") or "", -1)

    scene, lights = ctx.scene, ctx.lights
    world_group = group(scene.world)
    sun = getattr(scene.world, "sun", None)
    n_entries = len(lights)
    entry_group = np.full(n_entries, -1, np.int64)
    entry_world = np.zeros(n_entries, np.int64)
    for k, source in enumerate(lights.sources):
        world = source is WORLD or (sun is not None and source is sun)
        entry_world[k] = int(world)
        entry_group[k] = world_group if world else group(source)
    accel = ctx.accel
    prim_group = np.full(int(getattr(accel, "total_triangles", len(accel.triangles))), -1,
                         np.int64)
    start = 0
    for mesh in accel.ordered_meshes[:accel.static_meshes]:
        prim_group[start:start + len(mesh.triangles)] = group(mesh)
        start += len(mesh.triangles)
    for obj in getattr(accel, "moving", ()):
        prim_group[obj.prim_offset:obj.prim_offset + len(obj.mesh.triangles)] = \
            group(obj.mesh)
    mesh_lights = lights.mesh
    if mesh_lights is not None:
        entry = np.asarray(mesh_lights.entry, np.int64)
        prims = np.flatnonzero(entry >= 0)
        entry_group[lights.n_lamps + entry[prims]] = prim_group[prims]
    return entry_group, entry_world, prim_group, np.array([world_group], np.int64)


def scale_light(extra: np.ndarray, factor: float) -> None:
    """Scale the light channels of per-sample extras (n, channels, 3) in place (Film >
    Exposure), not the Color weights."""
    extra[:, :len(LIGHT_SLOTS)] *= factor
    extra[:, N_SLOTS:] *= factor


def images(film, groups: tuple) -> dict:
    """The film's light passes as (height, width, 3) means, row 0 at the top: the slots
    by SLOT_NAMES and each group as 'group:<name>'. The Direct and Indirect slots hold
    light, not yet divided by their Color (the add-on divides, as Cycles' film does)."""
    if film.extra_sum.shape[1] < N_SLOTS + len(groups):
        return {}                # kept none (a film may keep the shadow catcher's alone)
    c = np.maximum(film.count, 1)[:, None, None]
    mean = (film.extra_sum / c).reshape(film.height, film.width, -1, 3)
    out = {name: mean[:, :, i] for i, name in enumerate(SLOT_NAMES)}
    for j, name in enumerate(groups):
        out["group:" + name] = mean[:, :, N_SLOTS + j]
    return out


def divide_by_colour(light: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """Cycles' Direct and Indirect passes: the light divided by the Color pass, per
    channel, as Cycles' film divides them (its safe_divide_even_color): where a channel's
    colour is 0, that channel takes the other channels' ratio (their mean when both have
    one), so a saturated colour's pass stays grey; 0 where every channel's is."""
    light = np.asarray(light, np.float64)
    colour = np.asarray(colour, np.float64)
    zero = colour == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(zero, 0.0, light / np.where(zero, 1.0, colour))
    x, y, z = ratio[..., 0].copy(), ratio[..., 1].copy(), ratio[..., 2].copy()
    zx, zy, zz = zero[..., 0], zero[..., 1], zero[..., 2]
    # the order of Cycles' cases: a zero x first, then a zero y, then a zero z
    xy = zx & zy
    xz = zx & ~zy & zz
    x_only = zx & ~zy & ~zz
    yz = ~zx & zy & zz
    y_only = ~zx & zy & ~zz
    z_only = ~zx & ~zy & zz
    x, y = np.where(xy, z, x), np.where(xy, z, y)
    x, z = np.where(xz, y, x), np.where(xz, y, z)
    x = np.where(x_only, 0.5 * (y + z), x)
    y, z = np.where(yz, x, y), np.where(yz, x, z)
    y = np.where(y_only, 0.5 * (x + z), y)
    z = np.where(z_only, 0.5 * (x + y), z)
    return np.stack([x, y, z], axis=-1)


def per_sample(tally, n: int, k: int) -> np.ndarray:
    """The film's extra channels (n, k, 3) of a batch's LightTally: its slots (zeros
    without light passes), then its groups."""
    if tally.passes.shape[0] and not tally.groups.shape[0] and k == N_SLOTS:
        return tally.passes                  # the slots alone: no copy
    out = np.zeros((n, k, 3))
    if tally.passes.shape[0]:
        out[:, :N_SLOTS] = tally.passes
    if tally.groups.shape[0]:
        out[:, N_SLOTS:] = tally.groups
    return out
