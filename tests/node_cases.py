"""The node graphs tests/test_nodes_vs_cycles.py compares with Cycles, by family. Each
case shows its node's output as an emission colour in [0, 1] (see node_probe)."""
from __future__ import annotations

import math


def ident(sockets, identifier):
    """A socket by identifier (names repeat: Mix has an A per data type)."""
    return next(s for s in sockets if s.identifier == identifier)


def blender_enum(node_type, prop):
    """Every item of a node's enum property, as this Blender has them: the tests cover
    every operation, including ones DRT might not know."""
    import bpy
    return tuple(i.identifier for i in getattr(bpy.types, node_type).bl_rna
                 .properties[prop].enum_items)


def gen(nt, p):
    return p.coords(nt).outputs["Generated"]


def axis(nt, p, socket, k):
    sep = p.node(nt, "ShaderNodeSeparateXYZ")
    nt.links.new(socket, sep.inputs[0])
    return sep.outputs[k]


def shown(nt, p, value, scale=0.2, offset=0.5):
    """A float shown as grey offset + scale x value, clamped to [0, 1] (signs stay
    visible)."""
    m = p.node(nt, "ShaderNodeMath", operation="MULTIPLY_ADD", use_clamp=True)
    nt.links.new(value, m.inputs[0])
    m.inputs[1].default_value = scale
    m.inputs[2].default_value = offset
    return m.outputs[0]


def ramp_xy(nt, p, lo=-2.0, hi=2.0):
    """(a, b): the tile's generated x and y mapped to [lo, hi]."""
    g = gen(nt, p)
    out = []
    for k in range(2):
        mr = p.node(nt, "ShaderNodeMapRange")
        nt.links.new(axis(nt, p, g, k), mr.inputs["Value"])
        mr.inputs["To Min"].default_value = lo
        mr.inputs["To Max"].default_value = hi
        out.append(mr.outputs[0])
    return out


# ---------------------------------------------------------------- input
def _tex_coord(name):
    def build(nt, p):
        p.obj.rotation_euler = (0.0, 0.0, 0.4)
        p.obj.scale = (0.9, 0.8, 1.0)
        vm = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        nt.links.new(p.coords(nt).outputs[name], vm.inputs[0])
        vm.inputs[1].default_value = (0.5, 0.5, 0.5)
        vm.inputs[2].default_value = (0.5, 0.5, 0.5)
        return vm.outputs[0] if name in ("Object", "Normal") else p.coords(nt).outputs[name]
    return build


def _object_info(name):
    def build(nt, p):
        p.obj.color = (0.2, 0.6, 0.9, 1.0)
        p.obj.pass_index = 3
        info = p.node(nt, "ShaderNodeObjectInfo")
        if name == "Color":
            return info.outputs["Color"]
        if name == "Location":
            return shown(nt, p, axis(nt, p, info.outputs["Location"], 0), 0.1)
        if name == "Object Index":
            return shown(nt, p, info.outputs["Object Index"], 0.1, 0.2)
        return info.outputs["Random"]
    return build


def _fresnel(nt, p):
    f = p.node(nt, "ShaderNodeFresnel")
    f.inputs["IOR"].default_value = 1.45
    return f.outputs[0]


def _layer(name):
    def build(nt, p):
        lw = p.node(nt, "ShaderNodeLayerWeight")
        lw.inputs["Blend"].default_value = 0.3
        return lw.outputs[name]
    return build


def _geometry(name):
    def build(nt, p):
        geo = p.node(nt, "ShaderNodeNewGeometry")
        vm = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        nt.links.new(geo.outputs[name], vm.inputs[0])
        vm.inputs[1].default_value = (0.2, 0.2, 0.2) if name == "Position" else (0.5,) * 3
        vm.inputs[2].default_value = (0.5, 0.5, 0.5)
        return vm.outputs[0]
    return build


def _light_path(nt, p):
    lp = p.node(nt, "ShaderNodeLightPath")
    mix = p.node(nt, "ShaderNodeMix", data_type="RGBA")
    nt.links.new(lp.outputs["Is Camera Ray"], ident(mix.inputs, "Factor_Float"))
    ident(mix.inputs, "A_Color").default_value = (1.0, 0.0, 0.0, 1.0)
    ident(mix.inputs, "B_Color").default_value = (0.1, 0.7, 0.3, 1.0)
    return ident(mix.outputs, "Result_Color")


