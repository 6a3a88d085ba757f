"""True displacement in the engine, without Blender (engine/displacement.py): vertices
move by the displacement program as Cycles' GeometryManager::displace moves them, each
checked against offsets computed here from the definitions (not by the module's code);
normals are recomputed by Cycles' rule; a displaced surface reads Generated coordinates
at its undisplaced point. The Blender side and the comparison with Cycles:
test_displacement_vs_cycles.py."""
from __future__ import annotations

import numpy as np
import pytest
from engine import Camera, Material, ObjectInfo, RenderSettings, Scene, TriangleMesh, World
from engine import displacement as D
from engine import render
from engine.nodes import context as C
from engine.nodes import converter_nodes as CV
from engine.nodes import input_nodes as I
from engine.nodes import vector_nodes as V
from engine.nodes.program import ProgramBuilder


def grid(n=4, size=2.0):
    """An n x n grid of quads in z = 0 (object space), two triangles each, its UVs
    running over [0, 1]^2 and its vertex normals +z: (positions, triangles, uvs, normals)."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s, s)
    pos = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    tris = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    tris = np.array(tris, np.int32)
    uvs = (pos[tris][..., :2] / size + 0.5).astype(np.float32)
    return pos, tris, uvs, np.tile([0.0, 0.0, 1.0], (len(pos), 1))


def matrix(scale=(1.0, 1.0, 1.0), angle=0.0, offset=(0.0, 0.0, 0.0)):
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    m = np.eye(4)
    m[:3, :3] = rot @ np.diag(scale)
    m[:3, 3] = offset
    return m


def height_program(height_of="u", direction="normal"):
    """Height = the hit's UV u (or a NaN constant), direction = the hit's normal (or the
    vector (u, v, 0.5) for a VECTOR displacement): (program, height Value, direction)."""
    b = ProgramBuilder()
    uv = b.emit(I.IN_HIT3, "vector", [C.H_UV], varying=True)
    if height_of == "nan":
        h = b.emit(CV.CV_MATH, "float", [b.constant(float("nan")), b.constant(1.0),
                                         b.constant(0.0), CV.MATH_OPS.index("MULTIPLY"), 0],
                   varying=True)
    else:
        h = b.emit(I.IN_HIT1, "float", [C.H_UV], varying=True)
    if direction == "normal":
        d = b.emit(I.IN_HIT3, "vector", [C.H_N], varying=True)
    else:
        half = b.constant((0.0, 0.0, 0.5), "vector")
        d = b.emit(V.VEC_MATH, "vector", [uv, half, half, b.constant(1.0),
                                          V.VECTOR_OPS.index("ADD")])
    return b.build(), h, d


def _displace(disp, m, pos, tris, uvs, normals, material=None, tangents=None):
    row = C.object_row(m)
    material = np.zeros(len(tris), np.int64) if material is None else material
    return D.displace(pos, tris, material, normals, [disp, None], m, row, uvs, tangents)


def first_uv(tris, uvs, displaced):
    """Each vertex's UV at its first corner on a displaced triangle, by a plain loop."""
    out = {}
    for t, corners in enumerate(tris):
        if not displaced[t]:
            continue
        for k, v in enumerate(corners):
            out.setdefault(int(v), uvs[t, k])
    return out


@pytest.mark.parametrize("space", ["OBJECT", "WORLD"])
def test_displacement_node_moves_each_vertex_along_its_normal(space):
    """A Displacement node of height u: Object space moves a vertex by u along its
    normal in object space, whatever the object's scale; World space by u along the world
    normal, which a non-uniform scale then shrinks or stretches in object space."""
    pos, tris, uvs, normals = grid()
    normals = normals + np.array([0.3, -0.2, 0.0]) * pos[:, :1]       # tilted normals
    prog, h, d = height_program()
    m = matrix(scale=(2.0, 0.5, 3.0), angle=0.7, offset=(1.0, 2.0, 3.0))
    out, moved = _displace(D.Displacement(prog, d, h, "NORMAL", space), m, pos, tris, uvs,
                           normals)
    assert moved.all()
    first = first_uv(tris, uvs, moved)
    a = m[:3, :3]
    for v, uv in first.items():
        n = normals[v] / np.linalg.norm(normals[v])
        if space == "OBJECT":
            want = n * uv[0]
        else:
            nw = np.linalg.inv(a).T @ n
            want = np.linalg.inv(a) @ (nw / np.linalg.norm(nw) * uv[0])
        np.testing.assert_allclose(out[v] - pos[v], want, rtol=1e-6, atol=1e-7)


