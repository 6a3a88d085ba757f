"""Baking through Blender's bake operator (`bpy.ops.object.bake`, DRT's Render > Bake
panel): the RenderEngine's `bake` hands each texel of the object's active image its
triangle and barycentrics (the render result's BakePrimitive pass); DRT exports the
scene, finds those triangles in it, shades the points (engine.bake) and writes the
values into the result's Combined pass, which Blender turns into the image (tangent or
object space for normals, margins, colour spaces).

Pass types: Combined, Diffuse, Glossy, Transmission (with the Direct / Indirect /
Color filter), Emit, Normal and Ambient Occlusion, as Cycles bakes them; others are
refused with a clear error."""
from __future__ import annotations

import itertools
from importlib import import_module

import numpy as np

_layers = itertools.count(1)     # Blender finds a bake's image by its layer's name


class BakeError(RuntimeError):
    pass


def _label(kind: str) -> str:
    """A bake type as the Bake panel names it."""
    return {"AO": "Ambient Occlusion", "EMIT": "Emit"}.get(kind, kind.title())


def _texels(layer, width: int, height: int):
    """(texel ids, loop-triangle ids, u, v, footprints (n, 4)) of the texels to bake,
    from BakePrimitive (u, v, triangle id as int32 bits; -1: no triangle) and
    BakeDifferential (du/dx, du/dy, dv/dx, dv/dy)."""
    rect = layer.passes["BakePrimitive"]
    c = rect.channels
    buf = np.empty(width * height * c, np.float32)
    rect.rect.foreach_get(buf)
    buf = buf.reshape(-1, c)
    # Blender 5: (u, v, id); before it, (seed, id, u, v)
    if c == 3:
        ids, u, v = buf[:, 2].copy().view(np.int32), buf[:, 0], buf[:, 1]
    else:
        ids, u, v = buf[:, 1].copy().view(np.int32), buf[:, 2], buf[:, 3]
    texel = np.flatnonzero(ids >= 0)
    diff = layer.passes.get("BakeDifferential")
    footprint = None
    if diff is not None and diff.channels == 4:
        d = np.empty(width * height * 4, np.float32)
        diff.rect.foreach_get(d)
        footprint = d.reshape(-1, 4)[texel].astype(np.float64)
    return texel, ids[texel].astype(np.int64), u[texel].astype(np.float64), \
        v[texel].astype(np.float64), footprint


def _local_triangles(obj) -> np.ndarray:
    """For each loop triangle of the evaluated object's mesh, its index among the
    triangles DRT exported (-1: skipped as degenerate, export.mesh)."""
    from .export.mesh import degenerate_triangles, mesh_arrays
    mesh = obj.to_mesh()
    try:
        pos, tris, _, _ = mesh_arrays(mesh)
    finally:
        obj.to_mesh_clear()
    bad = degenerate_triangles(pos, tris)
    local = np.full(len(tris), -1, np.int64)
    local[~bad] = np.arange(int((~bad).sum()))
    return local


def _first_triangle(ctx, name: str) -> int:
    """The global id (engine.accel) of the first triangle of the exported mesh `name`."""
    start = 0
    for mesh in ctx.accel.ordered_meshes:
        if mesh.name == name and getattr(mesh, "instances", None) is None:
            return start
        start += len(mesh.triangles)
    raise BakeError(f"DRT: cannot bake {name!r}: it is not in the scene DRT rendered "
                    "(is it hidden from rendering, or not a mesh?)")


def bake(engine, depsgraph, obj, pass_type: str, pass_filter: int, width: int,
         height: int, reporter) -> None:
    """The RenderEngine's bake of `obj`'s image of width x height: writes its Combined."""
    from .engine_link import engine as drt
    from .export import export_scene
    bake_mod = import_module(drt.__name__ + ".bake")
    result = engine.begin_result(0, 0, width, height, layer=f"drt_bake_{next(_layers)}")
    try:
        layer = result.layers[0]
        texel, tri, u, v, footprint = _texels(layer, width, height)
        out = np.zeros((width * height, 4), np.float32)
        if pass_type in bake_mod.OPAQUE_WHEN_EMPTY:
            out[:, 3] = 1.0
        if pass_type not in bake_mod.KINDS:
            raise BakeError(f"DRT cannot bake {_label(pass_type)} (it bakes "
                            f"{', '.join(_label(k) for k in bake_mod.KINDS)})")
        local = _local_triangles(obj)[tri]
        keep = local >= 0
        texel, local, u, v = texel[keep], local[keep], u[keep], v[keep]
        footprint = footprint[keep] if footprint is not None else None
        scene = depsgraph.scene
        camera = drt.Camera(np.eye(4), lens=50.0)
        description = export_scene(depsgraph, reporter, view=(camera, 1, 1), alone=obj.name)
        settings = bake_mod.settings_for(scene.drt.to_engine_settings(), pass_type,
                                         int(pass_filter))
        ctx = drt.RenderContext(description, settings)
        try:
            prim = _first_triangle(ctx, obj.name) + local
            world = scene.world
            ao = float(world.light_settings.distance) if world is not None else 10.0
            values = bake_mod.bake(ctx, prim, u, v, pass_type, int(pass_filter),
                                   ao_distance=ao, cancelled=engine.test_break,
                                   footprint=footprint)
        finally:
            ctx.close()
        out[texel, :3] = values
        out[texel, 3] = 1.0
        layer.passes["Combined"].rect.foreach_set(out.reshape(-1))
    finally:
        engine.end_result(result)
