"""The world exporter (drt_addon/export/world.py): Background colour, Environment
Texture (image, colour space, interpolation, projection), Mapping node, Ray Visibility,
and a clear warning (never a crash) for what it does not model."""
import math

import numpy as np
import pytest

from drt_addon.export.errors import Reporter
from drt_addon.export.world import export_world

SIZE = (16, 8)


def _world(bpy, name="World"):
    world = bpy.data.worlds.new(name)
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.2, 0.3, 0.4, 1.0)
    bg.inputs["Strength"].default_value = 2.0
    return world, bg


def _image(bpy, name, float_buffer=True, colorspace=None):
    w, h = SIZE
    img = bpy.data.images.new(name, w, h, float_buffer=float_buffer)
    px = np.random.default_rng(0).random((h, w, 4)).astype(np.float32)
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    if colorspace:
        img.colorspace_settings.name = colorspace
    return img


def _environment(bpy, world, bg, image, **settings):
    tree = world.node_tree
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = image
    for k, v in settings.items():
        setattr(env, k, v)
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    return env


def _export(world):
    reporter = Reporter()
    return export_world(world, reporter), reporter.warnings


def test_uniform_background_and_visibility(bpy_drt):
    world, _ = _world(bpy_drt)
    world.cycles_visibility.camera = False
    world.cycles_visibility.glossy = False
    w, warnings = _export(world)
    assert w.texture is None and not warnings
    np.testing.assert_allclose(w.color, (0.4, 0.6, 0.8))
    assert w.visibility == 31 & ~1 & ~4


def test_float_environment_texture_with_strength(bpy_drt):
    world, bg = _world(bpy_drt)
    img = _image(bpy_drt, "hdr")
    _environment(bpy_drt, world, bg, img, interpolation="Closest")
    w, warnings = _export(world)
    assert not warnings
    tex = w.texture
    assert (tex.width, tex.height) == SIZE and tex.extension == "REPEAT"
    assert tex.interpolation == "Closest" and not tex.srgb
    px = np.empty(SIZE[0] * SIZE[1] * 4, np.float32)
    img.pixels.foreach_get(px)
    np.testing.assert_array_equal(tex.pixels.reshape(-1), px)
    assert w.strength == (2.0, 2.0, 2.0) and w.mapping is None


@pytest.mark.parametrize("colorspace,srgb", [("sRGB", True), ("Non-Color", False)])
def test_byte_image_colour_space(bpy_drt, colorspace, srgb):
    world, bg = _world(bpy_drt)
    _environment(bpy_drt, world, bg, _image(bpy_drt, "ldr" + colorspace, False, colorspace))
    w, warnings = _export(world)
    assert w.texture.srgb is srgb and not warnings


def _mapping(bpy, world, env, vector_type="POINT", rotation=(0.0, 0.0, 0.0),
             scale=(1.0, 1.0, 1.0), location=(0.0, 0.0, 0.0), coords="Generated"):
    tree = world.node_tree
    m = tree.nodes.new("ShaderNodeMapping")
    m.vector_type = vector_type
    m.inputs["Rotation"].default_value = rotation
    m.inputs["Scale"].default_value = scale
    if "Location" in m.inputs and m.inputs["Location"].enabled:
        m.inputs["Location"].default_value = location
    tree.links.new(m.outputs["Vector"], env.inputs["Vector"])
    if coords:
        tc = tree.nodes.new("ShaderNodeTexCoord")
        tree.links.new(tc.outputs[coords], m.inputs["Vector"])
    return m


@pytest.mark.parametrize("vector_type", ["POINT", "VECTOR", "TEXTURE", "NORMAL"])
def test_mapping_node_matrix(bpy_drt, vector_type):
    """Blender's Mapping node on a direction, as the matrix the engine applies."""
    from mathutils import Euler
    world, bg = _world(bpy_drt)
    env = _environment(bpy_drt, world, bg, _image(bpy_drt, "m" + vector_type))
    rot, scale = (0.3, -0.5, 1.2), (1.0, 2.0, 0.5)
    _mapping(bpy_drt, world, env, vector_type, rot, scale)
    w, warnings = _export(world)
    assert not warnings
    r = np.array(Euler(rot, "XYZ").to_matrix())
    s = np.diag(scale)
    expected = {"POINT": r @ s, "VECTOR": r @ s, "TEXTURE": np.linalg.inv(s) @ r.T,
                "NORMAL": r @ np.linalg.inv(s)}[vector_type]
    np.testing.assert_allclose(w.mapping, expected, atol=1e-6)


