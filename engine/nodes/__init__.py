"""Shader node programs: a material's node graph as a small program evaluated at every hit.

The exporter (drt_addon/export/nodes/) translates the node tree behind a material's
output into a `ShaderProgram`: one typed operation per node, sockets as registers, the
unlinked sockets' values as constant registers. The engine runs the program over each
hit (`interpreter.run`, a compiled loop with a switch per node family, as Cycles' SVM
interprets its node stack) and reads the program's outputs: per-hit Principled
parameters (base colour, metallic, roughness), emission and alpha.

One module per node family on each side, so a node is found by its family:

  context.py          the hit a program reads (position, normals, incoming direction,
                      UV, the object's coordinates and info, the camera's, the ray
                      kind, the path's bounces, the ray's footprint and the changes
                      of the surface fields over a pixel step)
  program.py          ShaderProgram and its builder; the outputs a program can drive
  interpreter.py      the compiled interpreter and its array driver
  pack.py             every material's program as the arrays the kernels take
  input_nodes.py      Texture Coordinate, Geometry, Object Info, Fresnel, Layer Weight,
                      Light Path
  texture_nodes.py    Image, Checker, Gradient
  procedural_nodes.py White Noise, Noise, Voronoi, Wave, Magic, Brick; their kernels:
                      hash.py (Jenkins lookup3 and PCG hashes), noise.py (Perlin noise
                      and fractals), voronoi.py, pattern_textures.py
  color_nodes.py      Mix (every blend mode), Color Ramp, Invert, Gamma,
                      Bright/Contrast, Hue/Saturation/Value
  converter_nodes.py  Math (every operation), Map Range, Clamp, Separate / Combine,
                      RGB to BW
  vector_nodes.py     Vector Math, Mapping, Normal Map
  bump.py             Bump; the hit's ray differentials it offsets the Height by:
                      differentials.py
  camera_coords.py    Texture Coordinate's Camera and Window

Registers are float64; a colour or vector takes three consecutive registers (colours
carry no alpha: an Image's Alpha is its own output). An instruction is eight int32:
opcode, output register, then operands (input registers or immediate codes, as each
family documents). Opcode ranges: input 0-99, texture 100-119, procedural textures
120-199, colour 200-299, converter 300-399, vector 400-419, bump 420-439.
"""
