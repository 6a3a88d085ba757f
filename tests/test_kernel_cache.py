"""The compiled-kernel cache (engine/kernels/kernel_cache.py): a change to any engine source a
kernel can see recompiles every kernel that could have inlined it (Numba alone would keep
a caller's stale machine code when only a callee in another module changed), a change no
kernel can see recompiles nothing, a user-chosen cache folder is honoured, and with no
writable cache the kernels compile in memory.

Each case runs in a fresh process on a private copy of the engine package, so this
process's own kernels and cache are never touched."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

PROBE = ("import numpy as np; from engine.sampling import make_sampler; "
         "s = make_sampler('jittered', 3, 16); "
         "print(repr(float(s.get_1d(5, np.arange(8), np.arange(8)).sum())))")


def _copy_engine(tmp_path):
    dst = tmp_path / "src"
    shutil.copytree(os.path.join(ROOT, "engine"), dst / "engine",
                    ignore=shutil.ignore_patterns("__pycache__"))
    return dst


def _run(src, **env):
    e = dict(os.environ, PYTHONPATH=str(src))
    e.pop("NUMBA_CACHE_DIR", None)
    e.update(env)
    proc = subprocess.run([sys.executable, "-c", PROBE], cwd=src, env=e, capture_output=True,
                          text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return float(proc.stdout.strip())


def _cached_files(folder):
    return [f for _, _, files in os.walk(folder) for f in files if f.endswith((".nbi", ".nbc"))]


def test_a_change_in_a_callee_module_recompiles_its_callers(tmp_path):
    src = _copy_engine(tmp_path)
    first = _run(src)
    cache = src / "engine" / "kernels" / "__pycache__" / "numba"
    assert _cached_files(cache), "the first run wrote no cached kernels"
    assert _run(src) == first                       # the cache gives the same values
    # The hash chain's constant lives in hashing.py; the cached entry point
    # (dispatch.batch_1d) lives in another module and inlines it.
    hashing = src / "engine" / "sampling" / "hashing.py"
    text = hashing.read_text()
    assert "GOLDEN = np.uint64(0x9E3779B97F4A7C15)" in text
    hashing.write_text(text.replace("GOLDEN = np.uint64(0x9E3779B97F4A7C15)",
                                    "GOLDEN = np.uint64(0x9E3779B97F4A7C17)"))
    changed = _run(src)
    assert changed != first, "a stale cached kernel ignored the changed callee"


def _stamps(folder):
    return {os.path.join(d, f): os.stat(os.path.join(d, f)).st_mtime_ns
            for d, _, files in os.walk(folder) for f in files if f.endswith((".nbi", ".nbc"))}


def test_a_change_no_kernel_can_see_recompiles_nothing(tmp_path):
    """The fingerprint covers the modules that define kernels and what they import
    (kernel_cache.kernel_sources): a change to the denoiser, which no kernel imports, keeps every
    cached kernel (no cache file is rewritten); the callee case above shows the reverse."""
    src = _copy_engine(tmp_path)
    first = _run(src)
    cache = src / "engine" / "kernels" / "__pycache__" / "numba"
    before = _stamps(cache)
    assert before
    denoiser = src / "engine" / "denoiser.py"
    denoiser.write_text(denoiser.read_text() + "\n# changed\n")
    assert _run(src) == first
    assert _stamps(cache) == before


def test_kernel_sources_follow_the_kernels_imports():
    from engine.kernels import kernel_cache
    names = {os.path.relpath(p, kernel_cache.ENGINE_DIR).replace(os.sep, "/")
             for p in kernel_cache.kernel_sources()}
    # kernels, their callees' modules, and plain modules they read constants from
    assert {"kernels/jit.py", "kernels/kernel_cache.py", "kernels/path_vertex.py",
            "sampling/hashing.py",
            "sampling/dispatch.py", "visibility.py", "kernels/lights/light_set.py",
            "embree/rays.py", "embree/library.py"} <= names
    # Python-side modules no kernel imports
    assert not names & {"denoiser.py", "render.py", "aov.py", "integrators/compiled_path.py"}


def test_user_cache_folder_is_used(tmp_path):
    src = _copy_engine(tmp_path)
    folder = tmp_path / "user-cache"
    _run(src, NUMBA_CACHE_DIR=str(folder))
    assert _cached_files(folder / "drt")
    assert not _cached_files(src / "engine")


def test_no_writable_cache_compiles_in_memory(tmp_path):
    src = _copy_engine(tmp_path)
    reference = _run(src)
    src2 = _copy_engine(tmp_path / "second")
    assert _run(src2, DRT_NUMBA_CACHE="0") == reference
    assert not _cached_files(src2 / "engine")


LOAD_PROBE = """
import sys
import numpy as np
from engine.sampling import make_sampler
s = make_sampler('jittered', 3, 16)
v = float(s.get_1d(5, np.arange(8), np.arange(8)).sum())
from numba.core.registry import cpu_target
from engine.sampling.dispatch import batch_1d
hits = sum(batch_1d.stats.cache_hits.values())
loaded = 'numba.np.arraymath' in sys.modules
# a function compiled afterwards in the same process: Numba's pipeline loads what it needs
from numba import njit
@njit
def spread(a):
    return np.linalg.norm(a) + np.median(a)
# the engine's kernels, and those whose Numba dispatcher exists (made on first use)
import engine.integrators.compiled_path
from engine.kernels.jit import Kernel
kernels = {id(k): k for name, m in list(sys.modules.items()) if name.startswith('engine')
           for k in vars(m).values() if isinstance(k, Kernel)}
