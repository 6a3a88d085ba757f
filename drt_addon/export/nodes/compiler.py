"""The node compiler: a material's node graph, from the sockets a shader reads, to an
engine.nodes ShaderProgram.

`NodeCompiler.input(node, name, kind)` gives the value an input socket of a shader node
receives: its own value when unlinked, else the compiled output it is linked to,
converted to the socket's kind as Cycles converts links (colour to float: Rec.709
luminance; vector to float: the average; float to colour or vector: repeated). Each
(node, output) is compiled once per material. Reroutes and muted links are followed;
node groups (nested) are flattened: inside a group, a Group Input output is the value
the group node's input receives. Muted nodes pass their first matching input through,
as Blender does.

The Bump node evaluates its Height at offset hits (`at_offset`): the nodes feeding it are
compiled again there, as new values (each offset region has its own memo), between the
instructions that move the hit and put it back, as Cycles' SVM compiler copies the
Height's nodes for its offset evaluations.

The Displacement socket's bump is compiled first, as Cycles' bump pass runs before the
surface's nodes; its bent normal then stands for the surface normal (`set_normal`) in
every node compiled after it (Geometry, Texture Coordinate, Fresnel, Layer Weight, Bump,
the Normal Map where it falls back), as Cycles' Set Normal writes sd->N.

A node no family translates is reported once per material, naming it, and the socket it
feeds falls back to its own value: never an error, never a black render.
"""
from __future__ import annotations

import importlib

from ...engine_link import engine
from . import color, converter, input, procedural, texture, vector
from .errors import Unsupported
from .links import usable_link

program = importlib.import_module(engine.__name__ + ".nodes.program")
cv = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
bump = importlib.import_module(engine.__name__ + ".nodes.bump")
context = importlib.import_module(engine.__name__ + ".nodes.context")
in_ops = importlib.import_module(engine.__name__ + ".nodes.input_nodes")
vec_ops = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")

TRANSLATORS = {}
for _family in (input, texture, procedural, color, converter, vector):
    TRANSLATORS.update(_family.TRANSLATORS)

SOCKET_KINDS = {"VALUE": "float", "INT": "float", "BOOLEAN": "float", "RGBA": "color",
                "VECTOR": "vector"}