def test_vector_displacement_in_tangent_space():
    """(x, y, z) = (u, v, 0.5) in tangent space: x along the tangent, y along the normal,
    z along the bitangent (normal x tangent, times the sign)."""
    pos, tris, uvs, normals = grid()
    tangents = np.zeros((len(tris), 3, 4), np.float32)
    tangents[..., 0], tangents[..., 3] = 1.0, -1.0            # tangent +x, sign -1
    prog, _, d = height_program(direction="vector")
    out, _ = _displace(D.Displacement(prog, d, kind="VECTOR", space="TANGENT"),
                       matrix(scale=(2.0, 2.0, 2.0)), pos, tris, uvs, normals,
                       tangents=tangents)
    for v, uv in first_uv(tris, uvs, np.ones(len(tris), bool)).items():
        t, n = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
        b = -np.cross(n, t)
        np.testing.assert_allclose(out[v] - pos[v], t * uv[0] + n * uv[1] + b * 0.5,
                                   rtol=1e-6, atol=1e-7)


def test_first_displacing_triangle_gives_the_corner_and_others_do_not_move():
    """A vertex takes the corner attributes of the first triangle, in the mesh's order,
    whose material displaces; triangles of a material without displacement move only
    the vertices they share with displaced ones."""
    pos, tris, uvs, normals = grid(n=2)
    uvs = uvs.copy()
    uvs[1] += 0.25               # triangle 1's corners disagree with their neighbours'
    material = np.array([1, 0, 0, 0, 1, 1, 1, 1])       # material 1: no displacement
    prog, h, d = height_program()
    out, moved = _displace(D.Displacement(prog, d, h), np.eye(4), pos, tris, uvs, normals,
                           material)
    np.testing.assert_array_equal(moved, material == 0)
    first = first_uv(tris, uvs, moved)
    for v in range(len(pos)):
        want = first[v][0] if v in first else 0.0
        np.testing.assert_allclose(out[v] - pos[v], [0.0, 0.0, want], atol=1e-7)
    assert any(first[v][0] != uvs[0][list(tris[0]).index(v)][0]
               for v in tris[0] if v in first)     # the rule is exercised


def test_non_finite_offset_is_zero():
    pos, tris, uvs, normals = grid()
    prog, h, d = height_program("nan")
    out, moved = _displace(D.Displacement(prog, d, h), np.eye(4), pos, tris, uvs, normals)
    assert moved.all()
    np.testing.assert_array_equal(out, pos)


def test_recomputed_normals_follow_cycles_rule():
    """Displacement Only: a smooth triangle's corner normals become, per vertex, the
    normalised sum of the unit normals of the recomputed triangles around it; a flat
    one's its face normal; the rest keep theirs."""
    pos, tris, _, _ = grid(n=3)
    rng = np.random.default_rng(3)
    moved_pos = pos + np.column_stack([np.zeros((len(pos), 2)), rng.uniform(0, 0.5, len(pos))])
    recompute = np.ones(len(tris), bool)
    recompute[:2] = False
    smooth = np.ones(len(tris), bool)
    smooth[5] = False
    old = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (len(tris), 3, 1))
    out = D.displaced_normals(moved_pos, tris, recompute, old, smooth)
    face = {}
    for t, (a, b, c) in enumerate(tris):
        n = np.cross(moved_pos[b] - moved_pos[a], moved_pos[c] - moved_pos[a])
        face[t] = n / np.linalg.norm(n)
    for t, corners in enumerate(tris):
        for k, v in enumerate(corners):
            if not recompute[t]:
                want = old[t, k]
            elif not smooth[t]:
                want = face[t]
            else:
                s = sum(face[u] for u in range(len(tris)) if recompute[u] and v in tris[u])
                want = s / np.linalg.norm(s)
            np.testing.assert_allclose(out[t, k], want, atol=1e-6)
    assert D.displaced_normals(moved_pos, tris, recompute, None, smooth) is None