def test_mapping_translation_and_zero_scale_are_reported(bpy_drt):
    world, bg = _world(bpy_drt)
    env = _environment(bpy_drt, world, bg, _image(bpy_drt, "t"))
    m = _mapping(bpy_drt, world, env, rotation=(0, 0, math.radians(30)),
                 location=(1.0, 0.0, 0.0), coords="Object")
    w, warnings = _export(world)
    assert len(warnings) == 1 and "Location" in warnings[0] and "World" in warnings[0]
    assert w.mapping is not None and w.texture is not None
    m.inputs["Scale"].default_value = (1.0, 0.0, 1.0)
    w, warnings = _export(world)
    assert any("zero scale" in t for t in warnings) and w.mapping is None


def test_unsupported_inputs_warn_and_fall_back(bpy_drt):
    world, bg = _world(bpy_drt)
    tree = world.node_tree
    # mirror ball: not modelled, the Background's own colour
    env = _environment(bpy_drt, world, bg, _image(bpy_drt, "ball"), projection="MIRROR_BALL")
    w, warnings = _export(world)
    assert w.texture is None and "MIRROR_BALL" in warnings[0]
    np.testing.assert_allclose(w.color, (0.4, 0.6, 0.8))
    # an unsupported vector source: the image is kept, the vector ignored
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    env.projection = "EQUIRECTANGULAR"
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Color"], env.inputs["Vector"])
    w, warnings = _export(world)
    assert w.texture is not None and w.mapping is None
    assert any("Noise" in t for t in warnings)


def test_a_node_graph_on_the_background_is_baked_into_a_map(bpy_drt):
    """A Gradient texture (Linear, of the Generated coordinates: for the world, the ray's
    direction) on the Background's Color, and a Value node on its Strength: the world is
    an environment map whose texel along direction d is clamp(d.x, 0, 1) x strength, at
    World > Settings > Map Resolution across; nothing is reported."""
    from engine.environment_map import uv_to_direction
    world, bg = _world(bpy_drt)
    world.cycles.sample_map_resolution = 64
    tree = world.node_tree
    gradient = tree.nodes.new("ShaderNodeTexGradient")
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Generated"], gradient.inputs["Vector"])
    tree.links.new(gradient.outputs["Color"], bg.inputs["Color"])
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 3.0
    tree.links.new(value.outputs[0], bg.inputs["Strength"])
    w, warnings = _export(world)
    assert not warnings and w.texture is not None
    px = w.texture.pixels
    h, wd = px.shape[:2]
    assert (wd, h) == (64, 32)
    u, v = np.meshgrid((np.arange(wd) + 0.5) / wd, (np.arange(h) + 0.5) / h)
    d, _ = uv_to_direction(np.stack([u.ravel(), v.ravel()], 1))
    expected = 3.0 * np.clip(d[:, 0], 0.0, 1.0)
    for ch in range(3):
        np.testing.assert_allclose(px[..., ch].ravel(), expected, atol=1e-5)


@pytest.mark.parametrize("output,camera,reported", [
    ("Is Camera Ray", True, False), ("Is Glossy Ray", False, True), (None, False, False)])
def test_a_light_path_node_bakes_what_the_camera_sees_apart(bpy_drt, output, camera,
                                                            reported):
    """Mix(red, blue) by a Light Path output on the Background's Color: with Is Camera Ray
    the lighting map is red (as diffuse rays see it) and the camera's own map blue; an
    output that tells other kinds of rays apart is read as for diffuse rays, and
    reported; with no Light Path node there is one map."""
    world, bg = _world(bpy_drt)
    world.cycles.sample_map_resolution = 64
    bg.inputs["Strength"].default_value = 1.0
    tree = world.node_tree
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.inputs["A"].default_value = (1.0, 0.0, 0.0, 1.0)
    mix.inputs["B"].default_value = (0.0, 0.0, 1.0, 1.0)
    if output is not None:
        path = tree.nodes.new("ShaderNodeLightPath")
        tree.links.new(path.outputs[output], mix.inputs["Factor"])
    else:
        mix.inputs["Factor"].default_value = 0.0
    tree.links.new(mix.outputs["Result"], bg.inputs["Color"])
    w, warnings = _export(world)
    assert w.texture is not None
    np.testing.assert_allclose(w.texture.pixels[..., :3].reshape(-1, 3).mean(0),
                               (1.0, 0.0, 0.0), atol=1e-6)
    assert (w.camera_texture is not None) == camera
    if camera:
        np.testing.assert_allclose(w.camera_texture.pixels[..., :3].reshape(-1, 3).mean(0),
                                   (0.0, 0.0, 1.0), atol=1e-6)
    assert bool(warnings) == reported
    if reported:
        assert "Is Glossy Ray" in warnings[0]