made = sum(k.realized for k in kernels.values())
print(repr(v), hits, loaded, repr(float(spread(np.arange(5.0)))), len(kernels), made)
"""


def test_cached_kernels_load_without_numbas_compiler_registries(tmp_path):
    """A second process loads its kernels from the cache without importing Numba's
    typing and lowering registries (engine.kernels.kernel_cache.EngineFunctionCache: 0.2 s of a
    render process), and a function compiled after them still compiles and runs."""
    src = _copy_engine(tmp_path)
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def run():
        proc = subprocess.run([sys.executable, "-c", LOAD_PROBE], cwd=src, env=env,
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        v, hits, loaded, spread, kernels, made = proc.stdout.split()
        return float(v), int(hits), loaded == "True", float(spread), int(kernels), int(made)

    first = run()                      # compiles, and so loads the registries
    second = run()                     # loads from the cache
    assert first[1] == 0 and first[2]
    assert second[1] == 1 and not second[2]
    assert second[0] == first[0]
    assert first[3] == second[3] == float(np.linalg.norm(np.arange(5.0)) + 2.0)
    # Dispatchers are made on first use: compiling batch_1d made its callees' too (to
    # type them); loading it from the cache made batch_1d's alone, of the engine's
    # hundreds of kernels (the path tracer's included, imported above)
    kernels, made_compiling, made_loading = second[4], first[5], second[5]
    assert kernels > 300
    assert made_loading == 1 < made_compiling


def test_a_cache_built_elsewhere_loads_where_the_engine_is_installed(tmp_path):
    """The cache's folders are named after the engine's own subfolders, not Numba's hash
    of their absolute path (engine.kernels.kernel_cache.EngineCacheLocator): kernels cached by a
    copy of the engine in one place load in a copy installed in another, as the extension
    package's caches must."""
    cache = tmp_path / "cache"
    first = _copy_engine(tmp_path / "built-here")
    second = _copy_engine(tmp_path / "installed-there")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))

    def run(src):
        proc = subprocess.run([sys.executable, "-c", LOAD_PROBE], cwd=src,
                              env=dict(env, PYTHONPATH=str(src)), capture_output=True,
                              text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        return proc.stdout.split()

    built, installed = run(first), run(second)
    assert int(built[1]) == 0 and int(installed[1]) == 1       # compiled, then loaded
    assert float(built[0]) == float(installed[0])


PURE_PYTHON = """
import sys, numpy as np
sys.path.insert(0, {tests!r})
from engine import render, RenderSettings
from engine_scenes import cornell_box
film, stats = render(cornell_box(4, 4), RenderSettings(samples=2, threads=1, seed=5))
np.save({out!r}, film.mean())
"""


def test_every_kernel_runs_as_plain_python(tmp_path):
    """NUMBA_DISABLE_JIT=1 runs every kernel as the Python it is written in (Embree's
    calls through ctypes), for a student to step through: a small render gives the
    compiled tracer's image (the same paths; float64 arithmetic in the same order, but
    Python's math functions are not LLVM's)."""
    from engine import RenderSettings, render
    from engine_scenes import cornell_box
    out = tmp_path / "python.npy"
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=ROOT)
    code = PURE_PYTHON.format(tests=os.path.join(ROOT, "tests"), out=str(out))
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    python = np.load(out)
    film, _ = render(cornell_box(4, 4), RenderSettings(samples=2, threads=1, seed=5))
    compiled = film.mean()
    assert compiled.max() > 0.05                       # lit: the comparison shows something
    np.testing.assert_allclose(python, compiled, rtol=1e-9, atol=1e-12)


TOGETHER_PROBE = """
import os, sys, time
import numpy as np
if sys.argv[1] == "unlocked":
    import engine.kernels.compile_lock as compile_lock
    compile_lock.fcntl = None                   # as where no lock can be taken
from engine.sampling import make_sampler
from engine.sampling.dispatch import batch_1d
from engine.kernels import compile_lock
open(sys.argv[2], "w").close()                  # ready; both start compiling together
while not all(os.path.exists(p) for p in sys.argv[3:]):
    time.sleep(0.01)
s = make_sampler('jittered', 3, 16)
v = float(s.get_1d(5, np.arange(8), np.arange(8)).sum())
print(repr(v), sum(batch_1d.stats.cache_hits.values()), len(compile_lock.held()))
"""


def _two_at_once(tmp_path, mode):
    src = _copy_engine(tmp_path / mode)
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_CACHE_DIR=str(tmp_path / mode / "c"))
    ready = [str(tmp_path / mode / f"ready{k}") for k in range(2)]
    procs = [subprocess.Popen([sys.executable, "-c", TOGETHER_PROBE, mode, ready[k], *ready],
                              cwd=src, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
             for k in range(2)]
    out = []
    for p in procs:
        stdout, stderr = p.communicate(timeout=600)
        assert p.returncode == 0, stderr
        value, hits, held = stdout.split()
        out.append((float(value), int(hits), int(held)))
    return out


def test_processes_sharing_the_cache_compile_a_kernel_once(tmp_path):
    """Two processes calling a kernel together on an empty cache: one compiles the kernel (and
    its callees), the other waits on the compile lock and loads what it saved
    (engine/kernels/compile_lock.py); neither holds a lock at the end. Without locks
    (the control) both compile."""
    locked = _two_at_once(tmp_path, "locked")
    assert locked[0][0] == locked[1][0]
    assert sorted(hits for _, hits, _ in locked) == [0, 1]
    assert all(held == 0 for _, _, held in locked)
    unlocked = _two_at_once(tmp_path, "unlocked")
    assert [hits for _, hits, _ in unlocked] == [0, 0]