def _generated_scene(undisplaced):
    """A 2 x 2 quad at z = 0 seen from above by an orthographic camera, emitting its
    Generated coordinates (texture space: the unit cube about the origin)."""
    b = ProgramBuilder()
    gen = b.emit(I.IN_HIT3, "vector", [C.H_GENERATED], varying=True)
    b.output("emission", gen)
    mat = Material("gen", (0.0, 0.0, 0.0), specular_ior_level=0.0, emission=(0.5, 0.5, 0.5),
                   shader=b.build())
    pos = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]])
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    mesh = TriangleMesh("quad", pos, tris, [0], object_info=ObjectInfo(np.eye(4)),
                        undisplaced=undisplaced(pos)[tris] if undisplaced else None)
    cam = np.eye(4)
    cam[2, 3] = 5.0
    return Scene(Camera(cam, kind="ORTHO", ortho_scale=1.5), 16, 16, [mesh], [mat],
                 world=World(color=(0.0, 0.0, 0.0)))


def test_displaced_surface_reads_generated_at_its_undisplaced_point():
    """Generated x at a hit is (x + 0.5) / 2 + 0.5 when the surface's undisplaced corners
    lie 0.5 along x from where it is hit (x / 2 + 0.5 without them)."""
    settings = RenderSettings(samples=256, max_bounces=0)
    x = (np.arange(16) + 0.5) / 16 * 1.5 - 0.75
    for shift, und in ((0.5, lambda p: p + [0.5, 0.0, 0.0]), (0.0, None)):
        img = render(_generated_scene(und), settings)[0].mean()
        want = (x + shift) / 2 + 0.5
        np.testing.assert_allclose(img[4:12, 2:14, 0], np.tile(want[2:14], (8, 1)), atol=4e-3)


def _bump_program(op, matrix_hit):
    """A program of one bump-family op on registers set from the hit row (a normal, and
    heights changing by 0.3 and -0.2 over the steps): the op's result."""
    from engine.nodes import bump as B
    b = ProgramBuilder()
    n = b.emit(I.IN_HIT3, "vector", [C.H_N], varying=True)
    if op == B.DISP_OBJECT_VECTOR:
        out = b.emit(op, "vector", [n, b.constant(0.7)], varying=True)
    else:
        out = b.emit(op, "vector", [n, b.constant(1.0), b.constant(1.0), b.constant(0.1),
                                    b.constant(0.3), b.constant(-0.2)], varying=True)
    return b.build().evaluate(out, matrix_hit)[0]


def _hit_with_object(m, normal=(0.2, -0.3, 0.9)):
    n = np.asarray(normal) / np.linalg.norm(normal)
    hit = C.hit_rows(np.zeros((1, 3)), n[None], objects=C.object_row(m)[None], obj=0)
    hit[0, C.H_DX + C.H_P:C.H_DX + C.H_P + 3] = [0.01, 0.002, 0.0]
    hit[0, C.H_DY + C.H_P:C.H_DY + C.H_P + 3] = [-0.001, 0.012, 0.003]
    return hit, n


def _bent_by_formula(a, b, n, dhx=0.3, dhy=-0.2, width=0.1):
    """Cycles' bump normal (svm_node_set_bump, strength 1, distance 1), written out."""
    rx, ry = np.cross(b, n), np.cross(n, a)
    det = a @ rx
    v = width * abs(det) * n - np.sign(det) * (dhx * rx + dhy * ry)
    return v / np.linalg.norm(v)


