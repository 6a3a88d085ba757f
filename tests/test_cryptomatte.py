"""Cryptomatte (engine.cryptomatte, written by drt_addon.render_engine): the hash and its
float form against the reference values, the ranking of coverage, and mattes picked by
Blender's own Cryptomatte node from DRT's passes and metadata against the same node on
Cycles' passes."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import render_current
from engine.cryptomatte import hash_to_float, layer_key, manifest, murmur3_32, ranked


def test_murmur3_reference_values():
    """MurmurHash3_x86_32, seed 0, against the reference implementation's values."""
    assert murmur3_32(b"") == 0
    assert murmur3_32(b"hello") == 0x248BFA47
    assert murmur3_32(b"The quick brown fox jumps over the lazy dog") == 0x2E4FF723
    assert murmur3_32(b"hello", seed=1) != murmur3_32(b"hello")


def test_hash_to_float_keeps_ids_finite_and_normal():
    """The float id is the hash's own bits, but for an exponent of 0 or 255 (denormals,
    infinities, NaNs), which is clamped to 1 or 254."""
    h = murmur3_32(b"Cube")
    assert np.array([hash_to_float(h)], np.float32).view(np.uint32)[0] == h or \
        ((h >> 23) & 0xFF) in (0, 255)
    for h in (0, 0x7F800000, 0xFFFFFFFF, 0x00000001, 0x80000000):
        f = hash_to_float(h)
        assert np.isfinite(f) and (f == 0 or abs(f) >= np.finfo(np.float32).tiny), hex(h)
        bits = int(np.array([f], np.float32).view(np.uint32)[0])
        assert bits & 0x807FFFFF == h & 0x807FFFFF          # sign and mantissa kept
    assert layer_key("ViewLayer.CryptoObject").startswith("cryptomatte/")
    assert len(layer_key("ViewLayer.CryptoObject")) == len("cryptomatte/") + 7
    assert manifest(["b", "a", "a"]) == '{"a":"%08x","b":"%08x"}' % (
        murmur3_32(b"a"), murmur3_32(b"b"))


def test_ranking_keeps_the_largest_coverage_first():
    a, b, c = (np.float32(x) for x in (1.5, -2.25, 3.0))
    pixel = np.array([0, 0, 0, 1, 1, 1, 1, 2])
    ids = np.array([b, a, a, c, c, a, b], np.float32)
    ids = np.append(ids, c)
    out_id, out_cov = ranked(pixel, ids, 4, 4, 2)
    np.testing.assert_array_equal(out_id[0], [a, b])
    np.testing.assert_allclose(out_cov[0], [0.5, 0.25])
    # a tie (a and b a quarter each) ranks by the ids' bits: a's are the smaller
    np.testing.assert_array_equal(out_id[1], [c, a])
    np.testing.assert_allclose(out_cov[1], [0.5, 0.25])
    np.testing.assert_allclose(out_cov[2], [0.25, 0.0])
    np.testing.assert_array_equal(out_cov[3], [0.0, 0.0])     # nothing hit


W, H = 48, 32


def _scene(bpy, engine):
    """A grey plane with three cubes: CubeA (material Red), CubeB (Blue), and a linked
    duplicate Dup, Dup.001 (Blue: one instanced mesh of two places in DRT)."""
    from mathutils import Vector
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.render.resolution_percentage = 100
    scene.render.engine = engine
    scene.cycles.samples = scene.drt.samples = 16
    mats = {}
    for name, color in (("Grey", (0.5, 0.5, 0.5)), ("Red", (0.8, 0.1, 0.1)),
                        ("Blue", (0.1, 0.1, 0.8))):
        mats[name] = bpy.data.materials.new(name)
        mats[name].diffuse_color = (*color, 1.0)
    bpy.ops.mesh.primitive_plane_add(size=10.0)
    bpy.context.object.data.materials.append(mats["Grey"])
    for name, loc, mat in (("CubeA", (-1.2, 0.0, 0.5), "Red"), ("CubeB", (0.2, 0.6, 0.5), "Blue"),
                           ("Dup", (1.4, -0.4, 0.4), "Blue")):
        bpy.ops.mesh.primitive_cube_add(size=0.8, location=loc)
        bpy.context.object.name = name
        bpy.context.object.data.materials.append(mats[mat])
    dup = bpy.data.objects.new("Dup.001", bpy.data.objects["Dup"].data)
    dup.location = (0.6, -1.3, 0.4)
    scene.collection.objects.link(dup)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, -6.0, 4.0)
    cam.rotation_euler = (Vector((0.0, 0.0, 0.3)) - cam.location).to_track_quat(
        "-Z", "Y").to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    vl = scene.view_layers[0]
    vl.use_pass_cryptomatte_object = vl.use_pass_cryptomatte_material = True
    bpy.context.view_layer.update()
    return scene


