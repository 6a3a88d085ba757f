"""Embree scenes built from NumPy arrays that Embree shares, never copies.

A `Scene` holds geometries: triangle meshes, curves, points and instances of other
scenes. Every buffer is a NumPy array handed to Embree with `rtcSetSharedGeometryBuffer`
and kept alive by the scene for as long as Embree may read it. Embree reads float32
vertices; DRT's meshes are float64, so a mesh's vertices are converted once, by one
vectorised NumPy operation, into a float32 array with the one float of padding Embree's
16-byte loads need, which Embree then shares. Index arrays are shared as they are
(int32 rows, read as unsigned).

Motion: a geometry given K vertex arrays (time steps, evenly spaced over [0, 1]) is
linearly interpolated by Embree over the ray's time in [0, 1]; an instance given K
transforms likewise interpolates the matrices, and one given K quaternion
decompositions (`add_moving_instance`) interpolates translation and scale linearly and
rotation spherically. `handle` is the scene's address, which the ray kernels
(`engine.embree.rays`) take.
"""
from __future__ import annotations

import ctypes
import threading

import numpy as np

from . import library as L

_DEVICE = None
_DEVICE_LOCK = threading.Lock()


class EmbreeError(RuntimeError):
    pass


def device() -> int:
    """The process's one Embree device (one device per scene crashes Embree past about a
    thousand scenes; all DRT's scenes share it)."""
    global _DEVICE
    with _DEVICE_LOCK:
        if _DEVICE is None:
            lib = L.load()
            handle = lib.rtcNewDevice(None)
            if not handle:
                raise EmbreeError("Embree could not create a device on this CPU")
            _DEVICE = handle
        return _DEVICE


def check(what: str) -> None:
    """Raise if the last Embree call on the device failed."""
    lib = L.load()
    code = lib.rtcGetDeviceError(device())
    if code:
        message = lib.rtcGetDeviceLastErrorMessage(device())
        raise EmbreeError(f"Embree {what}: {L.ERROR_NAMES.get(code, code)}"
                          + (f" ({message.decode(errors='replace')})" if message else ""))


def padded_float32(values: np.ndarray, columns: int, offset=None) -> np.ndarray:
    """(n, columns) float32 rows with one float of padding after the last, as Embree's
    vertex buffers need; `offset` (columns,) is subtracted first, in float64."""
    values = np.asarray(values)
    n = len(values)
    flat = np.empty(n * columns + 1, np.float32)
    flat[-1] = 0.0
    rows = flat[:n * columns].reshape(n, columns)
    with np.errstate(over="ignore"):       # beyond float32's range: inf, a miss
        if offset is None:
            rows[...] = values
        else:
            np.subtract(values, offset, out=rows, casting="same_kind")
    return rows


def _xyz_offset(offset):
    """An (x, y, z) shift as one for (x, y, z, radius) rows (the radius unshifted)."""
    return None if offset is None else np.append(np.asarray(offset, np.float64), 0.0)


def _pointer(a: np.ndarray) -> int:
    return a.ctypes.data


