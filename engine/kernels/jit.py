"""The one decorator every compiled kernel uses.

`kernel` is Numba's `njit` with the GIL released (`nogil=True`), so work units on
threads run in parallel, and with an on-disk cache so a second render starts at once
(where compiled code is kept and how it is keyed: kernel_cache.py).
`DRT_BORROWING=0` compiles every kernel with reference counting, to measure what
borrowing saves (docs/borrowing_benchmark.py); it has its own cache fingerprint.
"""
from __future__ import annotations

import threading

from numba import njit, types
from numba.core import event

from .kernel_cache import BORROWING, LOADS, EngineFunctionCache
from .tuple_ref import TupleRef


class Kernel:
    """A compiled kernel, made on first use: its Numba dispatchers (`njit(...)(py_func)`
    with the engine's cache) are created when the kernel is first called, compiled or
    typed, not when its module is imported. The engine defines about 700 kernels; a
    render loads six of them from the cache, and the rest are never used as dispatchers
    (the six hold their callees' machine code). Creating them all cost about 0.1 s of
    every process's first render (each dispatcher inspects its function's signature
    twice and sets up its cache).

    Two dispatchers, one per kind of caller:
    - `dispatcher`, for calls from Python: Numba's usual function, with the wrappers
      that convert Python objects to native arguments and back;
    - `callee`, for calls from other kernels (Numba sees a Kernel as it: `_numba_type_`,
      the typing of a global, a closure variable or an argument). It is compiled without
      those wrappers (`no_cpython_wrapper`, `no_cfunc_wrapper`), which a function only
      kernels call never runs: for a small kernel taking the light table, the wrapper that
      unboxes its twenty arrays is larger than the kernel itself, and Numba optimises
      and generates machine code for it all the same: with them, nearly a quarter of
      a first render's compile went to wrappers no kernel calls (docs/benchmarks.md,
      section 10, times the first run). A kernel called both ways (a test calling a callee from
      Python) compiles once for each.
    `targetoptions` and `py_func` (inlining) are the dispatcher's."""

    _lock = threading.Lock()
    CALLEE_OPTIONS = dict(no_cpython_wrapper=True, no_cfunc_wrapper=True)

    def __init__(self, py_func, options: dict):
        self.py_func = py_func
        self._options = options
        self._dispatcher = None
        self._callee = None
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__module__ = py_func.__module__
        self.__doc__ = py_func.__doc__

    def _make(self, options: dict, variant: str):
        made = njit(**options)(self.py_func)
        if LOADS and self._options.get("cache", True) and hasattr(made, "_cache"):
            # Numba's `cache=True`, with the engine's cache class
            made._cache = EngineFunctionCache(self.py_func, variant)
        return made

    @property
    def dispatcher(self):
        """The dispatcher for calls from Python, created once (threads may ask at the
        same time)."""
        dispatcher = self._dispatcher
        if dispatcher is None:
            with Kernel._lock:
                if self._dispatcher is None:
                    self._dispatcher = self._make(self._options, "")
                dispatcher = self._dispatcher
        return dispatcher

    @property
    def callee(self):
        """The dispatcher for calls from kernels, without Python's wrappers."""
        callee = self._callee
        if callee is None:
            with Kernel._lock:
                if self._callee is None:
                    self._callee = self._make({**self._options, **Kernel.CALLEE_OPTIONS},
                                              ".callee")
                callee = self._callee
        return callee

    @property
    def realized(self) -> bool:
        """Whether a dispatcher exists (the kernel was called, compiled or typed)."""
        return self._dispatcher is not None or self._callee is not None

    @property
    def _numba_type_(self):
        return self.callee._numba_type_

    def __call__(self, *args, **kwargs):
        return self.dispatcher(*args, **kwargs)

    def __getattr__(self, name):
        # targetoptions, compile, signatures, stats, overloads, ...: the dispatcher's
        if name in ("py_func", "_options", "_dispatcher", "_callee"):   # not set yet (a copy)
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __repr__(self):
        return f"<kernel {self.__module__}.{self.__qualname__}>"


