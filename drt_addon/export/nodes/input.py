"""Input nodes to program operations (engine.nodes.input_nodes): Texture Coordinate,
UV Map, Geometry, Object Info, Color Attribute and Attribute (colour attributes), Value,
RGB, Fresnel, Layer Weight, Light Path."""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .errors import Unsupported

I = importlib.import_module(engine.__name__ + ".nodes.input_nodes")
C = importlib.import_module(engine.__name__ + ".nodes.context")
V = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")
X = importlib.import_module(engine.__name__ + ".nodes.texture_nodes")
vis = importlib.import_module(engine.__name__ + ".visibility")


def hit3(c, field):
    return c.emit(I.IN_HIT3, "vector", [field], varying=True)


def hit1(c, field):
    return c.emit(I.IN_HIT1, "float", [field], varying=True)


def normal_input(c, node):
    """A node's Normal input: the hit's shading normal when unlinked (Cycles' sd->N)."""
    sock = node.inputs.get("Normal")
    if sock is not None and sock.is_linked:
        return c.socket(sock, "vector")
    return c.normal()


def _tex_coord(c, node, out):
    name = out.identifier
    if name in ("Generated", "Normal", "Object") and getattr(node, "object", None) is not None:
        raise Unsupported(f"the {name} coordinates of another object are not evaluated")
    if name == "Generated":
        return hit3(c, C.H_GENERATED)
    if name == "Normal":
        return c.object_normal()
    if name == "UV":
        return hit3(c, C.H_UV)
    if name == "Object":
        return hit3(c, C.H_OBJECT)
    if name == "Camera":
        return hit3(c, C.H_CAMERA)
    if name == "Window":
        return hit3(c, C.H_WINDOW)
    if name == "Reflection":
        incoming = hit3(c, C.H_I)
        minus = c.emit(V.VEC_MATH, "vector", [incoming, incoming, incoming, c.const(-1.0),
                                              V.VECTOR_OPS.index("SCALE")])
        return c.emit(V.VEC_MATH, "vector", [minus, c.normal(), minus, c.const(1.0),
                                             V.VECTOR_OPS.index("REFLECT")])
    raise Unsupported(f"the Texture Coordinate output {name} is not evaluated")


def _uv_map(c, node, out):
    return hit3(c, C.H_UV)


GEOMETRY = {"Position": C.H_P, "True Normal": C.H_NG, "Incoming": C.H_I}


def geometry_tangent(c):
    """The Geometry node's Tangent (Cycles' primitive_tangent): radial about the
    object's Z through its generated coordinates; also what an unlinked Tangent input of
    an anisotropic BSDF reads."""
    return c.emit(I.IN_TANGENT, "vector", [I.TANGENT_RADIAL, 2], varying=True)


def _tangent(c, node, out):
    """The Tangent node: radial about its axis, or its UV map's tangent (the mesh's
    MikkTSpace tangents, export.tangents; another map than the default is reported)."""
    if node.direction_type == "UV_MAP":
        return c.emit(I.IN_TANGENT, "vector", [I.TANGENT_UV_MAP, 0], varying=True)
    return c.emit(I.IN_TANGENT, "vector", [I.TANGENT_RADIAL, "XYZ".index(node.axis)],
                  varying=True)


def _geometry(c, node, out):
    name = out.identifier
    if name == "Normal":
        return c.normal()
    if name == "Tangent":
        return geometry_tangent(c)
    if name in GEOMETRY:
        return hit3(c, GEOMETRY[name])
    if name == "Backfacing":
        return hit1(c, C.H_BACKFACING)
    raise Unsupported(f"the Geometry output {name} is not evaluated")


def _object_info(c, node, out):
    name = out.identifier
    if name == "Location":
        return hit3(c, C.H_OBJ_LOCATION)
    if name == "Color":
        return c.convert(hit3(c, C.H_OBJ_COLOR), "color")
    if name == "Random":
        return hit1(c, C.H_OBJ_RANDOM)
    if name == "Object Index":
        return hit1(c, C.H_OBJ_INDEX)
    if name == "Alpha":
        return c.const(1.0)
    raise Unsupported(f"the Object Info output {name} is not evaluated")


HAIR_INFO = {"Is Strand": C.H_HAIR_IS_STRAND, "Intercept": C.H_HAIR_INTERCEPT,
             "Length": C.H_HAIR_LENGTH, "Thickness": C.H_HAIR_THICKNESS,
             "Random": C.H_HAIR_RANDOM}


