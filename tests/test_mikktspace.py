"""drt_addon/export/mikktspace.py against Blender's own MikkTSpace (Mesh.calc_tangents),
on meshes of triangles, where both compute the same thing: Cycles runs MikkTSpace on its
render triangles, so DRT does too, and that is what gives n-gons tangents and a mesh
without a UV map its map_to_sphere tangents (Blender's calc_tangents refuses both).
The renders against Cycles: test_normal_map_vs_cycles.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

from drt_addon.export import mikktspace


def _triangulated(bpy, make, smooth=True, mirror_uv=False):
    """A primitive (make(bpy)) cut into triangles, shaded smooth or flat; mirror_uv
    mirrors its UVs' u on half of the faces (triangles of both orientations)."""
    import bmesh
    bpy.ops.wm.read_factory_settings(use_empty=True)
    make(bpy)
    mesh = bpy.context.active_object.data
    bm = bmesh.new()
    bm.from_mesh(mesh)
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bm.to_mesh(mesh)
    bm.free()
    for p in mesh.polygons:
        p.use_smooth = smooth
    if mirror_uv:
        uv = mesh.uv_layers.active.uv
        for p in mesh.polygons:
            if p.index % 2:
                for li in p.loop_indices:
                    uv[li].vector.x = 1.0 - uv[li].vector.x
    mesh.calc_loop_triangles()
    return mesh


def _arrays(mesh):
    nt = len(mesh.loop_triangles)
    loops = np.empty(nt * 3, np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    tris = np.empty(nt * 3, np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    tris = tris.reshape(-1, 3)
    # the normals Blender's MikkTSpace reads: a flat face's is Blender's face normal,
    # which may differ from Cycles' cross product in the last bit (and MikkTSpace welds
    # corners by exact equality), so the comparison gives Blender's
    normals = np.empty(nt * 9, np.float32)
    mesh.loop_triangles.foreach_get("split_normals", normals)
    normals = normals.reshape(nt, 3, 3)
    uv = np.empty(len(mesh.loops) * 2, np.float32)
    mesh.uv_layers.active.uv.foreach_get("vector", uv)
    return co, tris, normals, uv.reshape(-1, 2)[loops].reshape(nt, 3, 2), loops


def _blender_tangents(mesh, loops):
    mesh.calc_tangents()
    t = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.loops.foreach_get("tangent", t)
    s = np.empty(len(mesh.loops), np.float32)
    mesh.loops.foreach_get("bitangent_sign", s)
    nt = len(loops) // 3
    return t.reshape(-1, 3)[loops].reshape(nt, 3, 3), s[loops].reshape(nt, 3)


PRIMITIVES = {
    "uv_sphere": lambda bpy: bpy.ops.mesh.primitive_uv_sphere_add(),
    "suzanne": lambda bpy: bpy.ops.mesh.primitive_monkey_add(),
    "cylinder": lambda bpy: bpy.ops.mesh.primitive_cylinder_add(),   # n-gon caps
    "torus": lambda bpy: bpy.ops.mesh.primitive_torus_add(),
    "cube": lambda bpy: bpy.ops.mesh.primitive_cube_add(),
}


@pytest.mark.parametrize("smooth", [True, False], ids=["smooth", "flat"])
@pytest.mark.parametrize("name", sorted(PRIMITIVES))
def test_tangents_match_blenders_mikktspace(bpy_drt, name, smooth):
    """Every corner's tangent within 1e-5 of Blender's, every bitangent sign equal, on
    smooth and flat-shaded triangle meshes. Measured: largest difference 1.8e-7 (smooth
    Suzanne and cylinder), 0 to 6e-8 on the flat ones."""
    mesh = _triangulated(bpy_drt, PRIMITIVES[name], smooth=smooth)
    co, tris, normals, uvs, loops = _arrays(mesh)
    ref_t, ref_s = _blender_tangents(mesh, loops)
    got = mikktspace.tangents(co, tris, normals, uvs)
    err = np.abs(got[..., :3] - ref_t).max()
    print(f"{name} ({'smooth' if smooth else 'flat'}): {len(tris)} triangles, "
          f"largest tangent difference {err:.2e}")
    assert err < 1e-5, err
    np.testing.assert_array_equal(got[..., 3], ref_s)


def test_mirrored_uvs_give_both_signs_as_blender(bpy_drt):
    """Half of Suzanne's faces with mirrored UVs: triangles of both orientations, which
    MikkTSpace keeps in separate groups at the vertices they share; signs of both kinds
    come out, each equal to Blender's, the tangents within 1e-5."""
    mesh = _triangulated(bpy_drt, PRIMITIVES["suzanne"], mirror_uv=True)
    co, tris, normals, uvs, loops = _arrays(mesh)
    ref_t, ref_s = _blender_tangents(mesh, loops)
    got = mikktspace.tangents(co, tris, normals, uvs)
    assert set(np.unique(ref_s)) == {-1.0, 1.0}
    np.testing.assert_array_equal(got[..., 3], ref_s)
    assert np.abs(got[..., :3] - ref_t).max() < 1e-5


def test_map_to_sphere_is_cycles():
    """Cycles' map_to_sphere (util/math_float3.h): u from atan2(x, y), v from the polar
    angle, (0, 0) at the origin and u = 0 on the z axis."""
    p = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 0.0],
                  [1.0, -1.0, 1.0]], np.float32)
    uv = mikktspace.map_to_sphere(p)
    expect = [(0.5, 0.5), (0.25, 0.5), (0.0, 1.0), (0.0, 0.0),
              (0.5 - math.atan2(1, -1) / (2 * math.pi), 1 - math.acos(1 / math.sqrt(3)) / math.pi)]
    np.testing.assert_allclose(uv, expect, atol=1e-6)