def kernel(fn=None, *, allocates=True, **options):
    """@kernel or @kernel(option=...): njit, GIL released, cached when possible (a
    `Kernel`: its dispatcher is made on first use).
    Floating-point semantics stay IEEE (no fastmath), so results match the NumPy
    reference implementations bit for bit where the operations are the same.

    allocates=False marks a function that kernels call per ray, that creates no array
    and returns none (scalars, or tuples of them): it is compiled without Numba's
    reference counting (`_nrt=False`). Its arrays are borrowed from the caller, which
    holds them for the call. Counted, every array it is given, also each array of a
    tuple such as the light table, costs an atomic increment on entry and a decrement on
    return, per call: docs/benchmarks.md, section 1, measures what that costs a Cornell
    box render (docs/borrowing_benchmark.py). Numba refuses to compile
    such a function if it allocates, or returns a new array or a view; `BorrowingCheck`
    refuses one that returns an argument array. tests/test_kernel_borrowing.py checks
    both and that renders leak no allocation."""
    opts = dict(nogil=True, error_model="numpy")
    if not allocates and BORROWING:
        opts["_nrt"] = False
    opts.update(options)

    def compiled(f):
        return Kernel(f, opts)
    return compiled if fn is None else compiled(fn)


def callback(py_func, sig):
    """py_func as a C callback (Numba's cfunc, nopython), for Embree to call (its filter
    functions: engine.embree.self_hits, curve_culling), loaded from or saved to the
    engine's cache like every kernel: relocatable to any name of the engine package, and
    read from the kernels an extension zip ships (Numba's own cfunc cache would pickle
    the module's name and write beside the shipped kernels)."""
    from numba.core import sigutils
    from numba.core.ccallback import CFunc
    made = CFunc(py_func, sigutils.normalize_signature(sig), locals={},
                 options=dict(nopython=True))
    if LOADS:
        made._cache = EngineFunctionCache(py_func, ".cfunc")
    made.compile()
    return made


_FILTERS: dict = {}


def filter_address(py_func, plain) -> int:
    """The address of an Embree filter function (RTCFilterFunctionN: one pointer to its
    arguments): py_func as a `callback`, made once per process; when kernels run as plain
    Python (NUMBA_DISABLE_JIT=1), a ctypes callback of `plain`, which reads the
    arguments through ctypes."""
    import ctypes
    from numba.core import config
    if py_func not in _FILTERS:
        if config.DISABLE_JIT:
            proto = ctypes.CFUNCTYPE(None, ctypes.POINTER(ctypes.c_uint64))
            made = proto(plain)
            _FILTERS[py_func] = (made, ctypes.cast(made, ctypes.c_void_p).value)
        else:
            made = callback(py_func, types.void(types.CPointer(types.uint64)))
            _FILTERS[py_func] = (made, made.address)
    return _FILTERS[py_func][1]


def holds_array(ty, kind=types.ArrayCompatible) -> bool:
    """Whether a Numba type is, or is a tuple holding, an array (or a `kind`)."""
    if isinstance(ty, kind):
        return True
    if isinstance(ty, types.BaseTuple):
        return any(holds_array(t, kind) for t in ty.types)
    return False


class BorrowingCheck(event.Listener):
    """Refuses, as it compiles, a kernel without reference counting whose result holds
    an array: its caller would release a reference the kernel never took; and any kernel
    whose result holds a tuple_ref.TupleRef, which points into the kernel's own frame."""

    def on_start(self, ev):
        pass

    def on_end(self, ev):
        dispatcher = (ev.data or {}).get("dispatcher")
        if dispatcher is None:
            return
        made_here = dispatcher.py_func.__module__ == TupleRef.__module__   # by_ref's own
        for sig, cres in list(dispatcher.overloads.items()):
            if not made_here and holds_array(cres.signature.return_type, TupleRef):
                raise TypeError(f"{dispatcher.py_func.__qualname__}{sig} returns a "
                                "reference to a tuple in its own frame (tuple_ref.by_ref)")
        if dispatcher.targetoptions.get("_nrt") is not False:
            return
        for sig, cres in list(dispatcher.overloads.items()):
            if holds_array(cres.signature.return_type):
                raise TypeError(f"{dispatcher.py_func.__qualname__}{sig} returns an array but "
                                "is marked @kernel(allocates=False)")


event.register("numba:compile", BorrowingCheck())
