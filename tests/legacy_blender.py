"""Debian's `blender` binary (Blender 3.4, system Python 3.11) with DRT as a legacy add-on:
shared by tests/test_debian_blender.py (command-line renders) and
tests/test_viewport_window.py (the Rendered viewport in a window, under Xvfb).

The add-on is this checkout, linked as <BLENDER_USER_SCRIPTS>/addons/drt; the packages the
tracer needs besides NumPy (embreex, numba, llvmlite: the extension's bundled wheels) are
this test environment's own, linked into one folder on PYTHONPATH, and NumPy is Debian's
python3-numpy, exactly as docs/batch.md tells a render-farm worker to set it up."""
from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import subprocess
import tempfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE_SCRIPT = os.path.join(ROOT, "tests", "legacy_blender_scene.py")
# what the extension zip bundles besides numpy: the tracer's packages, and the denoiser's
BUNDLED = ("embreex", "numba", "llvmlite", "pyoidn", "cffi", "pycparser")
TOP_LEVEL = ("_cffi_backend",)                 # cffi's compiled module, beside its package


def _package_dirs(name: str) -> list[str]:
    """The installed folder of package `name` and its auditwheel `NAME.libs` sibling."""
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        pytest.skip(f"{name} is not installed here: the Debian Blender test did not run")
    folder = list(spec.submodule_search_locations)[0]
    libs = folder + ".libs"
    return [folder] + ([libs] if os.path.isdir(libs) else [])


def _link(target: str, link: str) -> None:
    """`link` -> `target`, made or corrected (another checkout may have used the path)."""
    if os.path.islink(link) and os.readlink(link) == target:
        return
    os.makedirs(os.path.dirname(link), exist_ok=True)
    tmp = f"{link}.{os.getpid()}"
    os.symlink(target, tmp)
    os.replace(tmp, link)


class LegacyBlender:
    """The blender binary with DRT as a legacy add-on: throwaway preferences and packages
    folder per test module; the add-on's link kept per checkout."""

    def __init__(self, blender: str, home):
        self.blender, self.home = blender, home
        self.xvfb_run = shutil.which("xvfb-run")
        stable = os.path.join(tempfile.gettempdir(), "drt-legacy-blender-"
                              + hashlib.sha1(ROOT.encode()).hexdigest()[:12])
        scripts = os.path.join(stable, "scripts")
        _link(ROOT, os.path.join(scripts, "addons", "drt"))
        site = home / "site"
        site.mkdir()
        for name in BUNDLED:
            for folder in _package_dirs(name):
                os.symlink(folder, site / os.path.basename(folder))
        for name in TOP_LEVEL:
            spec = importlib.util.find_spec(name)
            if spec is not None and spec.origin:
                os.symlink(spec.origin, site / os.path.basename(spec.origin))
        self.env = {**os.environ, "BLENDER_USER_SCRIPTS": scripts,
                    "BLENDER_USER_CONFIG": str(home / "config"), "PYTHONPATH": str(site)}
        self.env.pop("NUMBA_CACHE_DIR", None)       # the checkout's own cache
        self.blend = str(home / "scene.blend")

    def run(self, *args, window: bool = False, timeout: float = 600
            ) -> subprocess.CompletedProcess:
        """Blender with `args`: in the background, or with `window` in a window on a
        virtual screen (xvfb-run, Mesa's software OpenGL)."""
        command = ([self.xvfb_run, "-a", "-s", "-screen 0 800x600x24", self.blender]
                   if window else [self.blender, "-b"])
        proc = subprocess.run([*command, *args], env=self.env, cwd=str(self.home),
                              capture_output=True, text=True, timeout=timeout)
        proc.log = proc.stdout + proc.stderr
        return proc