def test_degenerate_and_uvless_triangles_get_finite_unit_tangents():
    """Degenerate triangles (two equal positions) copy a good corner of the same welded
    vertex; triangles with no UV area take a neighbour's orientation; a corner that no
    group reaches keeps MikkTSpace's default (1, 0, 0), sign -1. Nothing is NaN."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]], np.float64)
    tris = np.array([[0, 1, 2], [1, 3, 2], [1, 4, 3]])        # the last is degenerate
    n = np.tile([0.0, 0.0, 1.0], (3, 3, 1)).astype(np.float32)
    uv = pos[tris][..., :2].astype(np.float32)
    uv[1] = uv[1, 0]                                           # no UV area
    out = mikktspace.tangents(pos, tris, n, uv)
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out[0, :, :3], [[1, 0, 0]] * 3, atol=1e-6)
    np.testing.assert_array_equal(out[0, :, 3], 1.0)
    np.testing.assert_allclose(np.linalg.norm(out[..., :3], axis=-1), 1.0, atol=1e-6)
    # the degenerate triangle's corner at vertex 1 copies the first good corner there
    np.testing.assert_array_equal(out[2, 0], out[0, 1])


def test_non_finite_input_gives_finite_tangents_and_leaves_good_corners_alone():
    """A triangle with a NaN or infinite position, normal or UV is left out (MikkTSpace's
    default tangent space at its corners) and adds nothing to the good triangles' groups:
    their tangents are those of the mesh without it."""
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [np.nan, 0, 0]], np.float64)
    tris = np.array([[0, 1, 2], [1, 3, 2], [1, 4, 3]])
    n = np.tile([0.0, 0.0, 1.0], (3, 3, 1)).astype(np.float32)
    uv = np.nan_to_num(pos[tris][..., :2]).astype(np.float32)
    out = mikktspace.tangents(pos, tris, n, uv)
    clean = mikktspace.tangents(pos[:4], tris[:2], n[:2], uv[:2])
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out[:2], clean, atol=1e-6)   # not bit for bit: two runs
    for bad in ("normal", "uv"):
        n2, uv2 = n.copy(), uv.copy()
        (n2 if bad == "normal" else uv2)[2, 1, 0] = np.inf
        out = mikktspace.tangents(pos[:4].copy(), np.array([[0, 1, 2], [1, 3, 2], [1, 0, 3]]),
                                  n2, uv2)
        assert np.all(np.isfinite(out)), bad
