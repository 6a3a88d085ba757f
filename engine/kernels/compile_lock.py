"""One process compiles a kernel; the others wait for it and load it from the cache.

Processes that share a kernel cache (the test suite's workers, `python -m drt_addon
compile`'s parallel jobs, a render farm's frames on one machine) would each compile a
kernel none of them finds cached, and all but one would throw the work away. Before
compiling, a process takes an exclusive lock on the kernel's lock file beside its cache
index (`fcntl.flock`: released by the kernel, also when a process dies), then looks in
the cache again: a process that waited finds the kernel the other one saved and loads
it. The lock is per function, and is let go when its code is saved. Kernels call
kernels but never their callers, so processes that wait on each other's locks never
wait in a cycle; a lock that is not let go within WAIT_SECONDS (a process stopped in a
debugger) is passed by, and the kernel compiled anyway.

Where locking is not possible (no `fcntl` on Windows, a cache folder that cannot hold
the file) kernels compile as before, each process on its own.
"""
from __future__ import annotations

import os
import time

try:
    import fcntl
except ImportError:          # Windows: no locks, processes may compile twice
    fcntl = None

WAIT_SECONDS = 900.0
POLL_SECONDS = 0.05

_held: dict[str, int] = {}   # lock file -> descriptor, the locks this process holds


def acquire(path: str) -> bool:
    """Lock `path`, waiting while another process holds it. True if this call took the
    lock (the caller then looks in the cache again, compiles on a miss and calls
    `release`); False if it was already held here or cannot be taken."""
    if fcntl is None or path in _held:
        return False
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError:
        return False
    deadline = time.monotonic() + WAIT_SECONDS
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            break
        except BlockingIOError:
            if time.monotonic() > deadline:
                os.close(fd)
                return False
            time.sleep(POLL_SECONDS)
        except OSError:
            os.close(fd)
            return False
    _held[path] = fd
    return True


def release(path: str) -> None:
    """Let go of `path` if this process holds it."""
    fd = _held.pop(path, None)
    if fd is not None:
        try:
            fcntl.flock(fd, fcntl.LOCK_UN)
        finally:
            os.close(fd)


def held() -> list[str]:
    """The lock files this process holds (for tests)."""
    return list(_held)
