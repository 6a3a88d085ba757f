"""Shader node graphs to engine.nodes programs: `compiler.NodeCompiler` walks the graph
from the sockets a shader reads; one module per node family (input, texture,
procedural, color, converter, vector, shader) translates each node to program
operations, named by the same families as the engine's interpreter (engine/nodes/)."""
from .compiler import NodeCompiler

__all__ = ["NodeCompiler"]