def checker_normal_map(nt, p, strength=1.0):
    """A tangent-space Normal Map of a UV checker of two normals; its output socket."""
    c = p.node(nt, "ShaderNodeTexChecker")
    c.inputs["Scale"].default_value = 4.0
    c.inputs["Color1"].default_value = (0.5, 0.5, 1.0, 1.0)
    c.inputs["Color2"].default_value = (0.8, 0.3, 0.85, 1.0)
    nt.links.new(p.coords(nt).outputs["UV"], c.inputs["Vector"])
    nm = p.node(nt, "ShaderNodeNormalMap")
    nm.inputs["Strength"].default_value = strength
    nt.links.new(c.outputs["Color"], nm.inputs["Color"])
    return nm.outputs[0]


def _normal_map(strength):
    def build(nt, p):
        vm = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        nt.links.new(checker_normal_map(nt, p, strength), vm.inputs[0])
        vm.inputs[1].default_value = (0.5, 0.5, 0.5)
        vm.inputs[2].default_value = (0.5, 0.5, 0.5)
        return vm.outputs[0]
    return build


def _vertex_colors(kind, domain, output):
    """A colour attribute with a colour per corner (or vertex), read by a Color Attribute
    node (kind VertexColor) or an Attribute node."""
    def build(nt, p):
        mesh = p.obj.data
        attr = mesh.color_attributes.new("Paint", "BYTE_COLOR" if domain == "CORNER"
                                         else "FLOAT_COLOR", domain)
        colors = [(0.9, 0.1, 0.1, 1.0), (0.1, 0.8, 0.2, 0.5), (0.1, 0.2, 0.9, 0.8),
                  (0.9, 0.9, 0.2, 0.3)]
        for k, item in enumerate(attr.data):
            item.color = colors[k % 4]
        if kind == "ShaderNodeVertexColor":
            n = p.node(nt, kind, layer_name="Paint")
        else:
            n = p.node(nt, kind, attribute_name="Paint")
        return n.outputs[output]
    return build


INPUT = [("tc_generated", _tex_coord("Generated")), ("tc_uv", _tex_coord("UV")),
         ("tc_object", _tex_coord("Object")),
         ("oi_color", _object_info("Color")), ("oi_location", _object_info("Location")),
         ("oi_index", _object_info("Object Index")),
         ("oi_random", _object_info("Random")),      # Cycles: a hash of the object's name
         ("light_path", _light_path),
         ("color_attribute", _vertex_colors("ShaderNodeVertexColor", "CORNER", "Color")),
         ("color_attribute_alpha", _vertex_colors("ShaderNodeVertexColor", "CORNER",
                                                  "Alpha")),
         ("attribute_point", _vertex_colors("ShaderNodeAttribute", "POINT", "Color")),
         ("attribute_fac", _vertex_colors("ShaderNodeAttribute", "POINT", "Fac"))]
INPUT_SPHERES = [("tc_normal", _tex_coord("Normal")), ("geo_normal", _geometry("Normal")),
                 ("geo_position", _geometry("Position")),
                 ("geo_true_normal", _geometry("True Normal")), ("fresnel", _fresnel),
                 ("lw_fresnel", _layer("Fresnel")), ("lw_facing", _layer("Facing")),
                 ("normal_map", _normal_map(1.0)), ("normal_map_half", _normal_map(0.5))]


# ---------------------------------------------------------------- textures
def _checker(vector=None, scale=5.0):
    def build(nt, p):
        c = p.node(nt, "ShaderNodeTexChecker")
        c.inputs["Scale"].default_value = scale
        c.inputs["Color1"].default_value = (0.9, 0.6, 0.1, 1.0)
        c.inputs["Color2"].default_value = (0.05, 0.2, 0.5, 1.0)
        if vector:
            nt.links.new(p.coords(nt).outputs[vector], c.inputs["Vector"])
        return c.outputs["Color"]
    return build


def _gradient(kind):
    def build(nt, p):
        g = p.node(nt, "ShaderNodeTexGradient", gradient_type=kind)
        if kind in ("SPHERICAL", "QUADRATIC_SPHERE", "RADIAL"):
            nt.links.new(p.coords(nt).outputs["Object"], g.inputs["Vector"])
        return g.outputs["Color"]
    return build


