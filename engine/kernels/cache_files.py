"""The engine's cached kernels as files that load wherever the engine is installed, and on
any CPU that can run them.

Numba's cache (an index `.nbi` per function, machine code `.nbc` per signature) holds
pickles, and a pickle names the modules of the classes and functions it holds: a kernel
cached by a source checkout names `engine.kernels.path_vertex`, the same kernel in the
Blender extension lives in `bl_ext.user_default.drt.engine.kernels.path_vertex` (and the
repository's name, `user_default`, is the user's choice). `RelocatingUnpickler` reads
`engine` (and any copy's `...drt.engine`) as whatever this engine package is called
(`ENGINE_PACKAGE`), so a cache built once, by `python -m drt_addon package`, loads in
every installed copy, and a cache written by one copy loads in the others.

Numba keys each signature's code by the CPU it was compiled for: its LLVM target triple,
CPU name and feature list ("magic tuple"), and loads only code compiled for the very CPU
it runs on. Code compiled for a CPU tier runs on every CPU with that tier's instructions:
`compatible` accepts code compiled for `generic` x86-64 everywhere, and for a named x86-64
level or an explicit feature list where the running CPU has every feature it needs. The
extension ships the `x86-64-v3` and `generic` tiers (`engine/kernels/prebuilt` inside the
zip, drt_addon/prebuilt_kernels.py); `EngineFunctionCache` (kernel_cache.py) looks there when the writable
cache has no code for this CPU.
"""
from __future__ import annotations

import functools
import io
import os
import pickle

from numba.core import caching
from numba.core.environment import _rebuild_env

# this package's name: "engine" in a source checkout, "bl_ext.<repo>.drt.engine" installed
ENGINE_PACKAGE = __name__.rsplit(".kernels.", 1)[0]

# The instructions each x86-64 level adds (LLVM's feature names), as the psABI defines them.
X86_64_LEVELS = {
    "x86-64": (),
    "x86-64-v2": ("cx16", "popcnt", "sse3", "sse4.1", "sse4.2", "ssse3", "sahf"),
    "x86-64-v3": ("cx16", "popcnt", "sse3", "sse4.1", "sse4.2", "ssse3", "sahf", "avx",
                  "avx2", "bmi", "bmi2", "f16c", "fma", "lzcnt", "movbe", "xsave"),
}
SHIPPED_TIERS = ("x86-64-v3", "generic")    # what the extension zip holds, best first


def canonical_module(module: str) -> str:
    """A module name as it is in this process: `engine.x`, and the engine of any copy of
    the add-on (`drt.engine.x` as a legacy add-on, `bl_ext.<repo>.drt.engine.x` as an
    extension), -> ENGINE_PACKAGE + `.x`. Caches are shared: Debian's Blender and the
    `bpy` module render from one checkout's cache (tests/test_debian_blender.py)."""
    parts = module.split(".")
    for i, part in enumerate(parts):
        if part == "engine" and (i == 0 or parts[i - 1] == "drt"):
            return ".".join([ENGINE_PACKAGE, *parts[i + 1:]])
    return module


def _relocated_env(modname, consts, env_name):
    """Numba's `_rebuild_env`, which imports the kernel's module by name."""
    return _rebuild_env(canonical_module(modname), consts, env_name)


class RelocatingUnpickler(pickle.Unpickler):
    """Reads `engine.*` references as this engine package's modules."""

    def find_class(self, module, name):
        found = super().find_class(canonical_module(module), name)
        return _relocated_env if found is _rebuild_env else found


def relocating_loads(data: bytes):
    return RelocatingUnpickler(io.BytesIO(data)).load()


def _features(text: str) -> set[str]:
    return {f[1:] for f in text.split(",") if f.startswith("+")}


@functools.lru_cache(maxsize=1)
def host_features() -> frozenset[str]:
    """The instruction-set features of this CPU (asked of LLVM once per process)."""
    from llvmlite import binding as ll
    return frozenset(name for name, on in ll.get_host_cpu_features().items() if on)


def compatible(magic, host_magic, host: set[str]) -> bool:
    """Whether code compiled for `magic` (triple, CPU name, features) runs here."""
    triple, cpu, features = magic
    if triple != host_magic[0]:
        return False
    if cpu == "generic" and not features:
        return True
    if cpu != host_magic[1] and cpu not in X86_64_LEVELS:
        return False             # a named CPU's instructions are not spelled out
    need = _features(features) | set(X86_64_LEVELS.get(cpu, ()))
    return need <= host


class RelocatableCacheFile(caching.IndexDataCacheFile):
    """Numba's index and data files, read with `RelocatingUnpickler`; `compatible_key`
    finds, for a key of this CPU, the key of code compiled for a compatible one, and
    `load_compatible` loads that code reading the index once."""

    def _load_index(self):
        try:
            with open(self._index_path, "rb") as f:
                version = pickle.load(f)
                data = f.read()
        except FileNotFoundError:
            return {}
        if version != self._version:
            return {}
        try:
            stamp, overloads = relocating_loads(data)
        except (ImportError, AttributeError):     # names a module this engine lacks
            return {}
        return overloads if stamp == self._source_stamp else {}

    def _load_data(self, name):
        with open(self._data_path(name), "rb") as f:
            return relocating_loads(f.read())

    def load_compatible(self, key, exact=False):
        """The cached data of `compatible_key(key, exact)`, or None (the index is read
        once: Numba's `load` would read it again)."""
        overloads = self._load_index()
        found = self.compatible_key(key, exact, overloads)
        if found is None:
            return None
        try:
            return self._load_data(overloads[found])
        except OSError:                            # removed meanwhile: compile instead
            return None

    def compatible_key(self, key, exact=False, overloads=None):
        """The index's key for the same signature and code compiled for a CPU this one
        can run (the host's own first, then the tier with the most features; only the
        host's own when `exact`), or None. `overloads`: the index, if already read."""
        sig, host_magic, code = key
        if overloads is None:
            overloads = self._load_index()
        if key in overloads or exact:
            return key if key in overloads else None
        host = host_features()
        found = [k for k in overloads if k[0] == sig and k[2] == code
                 and compatible(k[1], host_magic, host)]
        found.sort(key=lambda k: -len(_features(k[1][2]) | set(X86_64_LEVELS.get(k[1][1], ()))))
        return found[0] if found else None


def tier_environment(tier: str) -> dict:
    """The environment that makes Numba compile for `tier` (`python -m drt_addon package`
    builds the shipped caches in subprocesses with it)."""
    if tier == "generic":
        return {"NUMBA_CPU_NAME": "generic"}      # Numba's features are then none
    return {"NUMBA_CPU_NAME": tier,
            "NUMBA_CPU_FEATURES": ",".join("+" + f for f in X86_64_LEVELS[tier])}


def shipped_root(engine_dir: str, cache_root: str | None) -> str | None:
    """The read-only cache a package ships beside the sources, when it is not the
    writable cache itself."""
    root = os.path.join(engine_dir, "kernels", "prebuilt")
    if not os.path.isdir(root):
        return None
    if cache_root is not None and os.path.realpath(root) == os.path.realpath(cache_root):
        return None
    return root