class Scene:
    """An Embree scene: geometries attached in order (their ids 0, 1, ...), committed once.
    `robust` asks Embree for watertight traversal (no rays slipping between triangles
    that share an edge); `compact` for less memory."""

    def __init__(self, robust: bool = True, compact: bool = False,
                 quality: int = L.BUILD_QUALITY_MEDIUM):
        self._lib = L.load()
        self._device = device()
        self.handle = self._lib.rtcNewScene(self._device)
        check("rtcNewScene")
        # every scene takes the filter a query passes (engine.embree.self_hits)
        flags = (L.SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS
                 | (L.SCENE_FLAG_ROBUST if robust else 0)
                 | (L.SCENE_FLAG_COMPACT if compact else 0))
        self._lib.rtcSetSceneFlags(self.handle, flags)
        self._lib.rtcSetSceneBuildQuality(self.handle, quality)
        self._keep: list = []          # every array Embree shares, and instanced scenes
        self.kinds: list[str] = []     # the kind of each geometry, by id
        self.counts: list[int] = []    # primitives of each geometry, by id
        self.committed = False

    # -- geometry ------------------------------------------------------------------------
    def _new(self, kind: int):
        geom = self._lib.rtcNewGeometry(self._device, kind)
        check("rtcNewGeometry")
        return geom

    def _share(self, geom, buffer_type: int, slot: int, fmt: int, array: np.ndarray,
               stride: int, count: int):
        self._lib.rtcSetSharedGeometryBuffer(geom, buffer_type, slot, fmt, _pointer(array),
                                             0, stride, count)
        self._keep.append(array)

    def _attach(self, geom, kind: str, count: int) -> int:
        self._lib.rtcCommitGeometry(geom)
        gid = self._lib.rtcAttachGeometry(self.handle, geom)
        self._lib.rtcReleaseGeometry(geom)      # the scene holds it now
        check(f"attaching {kind}")
        self.kinds.append(kind)
        self.counts.append(count)
        return gid

    def _steps(self, geom, steps: list[np.ndarray]) -> None:
        if len(steps) > 1:
            if len(steps) > 129:
                raise ValueError("Embree takes at most 129 motion time steps")
            self._lib.rtcSetGeometryTimeStepCount(geom, len(steps))

    def add_triangles(self, vertices, triangles: np.ndarray, offset=None) -> int:
        """A triangle mesh: vertices (n, 3), or a list of K such arrays (time steps over
        [0, 1]); triangles (m, 3) vertex indices. Returns the geometry id."""
        steps = vertices if isinstance(vertices, (list, tuple)) else [vertices]
        index = np.ascontiguousarray(triangles, dtype=np.int32)
        if index.size and (index.min() < 0 or index.max() >= len(steps[0])):
            raise ValueError("a triangle refers to a vertex that does not exist")
        geom = self._new(L.GEOMETRY_TRIANGLE)
        self._steps(geom, steps)
        for k, verts in enumerate(steps):
            buf = padded_float32(verts, 3, offset)
            self._share(geom, L.BUFFER_VERTEX, k, L.FORMAT_FLOAT3, buf, 12, len(buf))
        self._share(geom, L.BUFFER_INDEX, 0, L.FORMAT_UINT3, index, 12, len(index))
        return self._attach(geom, "triangles", len(index))

    def add_curves(self, control_points, first_point: np.ndarray,
                   kind: int = L.GEOMETRY_ROUND_BSPLINE_CURVE, offset=None,
                   cull_back_faces: bool = False) -> int:
        """Curves: control_points (n, 4) x, y, z, radius (or a list of K time steps);
        first_point (m,) the first control point of each segment (cubic curves read 4
        points from it, linear ones 2). cull_back_faces: rays meet the curves only where
        they enter them (engine.embree.curve_culling), as in Cycles."""
        steps = control_points if isinstance(control_points, (list, tuple)) \
            else [control_points]
        index = np.ascontiguousarray(first_point, dtype=np.int32)
        geom = self._new(kind)
        if cull_back_faces:
            from .curve_culling import filter_address
            address = filter_address()
            self._lib.rtcSetGeometryIntersectFilterFunction(geom, address)
            self._lib.rtcSetGeometryOccludedFilterFunction(geom, address)
        self._steps(geom, steps)
        for k, pts in enumerate(steps):
            buf = padded_float32(pts, 4, _xyz_offset(offset))
            self._share(geom, L.BUFFER_VERTEX, k, L.FORMAT_FLOAT4, buf, 16, len(buf))
        self._share(geom, L.BUFFER_INDEX, 0, L.FORMAT_UINT, index, 4, len(index))
        return self._attach(geom, "curves", len(index))

    def add_points(self, points, kind: int = L.GEOMETRY_SPHERE_POINT, normals=None,
                   offset=None) -> int:
        """Points: (n, 4) x, y, z, radius (or a list of K time steps): spheres, discs
        facing the ray, or discs oriented by `normals` (n, 3)."""
        steps = points if isinstance(points, (list, tuple)) else [points]
        geom = self._new(kind)
        self._steps(geom, steps)
        for k, pts in enumerate(steps):
            buf = padded_float32(pts, 4, _xyz_offset(offset))
            self._share(geom, L.BUFFER_VERTEX, k, L.FORMAT_FLOAT4, buf, 16, len(buf))
        if kind == L.GEOMETRY_ORIENTED_DISC_POINT:
            if normals is None:
                raise ValueError("oriented discs need a normal per point")
            nbuf = padded_float32(normals, 3)
            self._share(geom, L.BUFFER_NORMAL, 0, L.FORMAT_FLOAT3, nbuf, 12, len(nbuf))
        return self._attach(geom, "points", len(steps[0]))

    def add_instance(self, child: "Scene", transforms) -> int:
        """An instance of a committed scene: transforms (4, 4) or (3, 4) object to world,
        or a list of K of them (time steps over [0, 1], matrices interpolated)."""
        if not child.committed:
            raise ValueError("commit a scene before instancing it")
        mats = transforms if isinstance(transforms, (list, tuple)) else [transforms]
        geom = self._new(L.GEOMETRY_INSTANCE)
        self._lib.rtcSetGeometryInstancedScene(geom, child.handle)
        self._steps(geom, mats)
        for k, m in enumerate(mats):
            m = np.asarray(m, np.float64)[:3, :4]
            if not np.all(np.isfinite(m)):
                raise ValueError("an instance's transform is not finite")
            col = np.ascontiguousarray(m.T, dtype=np.float32)   # 4 columns of 3
            self._lib.rtcSetGeometryTransform(geom, k, L.FORMAT_FLOAT3X4_COLUMN_MAJOR,
                                              _pointer(col))
        self._keep.append(child)
        return self._attach(geom, "instance", 1)

    def add_moving_instance(self, child: "Scene", steps: np.ndarray) -> int:
        """An instance of a committed scene moving rigidly over [0, 1]: steps (K, 16)
        rows of Embree's RTCQuaternionDecomposition (scale x, y, z; skew xy, xz, yz;
        shift x, y, z; quaternion r, i, j, k; translation x, y, z), K >= 2 evenly spaced
        time steps, the transform at a step T R S (engine.motion.RigidMotion.embree_steps).
        Embree interpolates S and T linearly and R by spherical linear interpolation."""
        if not child.committed:
            raise ValueError("commit a scene before instancing it")
        rows = np.asarray(steps, np.float64)
        if rows.ndim != 2 or rows.shape[1] != 16 or len(rows) < 2:
            raise ValueError(f"a moving instance needs (K >= 2, 16) steps, got {rows.shape}")
        if not np.all(np.isfinite(rows)):
            raise ValueError("a moving instance's transform is not finite")
        raw = np.zeros(len(rows) * 16 + 4, np.float32)       # RTC_ALIGN(16) structs
        start = (-raw.ctypes.data % 16) // 4
        aligned = raw[start:start + len(rows) * 16].reshape(len(rows), 16)
        aligned[...] = rows
        geom = self._new(L.GEOMETRY_INSTANCE)
        self._lib.rtcSetGeometryInstancedScene(geom, child.handle)
        self._steps(geom, aligned)
        for k in range(len(aligned)):
            self._lib.rtcSetGeometryTransformQuaternion(geom, k, _pointer(aligned[k]))
        check("rtcSetGeometryTransformQuaternion")
        self._keep.append(child)
        return self._attach(geom, "moving instance", 1)

    def add_instance_array(self, child: "Scene", transforms: np.ndarray) -> int:
        """K instances of a committed scene as one Embree instance array: transforms
        (K, 4, 4) or (K, 3, 4) object to world, shared with Embree as one float32 buffer
        (K x 12 floats, column-major), never one geometry per instance. A hit reports
        the array's geometry id as its instance id and the instance's index as its
        element (engine.embree.rays.intersect1)."""
        if not child.committed:
            raise ValueError("commit a scene before instancing it")
        m = np.asarray(transforms, np.float64)
        if m.ndim != 3 or m.shape[1] not in (3, 4) or m.shape[2] != 4:
            raise ValueError(f"instance transforms must be (K, 4, 4), got {m.shape}")
        if not np.all(np.isfinite(m[:, :3, :])):
            raise ValueError("an instance's transform is not finite")
        cols = np.ascontiguousarray(np.transpose(m[:, :3, :], (0, 2, 1)), dtype=np.float32)
        geom = self._new(L.GEOMETRY_INSTANCE_ARRAY)
        self._lib.rtcSetGeometryInstancedScene(geom, child.handle)
        self._share(geom, L.BUFFER_TRANSFORM, 0, L.FORMAT_FLOAT3X4_COLUMN_MAJOR, cols, 48,
                    len(cols))
        self._keep.append(child)
        return self._attach(geom, "instance array", len(cols))

    # -- build ---------------------------------------------------------------------------
    def commit(self) -> "Scene":
        """Build the hierarchy (Embree's builder runs on its own threads)."""
        self._lib.rtcCommitScene(self.handle)
        check("building the scene")
        self.committed = True
        return self

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        box = (ctypes.c_float * 8)()
        self._lib.rtcGetSceneBounds(self.handle, ctypes.addressof(box))
        check("rtcGetSceneBounds")
        return np.array(box[0:3]), np.array(box[4:7])

    def buffer_address(self, geometry: int, buffer_type: int, slot: int = 0) -> int:
        """Where Embree reads one of a geometry's buffers (the shared array's own data)."""
        geom = self._lib.rtcGetGeometry(self.handle, geometry)
        return self._lib.rtcGetGeometryBufferData(geom, buffer_type, slot) or 0

    def release(self) -> None:
        if self.handle:
            self._lib.rtcReleaseScene(self.handle)
            self.handle = None
            self._keep.clear()

    def __del__(self):
        try:
            self.release()
        except Exception:
            pass