def _missing_image(extension, interpolation="Linear", output="Color", mix_alpha=False):
    """An Image Texture whose file is not there: Cycles samples it as a 1 x 1 pink image
    with the node's extension and interpolation (constant when repeated, a tent of
    pink fading to black at the UV square's edges when clipped); with its Alpha used too
    (`mix_alpha`: the colour times the alpha), Cycles divides the colour by the alpha,
    so the colour is pink again and only the alpha is a tent."""
    def build(nt, p):
        import bpy
        image = bpy.data.images.new("gone.png", 4, 4)  # load() refuses a missing file
        image.source, image.filepath = "FILE", "//no/such/texture.png"
        t = p.node(nt, "ShaderNodeTexImage", extension=extension,
                   interpolation=interpolation)
        t.image = image
        if not mix_alpha:
            return t.outputs[output]
        mix = p.node(nt, "ShaderNodeMix", data_type="RGBA", blend_type="MULTIPLY")
        ident(mix.inputs, "Factor_Float").default_value = 1.0
        nt.links.new(t.outputs["Color"], ident(mix.inputs, "A_Color"))
        nt.links.new(t.outputs["Alpha"], ident(mix.inputs, "B_Color"))
        return ident(mix.outputs, "Result_Color")
    return build


TEXTURE = [("checker", _checker()), ("checker_uv", _checker("UV", 3.0)),
           ("checker_fac", lambda nt, p: _checker()(nt, p).node.outputs["Fac"])] + [
    (f"gradient_{k.lower()}", _gradient(k)) for k in
    ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE",
     "RADIAL")] + [
    ("missing_image_repeat", _missing_image("REPEAT")),
    ("missing_image_clip", _missing_image("CLIP")),
    ("missing_image_clip_alpha", _missing_image("CLIP", output="Alpha")),
    ("missing_image_clip_closest", _missing_image("CLIP", "Closest")),
    ("missing_image_clip_times_alpha", _missing_image("CLIP", mix_alpha=True))]


# ---------------------------------------------------------------- colour
BLENDS = blender_enum("ShaderNodeMix", "blend_type")


def _mix(blend):
    def build(nt, p):
        mix = p.node(nt, "ShaderNodeMix", data_type="RGBA", blend_type=blend)
        nt.links.new(gen(nt, p), ident(mix.inputs, "A_Color"))
        c = p.node(nt, "ShaderNodeTexChecker")
        c.inputs["Scale"].default_value = 2.0
        c.inputs["Color1"].default_value = (0.8, 0.3, 0.6, 1.0)
        c.inputs["Color2"].default_value = (0.2, 0.7, 0.4, 1.0)
        nt.links.new(c.outputs["Color"], ident(mix.inputs, "B_Color"))
        ident(mix.inputs, "Factor_Float").default_value = 0.7
        return ident(mix.outputs, "Result_Color")
    return build


def _ramp(interp):
    def build(nt, p):
        r = p.node(nt, "ShaderNodeValToRGB")
        ramp = r.color_ramp
        ramp.interpolation = interp
        ramp.elements[0].color = (0.9, 0.1, 0.1, 1.0)
        ramp.elements[1].position = 0.8
        e = ramp.elements.new(0.4)
        e.color = (0.1, 0.8, 0.3, 1.0)
        nt.links.new(axis(nt, p, gen(nt, p), 0), r.inputs["Fac"])
        return r.outputs["Color"]
    return build


def _color_op(kind, **inputs):
    def build(nt, p):
        n = p.node(nt, kind)
        nt.links.new(gen(nt, p), n.inputs["Color"])
        for k, v in inputs.items():
            n.inputs[k].default_value = v
        return n.outputs[0]
    return build


def _curves(nt, p):
    n = p.node(nt, "ShaderNodeRGBCurve")
    m = n.mapping
    m.curves[3].points.new(0.4, 0.6)            # the combined curve
    m.curves[0].points.new(0.5, 0.2)            # red
    m.curves[2].points[1].location = (0.8, 1.0)  # blue: a steeper end
    m.update()
    n.inputs["Fac"].default_value = 0.9
    scaled = p.node(nt, "ShaderNodeVectorMath", operation="SCALE")
    nt.links.new(gen(nt, p), scaled.inputs[0])
    scaled.inputs["Scale"].default_value = 1.3          # past the curves' range: extrapolated
    nt.links.new(scaled.outputs[0], n.inputs["Color"])
    return n.outputs[0]


COLOR = [(f"mix_{b.lower()}", _mix(b)) for b in BLENDS] + [
    ("rgb_curves", _curves),
    ("ramp_linear", _ramp("LINEAR")), ("ramp_constant", _ramp("CONSTANT")),
    ("ramp_ease", _ramp("EASE")),
    ("invert", _color_op("ShaderNodeInvert", Fac=0.8)),
    ("gamma", _color_op("ShaderNodeGamma", Gamma=2.2)),
    ("bright_contrast", _color_op("ShaderNodeBrightContrast", Bright=0.1, Contrast=0.4)),
    ("hsv", _color_op("ShaderNodeHueSaturation", Hue=0.3, Saturation=1.5, Value=0.8,
                      Fac=0.9))]