def _matte(bpy, scene, layer, names):
    """Blender's Cryptomatte node on the render: the matte of `names` in `layer`."""
    tree = bpy.data.node_groups.new("Comp", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    rl = tree.nodes.new("CompositorNodeRLayers")
    rl.scene = scene
    crypto = tree.nodes.new("CompositorNodeCryptomatteV2")
    crypto.source = "RENDER"
    crypto.scene = scene
    crypto.layer_name = f"ViewLayer.{layer}"
    crypto.matte_id = ",".join(names)
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(rl.outputs["Image"], crypto.inputs["Image"])
    tree.links.new(crypto.outputs["Matte"], out.inputs[0])
    scene.compositing_node_group = tree
    scene.render.use_compositing = True
    return render_current(bpy, scene)[..., 0]


@pytest.fixture(scope="module")
def mattes(bpy_drt):
    bpy = bpy_drt
    out = {}
    for engine in ("CYCLES", "DRT"):
        for layer, names in (("CryptoObject", ("CubeA",)), ("CryptoObject", ("Dup.001",)),
                             ("CryptoMaterial", ("Blue",)), ("CryptoObject", ("CubeB",))):
            scene = _scene(bpy, engine)
            out[engine, layer, names] = _matte(bpy, scene, layer, names)
    from drt_addon import render_engine
    return out, render_engine.last_render


@pytest.mark.parametrize("layer,names", [("CryptoObject", ("CubeA",)),
                                         ("CryptoObject", ("Dup.001",)),
                                         ("CryptoMaterial", ("Blue",))])
def test_blenders_cryptomatte_node_picks_the_same_matte_from_drt(mattes, layer, names):
    """CubeA, one of the two places of an instanced mesh (Dup.001), and a material:
    measured mean differences 0.0015, 0.0017 and 0.0043 (2-3 % of the matte's mean: its
    edges, where 16 samples of either engine split a pixel differently), no pixel off by
    more than 0.5; the control, CubeB's matte, is off by the whole matte."""
    images, _ = mattes
    cycles, drt = images["CYCLES", layer, names], images["DRT", layer, names]
    assert 0.01 < cycles.mean() < 0.3, (layer, names, cycles.mean())
    diff = np.abs(drt - cycles)
    print(f"{layer} {names}: matte {cycles.mean():.3f} of the image, mean difference "
          f"{diff.mean():.4f}, pixels off by more than 0.5: {(diff > 0.5).mean():.2%}")
    assert diff.mean() < 0.1 * cycles.mean() and (diff > 0.5).mean() < 0.01
    other = images["CYCLES", "CryptoObject", ("CubeB",)]       # the control
    assert np.abs(drt - other).mean() > 0.5 * cycles.mean()


def test_passes_and_manifest_are_written(mattes):
    _, last = mattes
    assert set(last["passes"]) >= {f"CryptoObject0{i}" for i in range(3)} | {
        f"CryptoMaterial0{i}" for i in range(3)}
    fields = last["metadata"]
    key = layer_key("ViewLayer.CryptoObject")
    assert fields[f"{key}/name"] == "ViewLayer.CryptoObject"
    assert fields[f"{key}/hash"] == "MurmurHash3_32"
    assert '"Dup.001":"%08x"' % murmur3_32(b"Dup.001") in fields[f"{key}/manifest"]
    rgba = last["passes"]["CryptoObject00"]
    assert rgba.shape == (H, W, 4) and (rgba[..., 1] >= rgba[..., 3]).all()
    total = sum(last["passes"][f"CryptoObject0{i}"][..., c] for i in range(3) for c in (1, 3))
    # each pixel's names cover the share of its 16 samples that hit something: all of
    # them on the plane, fewer where the sky shows
    assert (total <= 1.0 + 1e-6).all() and (total == 1.0).mean() > 0.5
    np.testing.assert_allclose(total * 16, np.round(total * 16), atol=1e-5)
