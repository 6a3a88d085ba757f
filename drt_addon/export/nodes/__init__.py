"""Shader node graphs to engine.nodes programs: `compiler.NodeCompiler` walks the graph
from the sockets a shader reads; one module per node family (input, texture, color,
converter, vector; procedural for the noise textures) translates each node to program
operations, named by the same families as the engine's interpreter (engine/nodes/)."""
from .compiler import NodeCompiler  # noqa: F401
