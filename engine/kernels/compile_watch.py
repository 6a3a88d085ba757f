"""Kernels compiled while a render runs: counted as Numba compiles them, out of the
kernels the render can reach, so that a first render says "compiling kernels, one time:
N of M" instead of a sample rate, and its time estimate leaves the compile out.

M is read off the code, not guessed: the kernels that the render's entry kernels name,
and the kernels those name, and so on (`reachable`). It is an upper bound: a kernel named
in a branch Numba prunes is never compiled, so a render may finish with N below M.
A kernel loaded from the on-disk cache is not compiled and not counted.
"""
from __future__ import annotations

import threading
import time
import types

from numba.core import event

from .jit import Kernel


ENGINE = __name__.rsplit(".kernels.", 1)[0]      # "engine", or the extension's name of it


def _named(code, scope: dict) -> list:
    """The objects a function's code refers to by global name, with one level of
    attributes of the engine's modules (`bsdf.setup`), its nested functions' too."""
    found = []
    for name in code.co_names:
        obj = scope.get(name)
        if isinstance(obj, types.ModuleType):
            if not obj.__name__.startswith(ENGINE + "."):
                continue
            found += [getattr(obj, a) for a in code.co_names if hasattr(obj, a)]
        elif obj is not None:
            found.append(obj)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            found += _named(const, scope)
    return found


def reachable(entries) -> set:
    """The Python functions of every kernel reachable from the entry kernels."""
    seen, todo = set(), [k for k in entries if isinstance(k, Kernel)]
    while todo:
        k = todo.pop()
        fn = k.py_func
        if fn in seen:
            continue
        seen.add(fn)
        scope = fn.__globals__
        if fn.__closure__:
            scope = {**scope, **dict(zip(fn.__code__.co_freevars,
                                         (c.cell_contents for c in fn.__closure__)))}
        todo += [o for o in _named(fn.__code__, scope)
                 if isinstance(o, Kernel) and o.py_func not in seen]
    return seen


class CompileWatch(event.Listener):
    """Counts the reachable kernels Numba compiles, and the seconds it spends compiling
    (outermost compiles only: Numba compiles one function at a time, callees inside
    their caller's compile)."""

    def __init__(self, functions: set):
        self.functions = functions
        self.total = len(functions)
        self.done: set = set()
        self.seconds = 0.0
        self._depth = 0
        self._t0 = 0.0
        self._lock = threading.Lock()

    @property
    def compiling(self) -> bool:
        return self._depth > 0

    def on_start(self, ev):
        with self._lock:
            if self._depth == 0:
                self._t0 = time.perf_counter()
            self._depth += 1

    def on_end(self, ev):
        with self._lock:
            self._depth -= 1
            if self._depth == 0:
                self.seconds += time.perf_counter() - self._t0
            dispatcher = (ev.data or {}).get("dispatcher")
            fn = getattr(dispatcher, "py_func", None)
            if fn in self.functions:
                self.done.add(fn)

    def __enter__(self):
        event.register("numba:compile", self)
        return self

    def __exit__(self, *exc):
        event.unregister("numba:compile", self)
        return False
