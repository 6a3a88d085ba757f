"""Where compiled kernels are cached, and how the cache is keyed.

The cache is keyed by all the engine sources compiled code can depend on, not by each
function's own file as Numba does by default: a kernel inlines the kernels it calls, so a
change to a callee in another module (or an upgraded add-on) must recompile its callers.
`EngineCacheLocator` stamps every cached kernel of the `engine` package with one
fingerprint: the SHA-256 of the Numba version and of `kernel_sources()`, every module
that defines kernels and every engine module they import, transitively. A module no
kernel reaches (engine/denoiser.py, say) changes nothing compiled.

Cache folder, the first writable of:
  1. `NUMBA_CACHE_DIR` when set (the Blender add-on points it at the extension's user
     folder, since an installed extension's own folder may be read-only);
  2. `engine/kernels/__pycache__/numba` beside the sources;
  3. a per-user cache folder (`drt-numba` in Numba's user cache location).
When none can be written, kernels compile in memory on every process start instead of
failing. A package's shipped kernels (`engine/kernels/prebuilt`, compiled for CPU tiers by
`python -m drt_addon package`) are read when that cache has none for this CPU, writable
or not; files load under any name of the engine package (cache_files.py).
Processes sharing the cache compile each kernel once: the others wait and load it
(compile_lock.py).
`DRT_NUMBA_CACHE=0` compiles every kernel in memory (a test and debug switch).
"""
from __future__ import annotations

import glob
import hashlib
import inspect
import os
import re
import tempfile

import numba
from numba.core import caching
from numba.core.runtime import rtsys

from . import cache_files, compile_lock

ENGINE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _writable(folder: str) -> bool:
    try:
        os.makedirs(folder, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".drt-probe-"):
            pass
        return True
    except OSError:
        return False


def _cache_root() -> str | None:
    if os.environ.get("DRT_NUMBA_CACHE", "1") == "0":
        return None
    candidates = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        candidates.append(os.path.join(os.environ["NUMBA_CACHE_DIR"], "drt"))
    candidates.append(os.path.join(ENGINE_DIR, "kernels", "__pycache__", "numba"))
    try:
        from numba.misc.appdirs import AppDirs
        candidates.append(os.path.join(AppDirs(appname="numba", appauthor=False)
                                       .user_cache_dir, "drt-numba"))
    except Exception:
        pass
    for folder in candidates:
        if _writable(folder):
            return folder
    return None


BORROWING = os.environ.get("DRT_BORROWING", "1") != "0"


def _module_name(path: str) -> str:
    rel = os.path.relpath(path, ENGINE_DIR)[:-len(".py")].split(os.sep)
    return ".".join(["engine", *(rel[:-1] if rel[-1] == "__init__" else rel)])


_FROM_IMPORT = re.compile(r"^[ \t]*from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+"
                          r"(\([^)]*\)|[^\n]*)", re.MULTILINE)
_KERNEL = re.compile(r"^[ \t]*@kernel\b", re.MULTILINE)


def _imported(text: str, path: str, name: str, modules: dict) -> set:
    """The engine modules (names in `modules`) that module `name` (its source `text`, at
    `path`) imports. The engine imports its own modules relatively, `from .x import y`."""
    package = name if path.endswith("__init__.py") else name.rsplit(".", 1)[0]
    found = set()
    for dots, module, names in _FROM_IMPORT.findall(text):
        if dots:
            base = package.rsplit(".", len(dots) - 1)[0] if len(dots) > 1 else package
            module = ".".join(p for p in (base, module) if p)
        names = re.sub(r"#[^\n]*", "", names).strip().strip("()").replace("\\", " ")
        names = [n.split()[0] for n in names.split(",") if n.split()]
        # `from .pkg import mod` reads the submodule; any other name comes from the
        # module (or the package's __init__) itself
        subs = {f"{module}.{n}" for n in names} & modules.keys()
        found.update(subs)
        if len(subs) < len(names) and module in modules:
            found.add(module)
    return found


def kernel_sources() -> list:
    """The engine's source files compiled code can depend on: every module that defines
    kernels (a function decorated with `@kernel`), this one, and transitively every
    engine module they import. A module no kernel reaches (the denoiser, the
    integrators' Python loops, the scene description) can change without recompiling
    anything."""
    paths = glob.glob(os.path.join(ENGINE_DIR, "**", "*.py"), recursive=True)
    modules = {_module_name(p): p for p in paths}
    texts = {}
    for n, p in modules.items():
        with open(p, encoding="utf-8") as f:
            texts[n] = f.read()
    imports = {n: _imported(texts[n], modules[n], n, modules) for n in modules}
    todo = [n for n in modules if _KERNEL.search(texts[n])] + ["engine.kernels.jit"]
    seen = set()
    while todo:
        n = todo.pop()
        if n not in seen:
            seen.add(n)
            todo.extend(imports[n])
    return sorted(modules[n] for n in seen)


