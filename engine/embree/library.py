"""Intel Embree 4, loaded once per process from the library the `embreex` wheel ships.

DRT calls Embree's C API itself (ctypes for building scenes in Python, and the two ray
queries from compiled kernels). `embreex` stays only as the package that ships the
library: its wheels carry Embree 4.4 with TBB for Linux, macOS and Windows
(`embreex.libs/libembree4-*.so.4`, `embreex/.dylibs/libembree4*.dylib`,
`embreex.libs/embree4*.dll`), and that file exports the whole C API. Its Python binding
is not used: it holds triangles only and copies them element by element.

Loading: the library is opened by its path, so a process holds one copy of Embree even
when something else (embreex's own modules) opened the same file. On Linux it is opened
with RTLD_DEEPBIND: inside a Blender binary that exports its own Embree's `rtc*`
symbols, Embree's internal calls still bind to its own functions.

Kernels: `register_kernel_symbols()` gives the addresses of `rtcIntersect1` and
`rtcOccluded1` to LLVM under the names `drt_rtcIntersect1` / `drt_rtcOccluded1`, which
the ray kernels declare as external functions (`engine.embree.rays`). Numba caches such
kernels (it would not cache one that calls a ctypes pointer); the symbols must be
registered before any of them is loaded, which importing `engine.embree.rays` does.
"""
from __future__ import annotations

import ctypes
import glob
import importlib.util
import os
import sys
import threading
from ctypes import c_bool, c_char_p, c_float, c_int, c_size_t, c_uint, c_void_p

# -- constants of the C API (rtcore_common.h, rtcore_geometry.h, rtcore_buffer.h) -------
INVALID_ID = 0xFFFFFFFF
GEOMETRY_TRIANGLE = 0
GEOMETRY_ROUND_LINEAR_CURVE = 16
GEOMETRY_FLAT_LINEAR_CURVE = 17
GEOMETRY_ROUND_BEZIER_CURVE = 24
GEOMETRY_FLAT_BEZIER_CURVE = 25
GEOMETRY_ROUND_BSPLINE_CURVE = 32
GEOMETRY_ROUND_CATMULL_ROM_CURVE = 58
GEOMETRY_SPHERE_POINT = 50
GEOMETRY_DISC_POINT = 51
GEOMETRY_ORIENTED_DISC_POINT = 52
GEOMETRY_INSTANCE = 121
GEOMETRY_INSTANCE_ARRAY = 122
BUFFER_INDEX, BUFFER_VERTEX, BUFFER_NORMAL, BUFFER_TRANSFORM = 0, 1, 3, 23
FORMAT_UINT, FORMAT_UINT3 = 0x5001, 0x5003
FORMAT_FLOAT3, FORMAT_FLOAT4 = 0x9003, 0x9004
FORMAT_FLOAT3X4_COLUMN_MAJOR = 0x9234
SCENE_FLAG_NONE, SCENE_FLAG_DYNAMIC, SCENE_FLAG_COMPACT, SCENE_FLAG_ROBUST = 0, 1, 2, 4
SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS = 8
BUILD_QUALITY_LOW, BUILD_QUALITY_MEDIUM, BUILD_QUALITY_HIGH = 0, 1, 2
ERROR_NAMES = {0: "none", 1: "unknown", 2: "invalid argument", 3: "invalid operation",
               4: "out of memory", 5: "unsupported CPU", 6: "cancelled"}

KERNEL_SYMBOLS = {"drt_rtcIntersect1": "rtcIntersect1",
                  "drt_rtcOccluded1": "rtcOccluded1"}


def _candidates() -> list[str]:
    """Where the embreex wheel keeps the Embree library, on each platform."""
    spec = importlib.util.find_spec("embreex")
    if spec is None or not spec.submodule_search_locations:
        return []
    package = list(spec.submodule_search_locations)[0]
    site = os.path.dirname(package)
    patterns = [os.path.join(site, "embreex.libs", "libembree4*.so*"),
                os.path.join(package, ".dylibs", "libembree4*.dylib"),
                os.path.join(site, "embreex.libs", "embree4*.dll"),
                os.path.join(package, "libembree4*"), os.path.join(package, "embree4*.dll")]
    found = []
    for pattern in patterns:
        found += sorted(glob.glob(pattern))
    return found