# ---------------------------------------------------------------- converter
MATH_OPS = blender_enum("ShaderNodeMath", "operation")


def _math(op):
    def build(nt, p):
        a, b = ramp_xy(nt, p)
        m = p.node(nt, "ShaderNodeMath", operation=op)
        nt.links.new(a, m.inputs[0])
        nt.links.new(b, m.inputs[1])
        m.inputs[2].default_value = 0.6
        scale = 0.02 if op in ("DEGREES", "EXPONENT", "SINH", "COSH") else 0.2
        return shown(nt, p, m.outputs[0], scale)
    return build


def _map_range(kind, clamp):
    def build(nt, p):
        mr = p.node(nt, "ShaderNodeMapRange", interpolation_type=kind, clamp=clamp)
        nt.links.new(axis(nt, p, gen(nt, p), 0), mr.inputs["Value"])
        mr.inputs["From Min"].default_value = 0.2
        mr.inputs["From Max"].default_value = 0.7
        mr.inputs["To Min"].default_value = 0.1
        mr.inputs["To Max"].default_value = 0.9
        ident(mr.inputs, "Steps").default_value = 3.0
        return mr.outputs[0]
    return build


def _clamp(kind):
    def build(nt, p):
        c = p.node(nt, "ShaderNodeClamp", clamp_type=kind)
        nt.links.new(axis(nt, p, gen(nt, p), 0), c.inputs["Value"])
        c.inputs["Min"].default_value = 0.7
        c.inputs["Max"].default_value = 0.3
        return c.outputs[0]
    return build


def _separate_combine(mode):
    def build(nt, p):
        sep = p.node(nt, "ShaderNodeSeparateColor", mode=mode)
        nt.links.new(gen(nt, p), sep.inputs[0])
        comb = p.node(nt, "ShaderNodeCombineColor", mode=mode)
        nt.links.new(sep.outputs[0], comb.inputs[1])
        nt.links.new(sep.outputs[1], comb.inputs[2])
        nt.links.new(sep.outputs[2], comb.inputs[0])
        return comb.outputs[0]
    return build


def _rgb_to_bw(nt, p):
    bw = p.node(nt, "ShaderNodeRGBToBW")
    nt.links.new(_checker()(nt, p), bw.inputs[0])
    return bw.outputs[0]


def _blackbody(nt, p):
    """Blackbody of a temperature computed by nodes (1250 K x 2, folded at export)."""
    bb = p.node(nt, "ShaderNodeBlackbody")
    m = p.node(nt, "ShaderNodeMath", operation="MULTIPLY")
    m.inputs[0].default_value, m.inputs[1].default_value = 1250.0, 2.0
    nt.links.new(m.outputs[0], bb.inputs["Temperature"])
    return bb.outputs[0]


def _blackbody_varying(nt, p):
    """Blackbody of a temperature that varies across the tile, 600 K to 12600 K (past
    both ends of Blender's table): looked up per hit."""
    bb = p.node(nt, "ShaderNodeBlackbody")
    m = p.node(nt, "ShaderNodeMath", operation="MULTIPLY_ADD")
    nt.links.new(axis(nt, p, gen(nt, p), 0), m.inputs[0])
    m.inputs[1].default_value, m.inputs[2].default_value = 12000.0, 600.0
    nt.links.new(m.outputs[0], bb.inputs["Temperature"])
    return bb.outputs[0]


def _group(bpy_data, name, build_inner):
    """A shader node group with one float input and one float output."""
    g = bpy_data.node_groups.new(name, "ShaderNodeTree")
    g.interface.new_socket("In", in_out="INPUT", socket_type="NodeSocketFloat")
    g.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketFloat")
    gin = g.nodes.new("NodeGroupInput")
    gout = g.nodes.new("NodeGroupOutput")
    g.links.new(build_inner(g, gin.outputs[0]), gout.inputs[0])
    return g


def _nested_groups(nt, p):
    """Groups in groups, a reroute and a muted node: flattened by the compiler."""
    import bpy

    def inner(g, value):
        m = g.nodes.new("ShaderNodeMath")
        m.operation = "ADD"
        m.inputs[1].default_value = 0.2
        g.links.new(value, m.inputs[0])
        return m.outputs[0]

    inner_group = _group(bpy.data, "Inner", inner)

    def outer(g, value):
        m = g.nodes.new("ShaderNodeMath")
        m.operation = "MULTIPLY"
        m.inputs[1].default_value = 0.5
        g.links.new(value, m.inputs[0])
        muted = g.nodes.new("ShaderNodeMath")
        muted.operation = "POWER"
        muted.mute = True                      # passes its first input through
        g.links.new(m.outputs[0], muted.inputs[0])
        node = g.nodes.new("ShaderNodeGroup")
        node.node_tree = inner_group
        g.links.new(muted.outputs[0], node.inputs[0])
        return node.outputs[0]

    group = p.node(nt, "ShaderNodeGroup")
    group.node_tree = _group(bpy.data, "Outer", outer)
    reroute = p.node(nt, "NodeReroute")
    nt.links.new(axis(nt, p, gen(nt, p), 0), reroute.inputs[0])
    nt.links.new(reroute.outputs[0], group.inputs[0])
    return group.outputs[0]


