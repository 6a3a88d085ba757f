"""Emissive triangles duplicated in place are one light (engine.mesh_lights).

Artists' files hold emissive meshes copied onto themselves: the public
`neon_tree_experiment.blend` holds 48,096 such pairs among its 96,192 emissive triangles.
A shadow ray towards one copy passes the other, so lighting each copy apart adds every
copy's light in next-event estimation, while a BSDF ray sees one surface: that file
rendered 0.5 % too bright with the light tree, and the merged entries fix it. Checked
here: copies (in any corner order and winding, and -0.0 for 0.0) share an entry, copies of
another radiance do not, and a floor under a lamp of two coincident copies gets the same
light from next-event estimation (MIS with the light tree and without it) as from BSDF rays
alone, which an unmerged light set fails (the control)."""
from __future__ import annotations

import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, TriangleMesh, World
from engine import mesh_lights
from engine.mesh_lights import EmissiveTriangles
from engine_scenes import look_at, quad
from test_path_estimators import _agree, _image_mean


def test_copies_in_any_corner_order_share_one_entry():
    a, b, c, d = [0.0, 0, 0], [1.0, 0, 0], [0.0, 1, 0], [0.0, -0.0, 1]
    v0 = [a, b, c, [0.0, 0, -0.0], a, a]
    v1 = [b, c, a, c, b, b]
    v2 = [c, a, b, b, c, d]
    radiance = [[1, 2, 3]] * 4 + [[3, 2, 1], [1, 2, 3]]
    m = EmissiveTriangles(v0, v1, v2, radiance, [4, 9, 1, 7, 3, 0], 12)
    assert len(m) == 3
    np.testing.assert_array_equal(m.prim, [4, 3, 0])           # the first of each set
    np.testing.assert_array_equal(m.entry_of([4, 9, 1, 7, 3, 0, 2, 11, -1]),
                                  [0, 0, 0, 0, 1, 2, -1, -1, -1])
    np.testing.assert_allclose(m.area, [0.5, 0.5, 0.5])
    np.testing.assert_allclose(m.power, np.pi * 0.5 * m.radiance @ [0.2126, 0.7152, 0.0722],
                               rtol=1e-3)


def _lamp_of_two_copies():
    """A grey floor under a 0.6 m square emitter, facing down at 1 m, stored twice: the
    second copy with the opposite winding, as a zero-thickness Solidify makes it."""
    lamp = quad((0, 0, 1), (0.0, 0.3, 0), (0.3, 0, 0), "lamp", 1)
    flipped = TriangleMesh("lamp copy", lamp.positions.copy(), lamp.triangles[:, ::-1].copy(),
                           lamp.material_indices.copy())
    floor = quad((0, 0, 0), (2, 0, 0), (0, 2, 0), "floor", 0)
    cam = Camera(look_at((0, -2.5, 2.0), (0, 0, 0.2)), lens=35.0)
    mats = [Material("grey", (0.5, 0.5, 0.5), specular_ior_level=0.0),
            Material("glow", (0, 0, 0), emission=(5.0, 4.0, 3.0))]
    return Scene(cam, 16, 12, [floor, lamp, flipped], mats, [], World((0, 0, 0)))


@pytest.mark.parametrize("tree", [True, False], ids=["light tree", "tree off"])
def test_next_event_estimation_counts_coincident_copies_once(tree, monkeypatch):
    scene = _lamp_of_two_copies()
    bsdf = _image_mean(scene, "bsdf", 256)
    mis = _image_mean(scene, "mis", 256, light_tree=tree)
    print("bsdf", bsdf[0].round(5), "mis", mis[0].round(5))
    assert bsdf[0].min() > 0.01                      # the floor is lit
    assert _agree(bsdf, mis)
    # the control: each copy its own light, next-event estimation adds both copies' light
    monkeypatch.setattr(mesh_lights, "_coincident_copies",
                        lambda v0, v1, v2, radiance: (np.arange(len(v0)), np.arange(len(v0))))
    apart = _image_mean(scene, "mis", 256, light_tree=tree)
    print("copies apart", apart[0].round(5))
    assert not _agree(bsdf, apart)
    assert np.all(apart[0] > 1.2 * bsdf[0])


def _floor_under_one_sided_emitter(sampling):
    """A grey floor lit by a 0.6 m square emitter facing down at 1 m (its triangles'
    front, where their normal points, towards the floor), its material's Emission
    Sampling `sampling`."""
    lamp = quad((0, 0, 1), (0.0, 0.3, 0), (0.3, 0, 0), "lamp", 1)
    assert np.cross(*(lamp.positions[lamp.triangles[0, 1:]]
                      - lamp.positions[lamp.triangles[0, 0]]))[2] < 0     # faces down
    floor = quad((0, 0, 0), (2, 0, 0), (0, 2, 0), "floor", 0)
    cam = Camera(look_at((0, -2.5, 2.0), (0, 0, 0.2)), lens=35.0)
    mats = [Material("grey", (0.5, 0.5, 0.5), specular_ior_level=0.0),
            Material("glow", (0, 0, 0), emission=(5.0, 4.0, 3.0),
                     emission_sampling=sampling)]
    return Scene(cam, 16, 12, [floor, lamp], mats, [], World((0, 0, 0)))


def test_emission_sampling_none_leaves_the_triangles_out_of_the_light_set():
    from engine.render import RenderContext
    for sampling, n in (("NONE", 0), ("FRONT", 2), ("BACK", 2), ("FRONT_BACK", 2)):
        ctx = RenderContext(_floor_under_one_sided_emitter(sampling),
                            RenderSettings(samples=1))
        ctx.close()
        assert len(ctx.lights.mesh if ctx.lights.mesh is not None else []) == n, \
            sampling


@pytest.mark.parametrize("tree", [True, False], ids=["light tree", "tree off"])
def test_emission_sampling_changes_noise_not_the_light(tree):
    """Material > Settings > Emission Sampling (engine.mesh_lights): whichever sides
    next-event estimation samples, the floor gets the light BSDF rays alone find (a side
    not sampled weighs its hits 1). Sampling the side that faces the floor (Front, here)
    cuts the noise; sampling only the other side (Back) or none leaves BSDF rays alone,
    as noisy as BSDF sampling: which side is the front is checked by that."""
    scene = _floor_under_one_sided_emitter("FRONT_BACK")
    bsdf = _image_mean(scene, "bsdf", 256)
    assert bsdf[0].min() > 0.01
    errors = {}
    for sampling in ("FRONT_BACK", "FRONT", "BACK", "NONE"):
        mis = _image_mean(_floor_under_one_sided_emitter(sampling), "mis", 256,
                          light_tree=tree)
        print(sampling, mis[0].round(5), "se", mis[1].round(5), "bsdf", bsdf[0].round(5),
              "se", bsdf[1].round(5))
        assert _agree(bsdf, mis), sampling
        errors[sampling] = mis[1].mean()
    assert errors["FRONT"] < 0.5 * errors["BACK"]
    assert errors["FRONT_BACK"] < 0.5 * errors["NONE"]
    assert errors["BACK"] > 0.7 * bsdf[1].mean() and errors["NONE"] > 0.7 * bsdf[1].mean()