def _fingerprint() -> bytes:
    """SHA-256 of Numba's version and the sources compiled code can depend on."""
    h = hashlib.sha256(numba.__version__.encode())
    if not BORROWING:
        h.update(b"reference counting everywhere")
    for path in kernel_sources():
        h.update(os.path.relpath(path, ENGINE_DIR).encode())
        with open(path, "rb") as f:
            h.update(f.read())
    return h.digest()


CACHE_ROOT = _cache_root()
CACHE = CACHE_ROOT is not None
# The kernels a package ships, compiled for CPU tiers (cache_files.py), read even where
# nothing can be written; never with DRT_NUMBA_CACHE=0, which compiles everything.
SHIPPED_ROOT = (None if os.environ.get("DRT_NUMBA_CACHE", "1") == "0"
                else cache_files.shipped_root(ENGINE_DIR, CACHE_ROOT))
LOADS = CACHE or SHIPPED_ROOT is not None
FINGERPRINT = _fingerprint() if LOADS else b""


class EngineCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """Caches the engine's kernels under CACHE_ROOT, stamped with the engine-wide
    FINGERPRINT; functions outside the engine package are left to Numba's locators."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(CACHE_ROOT or SHIPPED_ROOT,
                                        self.get_suitable_cache_subpath(py_file))

    def get_cache_path(self):
        return self._cache_path

    @classmethod
    def get_suitable_cache_subpath(cls, py_file):
        """The source's folder relative to the engine (`kernels_bsdf`), not Numba's hash
        of its absolute path: a cache built in one place (a source checkout, the
        extension package's build) loads wherever the engine is installed."""
        rel = os.path.relpath(os.path.dirname(os.path.abspath(py_file)), ENGINE_DIR)
        return "engine" if rel == "." else "engine_" + rel.replace(os.sep, "_")

    def get_source_stamp(self):
        return FINGERPRINT

    @classmethod
    def from_function(cls, py_func, py_file):
        if not LOADS or not os.path.abspath(py_file).startswith(ENGINE_DIR + os.sep):
            return None
        return super().from_function(py_func, py_file)

    _ensured: set = set()

    def ensure_cache_path(self):
        """Numba creates the folder and writes a probe file in it for every kernel (~450
        per process); once per folder is enough."""
        if not CACHE:          # the shipped kernels only: read, never written
            return
        if self._cache_path not in EngineCacheLocator._ensured:
            super().ensure_cache_path()
            EngineCacheLocator._ensured.add(self._cache_path)


class EngineFunctionCache(caching.FunctionCache):
    """Numba's on-disk cache of one kernel, loading it without first refreshing Numba's
    typing and lowering registries (Numba's `load_overload` does, to be ready to
    compile): that imports and installs every registry of Numba (its NumPy, linalg and
    random implementations, SciPy's BLAS where SciPy is installed), about 0.2 s of every
    process's first render, and machine code read from the cache needs none of it, only
    the runtime its allocations call (`rtsys`). A kernel that does compile goes through
    Numba's pipeline, which refreshes them then."""

    def __init__(self, py_func, variant: str = ""):
        super().__init__(py_func)
        stamp, base = self._impl.locator.get_source_stamp(), self._impl.filename_base
        base += variant        # a kernel's two dispatchers keep their code apart (Kernel)
        # the cache's files read by whatever name this engine package has (none when
        # nothing can be written: the shipped kernels are then the only ones on disk)
        self._cache_file = (cache_files.RelocatableCacheFile(self._cache_path, base, stamp)
                            if CACHE else None)
        self._lock_path = os.path.join(self._cache_path, base + ".lock")
        self._shipped = None
        if SHIPPED_ROOT is not None:
            sub = EngineCacheLocator.get_suitable_cache_subpath(inspect.getfile(py_func))
            self._shipped = cache_files.RelocatableCacheFile(
                os.path.join(SHIPPED_ROOT, sub), base, stamp)

    def load_overload(self, sig, target_context):
        """The cached code, or None after taking this kernel's compile lock (another
        process compiling it meanwhile is waited for, and its code loaded)."""
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            data = self._load_overload(sig, target_context)
            if data is None and self._cache_file is not None:
                self._impl.locator.ensure_cache_path()
                if compile_lock.acquire(self._lock_path):
                    data = self._load_overload(sig, target_context)
                    if data is not None:
                        compile_lock.release(self._lock_path)
            return data

    def _load_overload(self, sig, target_context):
        """This CPU's code from the writable cache, else code for a CPU tier this one can
        run, from the writable cache or the one the package ships (cache_files)."""
        if not self._enabled:
            return None
        key = self._index_key(sig, target_context.codegen())
        for files, exact in ((self._cache_file, True), (self._shipped, False)):
            data = files.load_compatible(key, exact) if files is not None else None
            if data is not None:
                return self._impl.rebuild(target_context, data)
        return None

    def _save_overload(self, sig, data):
        if self._cache_file is not None:       # else compiled in memory only
            try:
                super()._save_overload(sig, data)
            finally:
                compile_lock.release(self._lock_path)


if LOADS and EngineCacheLocator not in caching.CacheImpl._locator_classes:
    caching.CacheImpl._locator_classes.insert(0, EngineCacheLocator)
