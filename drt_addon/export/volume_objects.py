"""Volume objects (OpenVDB grids: a smoke cache, a cloud, a file from another program) to
what the engine renders: each grid an engine.volume_grid.VoxelGrid, read with the
`openvdb` module the bpy wheel ships (beside OpenImageIO in bpy's own site-packages),
and a closed box around the grids' active voxels, whose inside is the medium of the
object's material (export.volumes). Its shader program reads the grids where Cycles'
Attribute node and the Principled Volume's Density, Color and Temperature Attributes
do (export.nodes.input).

Grids live in the object's space by their own transforms (Blender's
`VolumeGrid.matrix_object`, which equals the file's). What DRT cannot read is said in
Blender's report, never dropped silently: a packed file, a missing file, a Volume
changed by modifiers (the grids are read from the file, before them), and grids of
integer or boolean values.
"""
from __future__ import annotations

import glob
import importlib
import importlib.util
import os
import sys

import numpy as np

from .layer_overrides import slot_materials
from ..engine_link import engine
from .matrices import to_numpy
from .mesh import LocalMesh

volume_grid = importlib.import_module(engine.__name__ + ".volume_grid")

# a box's 12 triangles, wound so that their normals point out (corner k = bits x, y, z)
_BOX = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                 [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]],
                np.int32)
_READABLE = {"FloatGrid": 1, "DoubleGrid": 1, "Vec3SGrid": 3, "Vec3DGrid": 3}
VOXEL_LIMIT = 1 << 28          # voxels of one grid's dense block (1 GiB of float32)


def openvdb_module():
    """The `openvdb` module of Blender's Python, or of the bpy wheel, which keeps it in
    its own site-packages (bpy/<version>/python/lib/python3.x/site-packages); None when
    there is none."""
    try:
        import openvdb
        return openvdb
    except ImportError:
        pass
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.origin:
        return None
    pattern = os.path.join(os.path.dirname(spec.origin), "*", "python", "lib", "python3*",
                           "site-packages")
    for site in sorted(glob.glob(pattern)):
        if glob.glob(os.path.join(site, "openvdb*")) and site not in sys.path:
            sys.path.append(site)
    try:
        import openvdb
        return openvdb
    except ImportError:
        return None


def _affine(grid) -> np.ndarray:
    """The grid's index -> object map as a 4 x 4 matrix (column vectors), read through
    its transform (linear transforms only)."""
    t = grid.transform
    o = np.array(t.indexToWorld((0.0, 0.0, 0.0)), np.float64)
    m = np.eye(4)
    for axis in range(3):
        e = [0.0, 0.0, 0.0]
        e[axis] = 1.0
        m[:3, axis] = np.array(t.indexToWorld(tuple(e)), np.float64) - o
    m[:3, 3] = o
    return m


def read_grid(grid, issue) -> "volume_grid.VoxelGrid | None":
    """One openvdb grid as a dense VoxelGrid over its active voxels' bounds (None, with
    `issue` called, when DRT cannot read it)."""
    kind = type(grid).__name__
    channels = _READABLE.get(kind)
    if channels is None:
        issue(f"grid {grid.name!r} holds {grid.valueTypeName} values, which DRT does not read")
        return None
    if not grid.transform.isLinear:
        issue(f"grid {grid.name!r} has a frustum transform, which DRT does not read")
        return None
    if grid.activeVoxelCount() == 0:
        return None
    lo, hi = grid.evalActiveVoxelBoundingBox()
    shape = tuple(int(h - l + 1) for l, h in zip(lo, hi))
    if int(np.prod(shape, dtype=np.int64)) > VOXEL_LIMIT:
        issue(f"grid {grid.name!r} spans {shape[0]} x {shape[1]} x {shape[2]} voxels, "
              f"more than DRT's dense grids hold ({VOXEL_LIMIT})")
        return None
    dtype = np.float64 if kind.endswith("DGrid") or kind == "DoubleGrid" else np.float32
    values = np.zeros(shape + ((3,) if channels == 3 else ()), dtype)
    grid.copyToArray(values, ijk=tuple(int(x) for x in lo))
    to_index = np.linalg.inv(_affine(grid))
    return volume_grid.VoxelGrid(grid.name, values, tuple(int(x) for x in lo), to_index)


def grid_file(volume) -> str | None:
    """The absolute path of the file a Volume datablock reads at the current frame (a
    sequence's frame: Blender resolves it when it loads the grids' metadata)."""
    import bpy
    volume.grids.load()
    path = volume.grids.frame_filepath or volume.filepath
    if not path:
        return None
    return bpy.path.abspath(path, library=volume.library)