CONVERTER = [(f"math_{o.lower()}", _math(o)) for o in MATH_OPS] + [
    (f"map_range_{k.lower()}", _map_range(k, True)) for k in
    ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")] + [
    ("map_range_unclamped", _map_range("LINEAR", False)),
    ("clamp_minmax", _clamp("MINMAX")), ("clamp_range", _clamp("RANGE")),
    ("color_rgb", _separate_combine("RGB")), ("color_hsv", _separate_combine("HSV")),
    ("color_hsl", _separate_combine("HSL")), ("rgb_to_bw", _rgb_to_bw),
    ("blackbody", _blackbody), ("blackbody_varying", _blackbody_varying),
    ("nested_groups", _nested_groups)]


# ---------------------------------------------------------------- vector
VECTOR_OPS = blender_enum("ShaderNodeVectorMath", "operation")


def _vector_math(op):
    def build(nt, p):
        vm = p.node(nt, "ShaderNodeVectorMath", operation=op)
        g = p.coords(nt).outputs["Object"]
        nt.links.new(g, vm.inputs[0])
        vm.inputs[1].default_value = (0.3, -0.6, 0.8)
        vm.inputs[2].default_value = (0.2, 0.4, -0.5)
        if "Scale" in vm.inputs:
            vm.inputs["Scale"].default_value = 0.7
        out = vm.outputs["Value"] if op in ("DOT_PRODUCT", "DISTANCE", "LENGTH") else \
            vm.outputs["Vector"]
        if out.name == "Value":
            return shown(nt, p, out, 0.2)
        show = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        nt.links.new(out, show.inputs[0])
        show.inputs[1].default_value = (0.2, 0.2, 0.2)
        show.inputs[2].default_value = (0.5, 0.5, 0.5)
        return show.outputs[0]
    return build


def _mapping(kind):
    def build(nt, p):
        m = p.node(nt, "ShaderNodeMapping", vector_type=kind)
        nt.links.new(gen(nt, p), m.inputs["Vector"])
        if "Location" in m.inputs:
            m.inputs["Location"].default_value = (0.1, -0.2, 0.3)
        m.inputs["Rotation"].default_value = (0.3, -0.2, math.radians(30))
        m.inputs["Scale"].default_value = (1.5, 0.7, 1.2)
        show = p.node(nt, "ShaderNodeVectorMath", operation="ABSOLUTE")
        nt.links.new(m.outputs[0], show.inputs[0])
        return show.outputs[0]
    return build


def _normal_node(output):
    """The Normal node: its own direction (unnormalised here, as a dragged widget may
    leave it) or its Dot with the tile's object coordinates (normalised by the node)."""
    def build(nt, p):
        n = p.node(nt, "ShaderNodeNormal")
        n.outputs["Normal"].default_value = (0.3, -0.5, 0.8)
        nt.links.new(p.coords(nt).outputs["Object"], n.inputs["Normal"])
        if output == "Dot":
            return shown(nt, p, n.outputs["Dot"], 0.4)
        show = p.node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        nt.links.new(n.outputs["Normal"], show.inputs[0])
        show.inputs[1].default_value = (0.4, 0.4, 0.4)
        show.inputs[2].default_value = (0.5, 0.5, 0.5)
        return show.outputs[0]
    return build


VECTOR = [(f"vmath_{o.lower()}", _vector_math(o)) for o in VECTOR_OPS] + [
    (f"mapping_{k.lower()}", _mapping(k)) for k in ("POINT", "TEXTURE", "VECTOR", "NORMAL")] + [
    ("normal_direction", _normal_node("Normal")), ("normal_dot", _normal_node("Dot"))]

FAMILIES = {"input": (INPUT, "plane"), "input_spheres": (INPUT_SPHERES, "sphere"),
            "texture": (TEXTURE, "plane"), "color": (COLOR, "plane"),
            "converter": (CONVERTER, "plane"), "vector": (VECTOR, "plane")}