def _hair_info(c, node, out):
    """Curves Info (Hair Info): what the strand hit is (engine.kernels.curve_hit
    .strand_info); zeros off hair, as in Cycles."""
    name = out.identifier
    if name in HAIR_INFO:
        return hit1(c, HAIR_INFO[name])
    if name == "Tangent Normal":
        return hit3(c, C.H_HAIR_TANGENT_NORMAL)
    raise Unsupported(f"the Curves Info output {name} is not evaluated")


def _value(c, node, out):
    return c.const(float(out.default_value))


def _rgb(c, node, out):
    return c.const(tuple(out.default_value)[:3], "color")


def _fresnel(c, node, out):
    return c.emit(I.IN_FRESNEL, "float", [c.input(node, "IOR", "float"),
                                         normal_input(c, node)], varying=True)


def _layer_weight(c, node, out):
    op = I.IN_LAYER_FRESNEL if out.identifier == "Fresnel" else I.IN_LAYER_FACING
    return c.emit(op, "float", [c.input(node, "Blend", "float"), normal_input(c, node)],
                  varying=True)


RAY_MASKS = {"Is Camera Ray": vis.CAMERA, "Is Shadow Ray": vis.SHADOW,
             "Is Diffuse Ray": vis.DIFFUSE, "Is Glossy Ray": vis.GLOSSY,
             "Is Reflection Ray": vis.DIFFUSE | vis.GLOSSY,
             "Is Transmission Ray": vis.TRANSMISSION}


DEPTHS = {"Ray Depth": C.H_DEPTH, "Diffuse Depth": C.H_DIFFUSE_DEPTH,
          "Glossy Depth": C.H_GLOSSY_DEPTH, "Transmission Depth": C.H_TRANSMISSION_DEPTH,
          "Transparent Depth": C.H_TRANSPARENT_DEPTH}


def _light_path(c, node, out):
    name = out.identifier
    if name in RAY_MASKS:
        return c.emit(I.IN_RAY_IS, "float", [RAY_MASKS[name]], varying=True)
    if name == "Ray Length":
        return hit1(c, C.H_RAY_LENGTH)
    if name in DEPTHS:
        return hit1(c, DEPTHS[name])
    if name == "Portal Depth":
        return c.const(0.0)                  # DRT has no ray portals
    raise Unsupported(f"the Light Path output {name} is not evaluated")


def grid_value(c, grid, kind, stochastic=False):
    """A Volume object's grid (engine.volume_grid.VoxelGrid) at the point, in object
    space: 'float' its channels' average (Cycles' Fac), else the triple (a scalar grid
    repeated). stochastic: one voxel, picked with the trilinear weights (Cycles 5's
    stochastic interpolation); else trilinear."""
    co = hit3(c, C.H_OBJECT)
    return c.emit(X.TEX_GRID, kind, [co, 0 if kind == "float" else 1, int(stochastic)],
                  varying=True, grid=grid)


def _color_attribute(c, node, out):
    """Color Attribute / Attribute (geometry): the mesh's colour attribute (the one the
    material names, else its render colour attribute); Fac is the colour's average. On
    a Volume object, an Attribute node naming one of its grids reads the grid (Alpha 1)."""
    if node.bl_idname == "ShaderNodeAttribute" and node.attribute_type != "GEOMETRY":
        raise Unsupported(f"{node.attribute_type.lower()} attributes are not evaluated")
    grids = getattr(c.ctx, "volume_grids", None) or {}
    if node.bl_idname == "ShaderNodeAttribute" and node.attribute_name in grids:
        grid = grids[node.attribute_name]
        name = out.identifier
        if name == "Alpha":
            return c.const(1.0)
        if name == "Fac":
            return grid_value(c, grid, "float")
        return grid_value(c, grid, "color" if name == "Color" else "vector")
    color = c.convert(hit3(c, C.H_COLOR), "color")
    name = out.identifier
    if name == "Alpha":
        return hit1(c, C.H_COLOR + 3)
    if name == "Fac":
        return c.convert(hit3(c, C.H_COLOR), "float")
    return color if name == "Color" else c.convert(color, "vector")


TRANSLATORS = {
    "ShaderNodeVertexColor": _color_attribute,
    "ShaderNodeAttribute": _color_attribute,
    "ShaderNodeTexCoord": _tex_coord,
    "ShaderNodeUVMap": _uv_map,
    "ShaderNodeNewGeometry": _geometry,
    "ShaderNodeTangent": _tangent,
    "ShaderNodeObjectInfo": _object_info,
    "ShaderNodeHairInfo": _hair_info,
    "ShaderNodeValue": _value,
    "ShaderNodeRGB": _rgb,
    "ShaderNodeFresnel": _fresnel,
    "ShaderNodeLayerWeight": _layer_weight,
    "ShaderNodeLightPath": _light_path,
}