# the grids Cycles' default volume shader (a Principled Volume) reads, and the
# Principled Volume's attribute inputs (string sockets)
PRINCIPLED_ATTRIBUTES = ("Density Attribute", "Color Attribute", "Temperature Attribute")
DEFAULT_GRIDS = {"density", "temperature"}


def attribute_name(node, socket: str) -> str:
    """The grid name a Principled Volume's attribute input names ('' for none)."""
    sock = node.inputs.get(socket)
    return str(getattr(sock, "default_value", "") or "") if sock is not None else ""


def _nodes(tree, seen=None):
    seen = set() if seen is None else seen
    if tree is None or id(tree) in seen:
        return
    seen.add(id(tree))
    for node in tree.nodes:
        yield node
        if node.bl_idname == "ShaderNodeGroup":
            yield from _nodes(node.node_tree, seen)


def wanted_grids(materials) -> set:
    """The grid names a Volume object's materials (layer_overrides.slot_materials) read
    (Attribute nodes, the Principled Volume's attributes); Cycles' default volume's for
    an empty slot or none."""
    names = set()
    for mat in materials or [None]:
        if mat is None:
            names |= DEFAULT_GRIDS
            continue
        for node in _nodes(getattr(mat, "node_tree", None)):
            if node.bl_idname == "ShaderNodeAttribute" and node.attribute_type == "GEOMETRY":
                names.add(node.attribute_name)
            elif node.bl_idname == "ShaderNodeVolumePrincipled":
                names |= {attribute_name(node, p) for p in PRINCIPLED_ATTRIBUTES}
    return {n for n in names if n}


def read_volume(obj, reporter, materials=None) -> dict | None:
    """{grid name: VoxelGrid} of the grids a Volume object's materials read (`materials`,
    by default its slots' own), from its OpenVDB file at the current frame; None
    (reported) when none can be read."""
    volume = obj.data
    issues = []
    if getattr(volume, "packed_file", None) is not None:
        issues.append("its OpenVDB file is packed into the .blend, which DRT cannot read "
                      "yet (File > External Data > Unpack Resources)")
    path = None if issues else grid_file(volume)
    if not issues and path is None:
        issues.append("it names no OpenVDB file")
    elif not issues and not os.path.isfile(path):
        issues.append(f"its OpenVDB file {path!r} is missing")
    vdb = None if issues else openvdb_module()
    if not issues and vdb is None:
        issues.append("this Blender has no openvdb module to read it")
    if any(m.show_render for m in getattr(obj, "modifiers", ())):
        issues.append("its modifiers are not applied (the grids are read from the file)")
    grids = {}
    if vdb is not None:
        wanted = wanted_grids(slot_materials(obj) if materials is None else materials)
        try:
            names = [g.name for g in vdb.readAllGridMetadata(path)]
            found = [vdb.read(path, n) for n in names if n in wanted]
        except Exception as e:                   # a broken file: said, never a crash
            issues.append(f"its OpenVDB file {path!r} cannot be read ({e})")
            names, found = [], []
        for g in found:
            grid = read_grid(g, issues.append)
            if grid is not None:
                grids[grid.name] = grid
        if names and not grids:
            issues.append(f"none of the grids its materials read ({', '.join(sorted(wanted))}"
                          f") holds active voxels in its file, whose grids are "
                          f"{', '.join(names)}")
    if issues and reporter is not None:
        reporter.warn(f"DRT: Volume object {obj.name!r}: " + "; ".join(issues),
                      key=(obj.name, "volume object"))
    return grids or None


def domain(grids: dict) -> LocalMesh:
    """The closed box (object space) around every grid's voxels: the medium's boundary,
    outside which every grid reads 0."""
    los, his = zip(*(g.bounds() for g in grids.values()))
    lo, hi = np.min(los, axis=0), np.max(his, axis=0)
    corners = np.array([[hi[0] if k & 1 else lo[0], hi[1] if k & 2 else lo[1],
                         hi[2] if k & 4 else lo[2]] for k in range(8)])
    return LocalMesh(corners, _BOX.copy(), np.zeros(len(_BOX), np.int32))


def density_scale(obj, matrix_world) -> float:
    """Cycles' density of a Volume object whose Render > Space is Object (the default):
    its coefficients divided by how much the object's matrix stretches the diagonal
    (1, 1, 1) / sqrt(3), so that scaling the object keeps its look; 1 in World space."""
    render = getattr(obj.data, "render", None)
    if getattr(render, "space", "OBJECT") != "OBJECT":
        return 1.0
    m = np.asarray(to_numpy(matrix_world), np.float64)[:3, :3]
    stretch = float(np.linalg.norm(m @ np.full(3, 1.0 / np.sqrt(3.0))))
    return 1.0 / stretch if np.isfinite(stretch) and stretch > 0.0 else 1.0