def test_missing_image_is_pink_like_cycles(bpy_drt):
    world, bg = _world(bpy_drt)
    _environment(bpy_drt, world, bg, None)
    w, warnings = _export(world)
    assert w.texture is None and not warnings
    np.testing.assert_allclose(w.color, (2.0, 0.0, 2.0))
    img = bpy_drt.data.images.new("gone", 4, 4)
    img.source = "FILE"
    img.filepath = "/nonexistent/sky.exr"          # a file that is not there
    world.node_tree.nodes["Environment Texture"].image = img
    w, warnings = _export(world)
    assert w.texture is None and any("no pixels" in t for t in warnings)
    np.testing.assert_allclose(w.color, (2.0, 0.0, 2.0))


def _sky(bpy, **settings):
    world, bg = _world(bpy, "Sky")
    sky = world.node_tree.nodes.new("ShaderNodeTexSky")
    for k, v in settings.items():
        setattr(sky, k, v)
    world.node_tree.links.new(sky.outputs["Color"], bg.inputs["Color"])
    return world, bg, sky


def test_sky_texture_becomes_a_map_and_a_sun(bpy_drt):
    """The default sky: an equirectangular map times the Strength (2) and a sun lamp
    along +Y, 15 degrees up, of the node's size, seen as the world is."""
    world, bg, sky = _sky(bpy_drt)
    world.cycles_visibility.glossy = False
    w, warnings = _export(world)
    assert not warnings and w.texture is not None and w.mapping is None
    assert w.strength == (2.0, 2.0, 2.0)
    sun = w.sun
    e = math.radians(15.0)
    np.testing.assert_allclose(sun.direction, (0.0, -math.cos(e), -math.sin(e)), atol=1e-6)
    assert sun.angle == pytest.approx(sky.sun_size)
    assert sun.visibility == 31 & ~4          # glossy off, shadows always cast
    bg.inputs["Strength"].default_value = 1.0
    one, _ = _export(world)
    np.testing.assert_allclose(np.asarray(sun.strength), 2.0 * np.asarray(one.sun.strength))
    # no disc, no lamp
    sky.sun_disc = False
    assert _export(world)[0].sun is None


def test_sky_texture_vector(bpy_drt):
    """A Mapping node on the Vector turns a Preetham sky; Blender 5.0 makes the socket
    unavailable on the physical skies (Cycles never reads it), so there it is ignored
    and the sun stays put."""
    world, bg, sky = _sky(bpy_drt, sky_type="PREETHAM")
    tree = world.node_tree
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90.0))
    coords = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], sky.inputs[0])
    w, warnings = _export(world)
    assert not warnings and w.mapping is not None and w.sun is None
    np.testing.assert_allclose(w.mapping @ (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), atol=1e-6)
    sky.sky_type = "MULTIPLE_SCATTERING"
    assert not sky.inputs[0].enabled
    w, warnings = _export(world)
    assert not warnings and w.mapping is None
    e = math.radians(15.0)
    np.testing.assert_allclose(w.sun.direction, (0.0, -math.cos(e), -math.sin(e)), atol=1e-6)


def test_unmodelled_sky_types_are_reported(bpy_drt):
    world, bg, sky = _sky(bpy_drt, sky_type="HOSEK_WILKIE")
    w, warnings = _export(world)
    assert w.texture is None and w.sun is None and "Hosek" in warnings[0]
    np.testing.assert_allclose(w.color, (0.4, 0.6, 0.8))
    sky.sky_type = "SINGLE_SCATTERING"
    w, warnings = _export(world)
    assert w.texture is not None and "Single Scattering" in warnings[0]
    sky.sky_type = "PREETHAM"
    w, warnings = _export(world)
    assert w.texture is not None and w.sun is None and not warnings