class NodeCompiler:
    def __init__(self, ctx):
        self.ctx = ctx                     # materials._Ctx: issues, image cache
        self.b = program.ProgramBuilder()
        self._memo = {}
        self._groups = []                  # stack of group nodes being flattened
        self._region = 0                   # the offset region being compiled (0: none)
        self._regions = 0
        self._normal = None                # sd->N once the Displacement's bump set it

    # -- the surface normal ----------------------------------------------------------
    def normal(self):
        """The surface's shading normal as nodes read it (Cycles' sd->N): the hit's, or
        the one the Displacement socket's bump set (`set_normal`)."""
        if self._normal is not None:
            return self._normal
        return self.emit(in_ops.IN_HIT3, "vector", [context.H_N], varying=True)

    def object_normal(self):
        """The shading normal in object space (the Texture Coordinate node's Normal)."""
        if self._normal is not None:
            return self.emit(vec_ops.VEC_OBJECT_NORMAL, "vector", [self._normal],
                             varying=True)
        return self.emit(in_ops.IN_HIT3, "vector", [context.H_OBJ_NORMAL], varying=True)

    def set_normal(self, normal):
        """Cycles' Set Normal at the end of its bump pass: the nodes compiled from now on
        read `normal` as the surface's normal, and are compiled anew (a node the bump
        already read evaluates again, at the bent normal, as Cycles' surface pass does)."""
        self._normal = normal
        self._memo.clear()

    # -- values --------------------------------------------------------------------
    def const(self, x, kind=None):
        return self.b.constant(x, kind)

    def emit(self, opcode, kind, operands=(), varying=None, image=None, grid=None):
        return self.b.emit(opcode, kind, operands, varying, image, grid)

    def convert(self, value, kind):
        """`value` as a `kind` value ('float', 'color', 'vector'), Cycles' link rules."""
        if value.kind == kind:
            return value
        if kind == "float":
            op = cv.CV_LUMINANCE if value.kind == "color" else cv.CV_AVERAGE
            return self.emit(op, "float", [value])
        if value.kind == "float":
            return self.emit(cv.CV_BROADCAST, kind, [value])
        return program.Value(value.reg, kind, value.varying)        # colour <-> vector

    def default(self, sock, kind):
        """The constant register of an unlinked socket's own value."""
        v = getattr(sock, "default_value", 0.0)
        try:
            vals = tuple(v)[:3]
        except TypeError:
            vals = (float(v),)
        if kind == "float":
            return self.const(float(vals[0]))
        if len(vals) == 1:
            vals = vals * 3
        return self.const(vals, kind)

    # -- graph walking -------------------------------------------------------------
    def _source(self, sock):
        """(node, output socket) linked into input `sock`, through reroutes and groups'
        inputs; None when unlinked."""
        seen = set()
        while True:
            link = usable_link(sock)
            if link is None:
                return None
            node, out = link.from_node, link.from_socket
            if node.bl_idname == "NodeReroute":
                if node.as_pointer() in seen:       # a loop of reroutes
                    return None
                seen.add(node.as_pointer())
                sock = node.inputs[0]
                continue
            if node.bl_idname == "NodeGroupInput":
                if not self._groups:
                    return None
                group = self._groups[-1]
                inner = next((s for s in group.inputs if s.identifier == out.identifier),
                             None)
                if inner is None:
                    return None
                self._groups.pop()
                try:
                    found = self._source(inner)
                    return ("default", inner) if found is None else found
                finally:
                    self._groups.append(group)
            return node, out, list(self._groups)

    def input(self, node, name, kind=None):
        """The value input `name` (name or identifier) of `node` receives."""
        sock = node.inputs.get(name) if isinstance(name, str) else node.inputs[name]
        if sock is None:
            sock = next((s for s in node.inputs if s.identifier == name), None)
        if sock is None:
            raise KeyError(f"{node.name!r} has no input {name!r}")
        return self.socket(sock, kind)

    def socket(self, sock, kind=None):
        kind = kind or SOCKET_KINDS.get(sock.type, "float")
        found = self._source(sock)
        if found is None:
            return self.default(sock, kind)
        if found[0] == "default":
            return self.default(found[1], kind)
        node, out, groups = found
        saved = self._groups
        self._groups = groups
        try:
            value = self.output(node, out)
        finally:
            self._groups = saved
        if value is None:
            return self.default(sock, kind)
        return self.convert(value, kind)

    def output(self, node, out):
        """The compiled value of output socket `out` of `node` (None: not evaluated,
        reported)."""
        key = (self._region, tuple(g.as_pointer() for g in self._groups),
               node.as_pointer(), out.identifier)
        if key in self._memo:
            return self._memo[key]
        self._memo[key] = None              # a cycle reads the fallback
        value = self._translate(node, out)
        self._memo[key] = value
        return value

    def _translate(self, node, out):
        if getattr(node, "mute", False):
            return self._muted(node, out)
        kind = node.bl_idname
        if kind == "ShaderNodeGroup":
            return self._group(node, out)
        fn = TRANSLATORS.get(kind)
        if fn is None:
            self.ctx.issue(f"the {node.bl_label!r} node ({node.name!r}) is not evaluated by "
                           f"DRT; the socket it feeds uses its own value")
            return None
        try:
            return fn(self, node, out)
        except Unsupported as e:
            self.ctx.issue(f"{node.name!r}: {e}; the socket it feeds uses its own value")
            return None

    def _muted(self, node, out):
        for sock in node.inputs:
            if sock.type == out.type and sock.type != "SHADER":
                return self.socket(sock)
        return self.default(out, SOCKET_KINDS.get(out.type, "float"))

    def _group(self, node, out):
        tree = node.node_tree
        if tree is None:
            return None
        if len(self._groups) > 16 or any(g.node_tree == tree for g in self._groups):
            self.ctx.issue(f"node group {tree.name!r} is nested too deep or recursive")
            return None
        outputs = [n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"]
        gout = next((n for n in outputs if getattr(n, "is_active_output", False)),
                    outputs[0] if outputs else None)
        if gout is None:
            return None
        sock = next((s for s in gout.inputs if s.identifier == out.identifier), None)
        if sock is None:
            return None
        self._groups.append(node)
        try:
            return self.socket(sock, SOCKET_KINDS.get(out.type, "float"))
        finally:
            self._groups.pop()

    def at_offset(self, axis, width, compute):
        """What `compute()` compiles, evaluated with the hit moved by `width` (a float
        Value) times its pixel step along axis 0 (x) or 1 (y)."""
        save = self.b.block(context.N_DIFF)
        self.emit(bump.BUMP_ENTER, "float", [save, axis, width], varying=True)
        self._regions += 1
        outer, self._region = self._region, self._regions
        try:
            value = compute()
        finally:
            self._region = outer
        self.emit(bump.BUMP_LEAVE, "float", [save], varying=True)
        return value

    def undisplaced(self, compute):
        """What `compute(steps)` compiles, evaluated on a displaced surface's undisplaced
        point (bump.DISP_ENTER): a Displacement and Bump material's bump, as Cycles
        evaluates it. compute calls steps() before its Bump normal, which takes the
        undisplaced surface's steps. Its nodes are compiled anew there (a region of
        their own)."""
        save = self.b.block(context.N_UNDISPLACED)
        self.emit(bump.DISP_ENTER, "float", [save, 0], varying=True)
        self._regions += 1
        outer, self._region = self._region, self._regions
        try:
            value = compute(lambda: self.emit(bump.DISP_ENTER, "float", [save, 1],
                                              varying=True))
        finally:
            self._region = outer
        self.emit(bump.DISP_LEAVE, "float", [save], varying=True)
        return value

    # -- results -------------------------------------------------------------------
    def fold(self, value):
        """A non-varying value computed now (float or tuple); None if it varies."""
        if value.varying:
            return None
        return self.b.build().constant_value(value)

    def mean(self, value):
        return self.b.build().mean_value(value)

    def build(self):
        return self.b.build()