def test_object_space_bump_and_displacement_node():
    """BUMP_NORMAL_OBJECT is the bump worked out in object space (normal by M^T, steps by
    M^-1, the result back by M^-T), DISP_OBJECT_VECTOR the Displacement node's
    M normalize(M^T n) h; with the identity they are the world-space ones."""
    from engine.nodes import bump as B
    m = matrix(scale=(2.0, 0.5, 1.5), angle=0.4)
    hit, n = _hit_with_object(m)
    a3 = m[:3, :3]
    dx = hit[0, C.H_DX + C.H_P:C.H_DX + C.H_P + 3]
    dy = hit[0, C.H_DY + C.H_P:C.H_DY + C.H_P + 3]
    no = a3.T @ n
    bent_o = _bent_by_formula(np.linalg.solve(a3, dx), np.linalg.solve(a3, dy),
                              no / np.linalg.norm(no))
    want = np.linalg.inv(a3).T @ bent_o
    np.testing.assert_allclose(_bump_program(B.BUMP_NORMAL_OBJECT, hit),
                               want / np.linalg.norm(want), atol=1e-9)
    np.testing.assert_allclose(_bump_program(B.DISP_OBJECT_VECTOR, hit),
                               a3 @ (no / np.linalg.norm(no)) * 0.7, atol=1e-12)
    world = _bump_program(B.BUMP_NORMAL, hit)
    np.testing.assert_allclose(world, _bent_by_formula(dx, dy, n), atol=1e-9)
    assert np.abs(world - _bump_program(B.BUMP_NORMAL_OBJECT, hit)).max() > 1e-3
    plain, _ = _hit_with_object(np.eye(4))
    np.testing.assert_allclose(_bump_program(B.BUMP_NORMAL_OBJECT, plain),
                               _bump_program(B.BUMP_NORMAL, plain), atol=1e-12)


def test_undisplaced_region_swaps_and_restores_the_hit():
    """DISP_ENTER part 0 puts the undisplaced position and object coordinates in the
    hit's place, part 1 the undisplaced position steps; DISP_LEAVE puts all back."""
    from engine.nodes import bump as B
    b = ProgramBuilder()
    save = b.block(C.N_UNDISPLACED)
    read = lambda col: b.emit(I.IN_HIT3, "vector", [col], varying=True)   # noqa: E731
    b.emit(B.DISP_ENTER, "float", [save, 0], varying=True)
    inside = [read(C.H_P), read(C.H_OBJECT), read(C.H_DX + C.H_P)]
    b.emit(B.DISP_ENTER, "float", [save, 1], varying=True)
    steps = [read(C.H_DX + C.H_P), read(C.H_DY + C.H_P)]
    b.emit(B.DISP_LEAVE, "float", [save], varying=True)
    after = [read(C.H_P), read(C.H_OBJECT), read(C.H_DX + C.H_P), read(C.H_DY + C.H_P)]
    prog = b.build()
    hit, _ = _hit_with_object(np.eye(4))
    hit[0, C.H_P:C.H_P + 3] = [1.0, 2.0, 3.0]
    hit[0, C.H_OBJECT:C.H_OBJECT + 3] = [4.0, 5.0, 6.0]
    und = 100.0 + np.arange(C.N_UNDISPLACED)
    hit[0, C.H_UNDISPLACED:C.H_UNDISPLACED + C.N_UNDISPLACED] = und
    got = lambda v: prog.evaluate(v, hit)[0]                                # noqa: E731
    np.testing.assert_array_equal(got(inside[0]), und[0:3])
    np.testing.assert_array_equal(got(inside[1]), und[3:6])
    np.testing.assert_array_equal(got(inside[2]), hit[0, C.H_DX + C.H_P:C.H_DX + C.H_P + 3])
    np.testing.assert_array_equal(got(steps[0]), und[6:9])
    np.testing.assert_array_equal(got(steps[1]), und[9:12])
    for v, col in zip(after, (C.H_P, C.H_OBJECT, C.H_DX + C.H_P, C.H_DY + C.H_P)):
        np.testing.assert_array_equal(got(v), hit[0, col:col + 3])


def test_flat_faces_bumped_after_displacement_take_the_vertex_normals():
    """Displacement and Bump on flat faces: those faces' corners take the undisplaced
    vertex normals (Cycles bumps from them); other flat faces keep their moved face
    normal; nothing changes where no flat face was so moved."""
    pos, tris, _, normals = grid(n=2)
    moved = pos + np.column_stack([np.zeros((len(pos), 2)), 0.3 * pos[:, 0] ** 2])
    kept = np.array([True, True, False, False, True, False, False, False])
    smooth = np.zeros(len(tris), bool)
    out = D.bumped_from_vertex_normals(moved, tris, kept, None, smooth, normals * 2.0)
    face = D.face_normals(moved, tris)
    for t in range(len(tris)):
        want = np.tile([0.0, 0.0, 1.0], (3, 1)) if kept[t] else np.tile(face[t], (3, 1))
        np.testing.assert_allclose(out[t], want, atol=1e-6)
    assert D.bumped_from_vertex_normals(moved, tris, kept, None, ~smooth, normals) is None
