"""The compiled kernels an extension zip ships, so that its first render compiles nothing.

`python -m drt_addon package` builds them for the zip of the platform it runs on (Numba's
machine code is specific to an OS and an architecture): for each CPU tier (default
`x86-64-v3`, which CPUs since 2013-2015 run, and `generic` x86-64, which every x86-64 runs)
it runs `python -m drt_addon compile` in a subprocess that compiles for that tier
(`engine.kernels.cache_files.tier_environment`) into one cache folder. The folder goes into
the zip as `engine/kernels/prebuilt/`; the installed engine loads from it the best tier
the user's CPU runs when its own cache has nothing for the kernel
(`engine/kernels/kernel_cache.py`, `cache_files.py`), whatever the extension's repository is called.

Nothing here imports bpy; the tracer is imported for its tier names only.
"""
from __future__ import annotations

import importlib
import os
import platform
import subprocess
import sys
import time

from . import precompile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDER = os.path.join("engine", "kernels", "prebuilt")   # inside the zip


def _cache_files():
    """engine.kernels.cache_files (the tiers, and the settings that compile for one)."""
    from .engine_link import engine
    return importlib.import_module(engine.__name__ + ".kernels.cache_files")


def host_platform() -> str | None:
    """This machine's extension platform name when its kernels can be prebuilt here (x86-64
    Linux or Windows), else None."""
    machine = platform.machine().lower()
    if machine not in ("x86_64", "amd64"):
        return None
    return {"linux": "linux-x64", "win32": "windows-x64"}.get(sys.platform)


def build(folder: str, tiers=None, scenes=None, python: str = sys.executable,
          log=None) -> dict:
    """Compile the kernels that rendering `scenes` (sample scene names) reaches, once per
    tier (default: the shipped tiers; scenes default: `compile`'s), into `folder` (it then
    holds the engine's cache layout: `engine_kernels/...`).
    Returns {tier: seconds}. Raises RuntimeError with the compile's own message on
    failure."""
    cache_files = _cache_files()
    tiers = tiers or cache_files.SHIPPED_TIERS
    os.makedirs(folder, exist_ok=True)
    blends = [os.path.join(ROOT, "sample_blends", f"{name}.blend")
              for name in scenes or precompile.SCENES]
    seconds = {}
    for tier in tiers:
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("NUMBA_", "DRT_"))}
        env.update(cache_files.tier_environment(tier))
        # jit.py caches under NUMBA_CACHE_DIR/drt
        env["NUMBA_CACHE_DIR"] = os.path.join(folder, ".numba")
        t0 = time.perf_counter()
        proc = subprocess.run([python, "-m", "drt_addon", "compile", "--no-progress", *blends],
                              cwd=ROOT, env=env, capture_output=True, text=True)
        seconds[tier] = time.perf_counter() - t0
        if proc.returncode != 0:
            tail = (proc.stderr.strip() or proc.stdout.strip()).splitlines()[-1:] or ["?"]
            raise RuntimeError(f"compiling the {tier} kernels failed: {tail[0]}")
        if log:
            log(f"compiled the {tier} kernels in {seconds[tier]:.0f} s")
    cache = os.path.join(folder, ".numba", "drt")
    for name in os.listdir(cache):
        os.replace(os.path.join(cache, name), os.path.join(folder, name))
    for dirpath, _dirs, files in os.walk(os.path.join(folder, ".numba"), topdown=False):
        for f in files:
            os.remove(os.path.join(dirpath, f))
        os.rmdir(dirpath)
    return seconds
