"""Bump and the camera's texture coordinates, the node_probe way (tests/
test_nodes_vs_cycles.py): each case shows a vector (the bent normal, Camera, Window) as an
emission colour, 0.5 + scale x vector. The probe's camera is orthographic, so the bump's
offsets are a fixed fraction of a pixel (Filter Width x the pixel size); on the spheres
the steps follow the curved surface."""
from __future__ import annotations

from node_cases import checker_normal_map, ident


def _shown(nt, p, socket, scale=0.5):
    vm = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    nt.links.new(socket, vm.inputs[0])
    vm.inputs[1].default_value = (scale,) * 3
    vm.inputs[2].default_value = (0.5, 0.5, 0.5)
    return vm.outputs[0]


def _height(nt, p, kind, coords="Generated", scale=4.0):
    """A height texture's Fac (or Geometry Position / a colour attribute's Fac)."""
    if kind == "attribute":
        mesh = p.obj.data
        attr = mesh.color_attributes.new("Height", "FLOAT_COLOR", "POINT")
        for k, item in enumerate(attr.data):
            item.color = ((0.0, 0.3, 1.0, 0.6)[k % 4],) * 3 + (1.0,)
        return p.node(nt, "ShaderNodeAttribute", attribute_name="Height").outputs["Fac"]
    t = p.node(nt, {"noise": "ShaderNodeTexNoise", "checker": "ShaderNodeTexChecker",
                    "wave": "ShaderNodeTexWave"}[kind])
    t.inputs["Scale"].default_value = scale
    if coords == "Position":
        socket = p.node(nt, "ShaderNodeNewGeometry").outputs["Position"]
    else:
        socket = p.coords(nt).outputs[coords]
    nt.links.new(socket, t.inputs["Vector"])
    return t.outputs["Fac"]


def _bump(nt, p, height, strength=1.0, distance=0.5, width=None, invert=False, normal=None):
    b = p.node(nt, "ShaderNodeBump", invert=invert)
    b.inputs["Strength"].default_value = strength
    b.inputs["Distance"].default_value = distance
    if width is not None:
        b.inputs["Filter Width"].default_value = width
    nt.links.new(height, b.inputs["Height"])
    if normal is not None:
        nt.links.new(normal, b.inputs["Normal"])
    return b.outputs["Normal"]


def bump_case(kind, coords="Generated", scale=4.0, rotate=False, **bump):
    def build(nt, p):
        if rotate:
            p.obj.rotation_euler = (0.0, 0.0, 0.5)
        return _shown(nt, p, _bump(nt, p, _height(nt, p, kind, coords, scale), **bump))
    return build


def _chained(nt, p):
    """Bump -> Normal of a second Bump."""
    inner = _bump(nt, p, _height(nt, p, "wave", "UV", 2.0), distance=0.3)
    return _shown(nt, p, _bump(nt, p, _height(nt, p, "noise"), normal=inner))


def _normal_map_into_bump(nt, p):
    """Normal Map -> Normal of a Bump."""
    normal = checker_normal_map(nt, p)
    return _shown(nt, p, _bump(nt, p, _height(nt, p, "noise"), normal=normal))


def _through_math(nt, p):
    """The height through Math nodes (each evaluated three times)."""
    m = p.node(nt, "ShaderNodeMath", operation="SINE")
    nt.links.new(_height(nt, p, "noise", "Object", 3.0), m.inputs[0])
    m2 = p.node(nt, "ShaderNodeMath", operation="MULTIPLY")
    nt.links.new(m.outputs[0], m2.inputs[0])
    m2.inputs[1].default_value = 4.0
    return _shown(nt, p, _bump(nt, p, m2.outputs[0], distance=0.2))


def _coords(name, scale):
    def build(nt, p):
        p.obj.rotation_euler = (0.3, 0.0, 0.4)
        return _shown(nt, p, p.coords(nt).outputs[name], scale)
    return build


def _depth(name):
    """A Light Path depth as the factor of a red/green mix (0 on camera rays)."""
    def build(nt, p):
        lp = p.node(nt, "ShaderNodeLightPath")
        mix = p.node(nt, "ShaderNodeMix", data_type="RGBA")
        nt.links.new(lp.outputs[name], ident(mix.inputs, "Factor_Float"))
        ident(mix.inputs, "A_Color").default_value = (0.9, 0.2, 0.1, 1.0)
        ident(mix.inputs, "B_Color").default_value = (0.1, 0.7, 0.3, 1.0)
        return ident(mix.outputs, "Result_Color")
    return build


BUMP = [("bump_noise", bump_case("noise")), ("bump_checker", bump_case("checker")),
        ("bump_wave_uv", bump_case("wave", "UV", 2.0)),
        ("bump_object", bump_case("noise", "Object", 3.0, rotate=True)),
        ("bump_position", bump_case("wave", "Position", 1.5)),
        ("bump_attribute", bump_case("attribute", distance=1.0)),
        ("bump_filter_width_1", bump_case("noise", width=1.0)),
        ("bump_invert_half", bump_case("noise", invert=True, strength=0.5)),
        ("bump_chained", _chained), ("bump_normal_map", _normal_map_into_bump),
        ("bump_math", _through_math),
        ("tc_camera", _coords("Camera", 0.05)), ("tc_window", _coords("Window", 1.0))] + [
    (f"lp_{name.split()[0].lower()}_depth", _depth(name)) for name in
    ("Diffuse Depth", "Glossy Depth", "Transmission Depth", "Transparent Depth")]
BUMP_SPHERES = [("bump_sphere_noise", bump_case("noise", "Object", 3.0)),
                ("bump_sphere_checker", bump_case("checker", "UV", 8.0, distance=0.1)),
                ("tc_sphere_window", _coords("Window", 1.0))]

FAMILIES = {"bump": (BUMP, "plane"), "bump_spheres": (BUMP_SPHERES, "sphere")}