def library_path() -> str:
    """The Embree library's path (DRT_EMBREE_LIBRARY overrides the search)."""
    override = os.environ.get("DRT_EMBREE_LIBRARY")
    if override:
        return override
    found = _candidates()
    if not found:
        raise ImportError("Intel Embree 4 was not found: DRT loads it from the embreex "
                          "wheel (pip install embreex==4.4.0.post1)")
    return found[0]


def _prototypes(lib) -> None:
    """ctypes signatures of the calls made from Python (handles are void pointers)."""
    sig = {
        "rtcNewDevice": (c_void_p, [c_char_p]),
        "rtcReleaseDevice": (None, [c_void_p]),
        "rtcGetDeviceError": (c_int, [c_void_p]),
        "rtcGetDeviceLastErrorMessage": (c_char_p, [c_void_p]),
        "rtcNewScene": (c_void_p, [c_void_p]),
        "rtcReleaseScene": (None, [c_void_p]),
        "rtcSetSceneFlags": (None, [c_void_p, c_int]),
        "rtcSetSceneBuildQuality": (None, [c_void_p, c_int]),
        "rtcCommitScene": (None, [c_void_p]),
        "rtcAttachGeometry": (c_uint, [c_void_p, c_void_p]),
        "rtcNewGeometry": (c_void_p, [c_void_p, c_int]),
        "rtcReleaseGeometry": (None, [c_void_p]),
        "rtcCommitGeometry": (None, [c_void_p]),
        "rtcSetGeometryBuildQuality": (None, [c_void_p, c_int]),
        "rtcSetGeometryTimeStepCount": (None, [c_void_p, c_uint]),
        "rtcSetGeometryTimeRange": (None, [c_void_p, c_float, c_float]),
        "rtcSetGeometryMask": (None, [c_void_p, c_uint]),
        "rtcSetSharedGeometryBuffer": (None, [c_void_p, c_int, c_uint, c_int, c_void_p,
                                              c_size_t, c_size_t, c_size_t]),
        "rtcSetGeometryInstancedScene": (None, [c_void_p, c_void_p]),
        "rtcSetGeometryTransform": (None, [c_void_p, c_uint, c_int, c_void_p]),
        "rtcSetGeometryTransformQuaternion": (None, [c_void_p, c_uint, c_void_p]),
        "rtcGetSceneBounds": (None, [c_void_p, c_void_p]),
        "rtcGetGeometry": (c_void_p, [c_void_p, c_uint]),
        "rtcGetGeometryBufferData": (c_void_p, [c_void_p, c_int, c_uint]),
        "rtcIntersect1": (None, [c_void_p, c_void_p, c_void_p]),
        "rtcOccluded1": (None, [c_void_p, c_void_p, c_void_p]),
        "rtcSetGeometryEnableFilterFunctionFromArguments": (None, [c_void_p, c_bool]),
        "rtcSetGeometryIntersectFilterFunction": (None, [c_void_p, c_void_p]),
        "rtcSetGeometryOccludedFilterFunction": (None, [c_void_p, c_void_p]),
    }
    for name, (restype, argtypes) in sig.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes


_LIB = None
_LOCK = threading.Lock()
_REGISTERED = False


def load():
    """The Embree library (ctypes), opened on first use and kept for the process."""
    global _LIB
    with _LOCK:
        if _LIB is None:
            path = library_path()
            mode = ctypes.RTLD_LOCAL
            if sys.platform.startswith("linux"):
                mode |= os.RTLD_DEEPBIND
            lib = ctypes.CDLL(path, mode=mode)
            _prototypes(lib)
            lib.drt_path = path
            _LIB = lib
        return _LIB


def function_address(name: str) -> int:
    """The address of one of Embree's exported functions."""
    return ctypes.cast(getattr(load(), name), c_void_p).value


def register_kernel_symbols() -> None:
    """Tell LLVM where the kernels' Embree calls are (before any kernel loads)."""
    global _REGISTERED
    if _REGISTERED:
        return
    from llvmlite import binding
    for alias, name in KERNEL_SYMBOLS.items():
        binding.add_symbol(alias, function_address(name))
    _REGISTERED = True
