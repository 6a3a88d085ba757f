"""The one decorator every compiled kernel uses, and where compiled code is cached.

`kernel` is Numba's `njit` with the GIL released (`nogil=True`), so work units on
threads run in parallel, and with an on-disk cache so a second render starts at once.

Cache location, in order:
  1. `NUMBA_CACHE_DIR` when the user (or the Blender add-on) sets it;
  2. Numba's own choice: `__pycache__` beside the source, else a per-user cache folder;
  3. nowhere: when no cache location can be written (a read-only install with a
     read-only home), kernels compile in memory on every process start instead of
     failing. `DRT_NUMBA_CACHE=0` forces this (a test and debug switch).
"""
from __future__ import annotations

import os
import tempfile

from numba import njit


def _writable(folder: str) -> bool:
    try:
        os.makedirs(folder, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".drt-probe-"):
            pass
        return True
    except OSError:
        return False


def _cache_possible() -> bool:
    if os.environ.get("DRT_NUMBA_CACHE", "1") == "0":
        return False
    explicit = os.environ.get("NUMBA_CACHE_DIR")
    if explicit:
        return _writable(explicit)
    beside = os.path.join(os.path.dirname(os.path.abspath(__file__)), "__pycache__")
    if _writable(beside):
        return True
    # Numba's per-user fallback (its _UserWideCacheLocator)
    try:
        from numba.misc.appdirs import AppDirs
        return _writable(AppDirs(appname="numba", appauthor=False).user_cache_dir)
    except Exception:
        return False


CACHE = _cache_possible()


def kernel(fn=None, **options):
    """@kernel or @kernel(inline='always', ...): njit, GIL released, cached when possible.
    Floating-point semantics stay IEEE (no fastmath), so results match the NumPy
    reference implementations bit for bit where the operations are the same."""
    opts = dict(nogil=True, cache=CACHE, error_model="numpy")
    opts.update(options)
    if fn is None:
        return lambda f: njit(**opts)(f)
    return njit(**opts)(fn)