def test_sampling_method_none_keeps_the_world_from_being_a_light(bpy_drt):
    """World > Settings > Sampling Method: Auto samples a world that varies over
    directions as a light, None does not (escaping rays alone find it, as in Cycles)."""
    from engine.kernels.lights import is_uniform_world, pack_lights
    from engine.lights import LightSet
    world, bg = _world(bpy_drt, "sampled")
    _environment(bpy_drt, world, bg, _image(bpy_drt, "hdr_sampled"))
    lit = _export(world)[0]
    world.cycles.sampling_method = "NONE"
    unlit = _export(world)[0]
    assert lit.light_sampling and not unlit.light_sampling
    lights = LightSet([], 10.0, world=lit)
    assert lights.env_index is not None
    assert not is_uniform_world(pack_lights(lights), lights.env_index)
    assert LightSet([], 10.0, world=unlit).env_index is None
    assert LightSet([], 10.0, world=unlit).world is not None       # still seen by rays


def _linked(world, bg, kind, output=0, vector=None):
    tree = world.node_tree
    node = tree.nodes.new(kind)
    if vector is not None:
        tree.links.new(vector, node.inputs["Vector"])
    tree.links.new(node.outputs[output], bg.inputs["Color"])
    return node


@pytest.mark.parametrize("build, sampled", [
    ("plain", False),                  # one colour: Cycles never samples it
    ("no_nodes", False),
    ("value", False),                  # an RGB node: still one colour
    ("light_path", False),             # Is Camera Ray mixing two colours
    ("noise", True),                   # a texture on its default coordinates
    ("noise_on_constant", False),      # a texture whose Vector is a constant
    ("gradient_in_group", True),       # the same, inside a node group
    ("texture_coordinate", True),      # the direction itself
    ("layer_weight", True),
])
def test_only_a_world_that_varies_over_directions_is_sampled_as_a_light(bpy_drt, build,
                                                                        sampled):
    """Cycles samples the world as a light only when its surface varies over directions
    (Shader::has_surface_spatial_varying: a texture on its own coordinates, a Texture
    Coordinate, Geometry, Layer Weight ... node compiled into it); a world of one colour
    is found by escaping rays alone, so a Light Path trick that tells shadow rays apart
    lets its light in only through the rays that pass (test_shadow_ray_glass_vs_cycles).
    The exporter decides as Cycles does, and the light set then has no world entry."""
    from engine.lights import LightSet
    world, bg = _world(bpy_drt, build)
    tree = world.node_tree
    if build == "no_nodes":
        world.use_nodes = False
    elif build == "value":
        _linked(world, bg, "ShaderNodeRGB")
    elif build == "light_path":
        mix = _linked(world, bg, "ShaderNodeMix", output=2)
        mix.data_type = "RGBA"
        tree.links.new(tree.nodes.new("ShaderNodeLightPath").outputs["Is Camera Ray"],
                       mix.inputs["Factor"])
    elif build == "noise":
        _linked(world, bg, "ShaderNodeTexNoise", output="Color")
    elif build == "noise_on_constant":
        xyz = tree.nodes.new("ShaderNodeCombineXYZ")
        _linked(world, bg, "ShaderNodeTexNoise", output="Color", vector=xyz.outputs[0])
    elif build == "gradient_in_group":
        group = bpy_drt.data.node_groups.new("Sky", "ShaderNodeTree")
        group.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
        out = group.nodes.new("NodeGroupOutput")
        gradient = group.nodes.new("ShaderNodeTexGradient")
        group.links.new(gradient.outputs["Color"], out.inputs[0])
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        tree.links.new(node.outputs[0], bg.inputs["Color"])
    elif build == "texture_coordinate":
        _linked(world, bg, "ShaderNodeTexCoord", output="Generated")
    elif build == "layer_weight":
        _linked(world, bg, "ShaderNodeLayerWeight", output="Facing")
    exported = _export(world)[0]
    assert exported.light_sampling == sampled
    assert (LightSet([], 10.0, world=exported).env_index is not None) == sampled
