"""The extension zip, end to end, along the path a Blender 4.2+ user takes:

`python -m drt_addon package --platform linux-x64` builds and validates this machine's zip
(one zip per platform; only this one is built, so a run downloads only its wheels); the zip
holds the add-on, the tracer, its kernels compiled for CPU tiers (engine/kernels/prebuilt)
and the embreex, numba, llvmlite, pyoidn, cffi and pycparser wheels for linux-x64, and nothing of the development
tree; installed with Blender's own operator into a throwaway user extension repository it
is enabled as `bl_ext.user_default.drt` and renders the Cornell box with the DRT engine
without compiling: the kernels built under the module name `engine` load in the installed
`bl_ext.user_default.drt.engine`, on this CPU, from the generic tier. The extension's
user folder (<user>/extensions/.user/user_default/drt/numba_cache) is Numba's cache for
what the zip does not hold. A truly read-only user folder (a read-only bind mount where
user namespaces allow one) still renders from the shipped kernels; with DRT_NUMBA_CACHE=0
it compiles in memory.

Blender runs in subprocesses (`python -I -c ...`, cwd outside the repository): this pytest
process may hold the source-checkout add-on, and Blender cannot register a second engine
called DRT. The subprocess never sees the source tree, so everything it renders comes from
the installed zip.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import time
import tomllib
import zipfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORNELL = os.path.join(ROOT, "sample_blends", "cornell_box.blend")
PKG = "bl_ext.user_default.drt"

if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
from drt_addon import packaging  # noqa: E402  (pure Python, imports no bpy)


def _manifest() -> dict:
    with open(os.path.join(ROOT, "blender_manifest.toml"), "rb") as f:
        return tomllib.load(f)


def _blender_ext_module():
    spec = importlib.util.spec_from_file_location("_drt_blender_ext", packaging.find_blender_ext())
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _validate(path: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, packaging.find_blender_ext(), "validate", path],
                          capture_output=True, text=True, timeout=120)


PLATFORM = "linux-x64"  # this machine's; the only zip the tests build
# The zip ships the kernels the Cornell box's render reaches, compiled for the generic
# x86-64 tier alone: the most portable tier, and what a CPU without the x86-64-v3
# instructions loads (the default build adds x86-64-v3 and more scenes).
KERNEL_OPTIONS = ("--kernel-tier", "generic", "--kernel-scene", "cornell_box")
PREBUILT = "engine/kernels/prebuilt/"
BUNDLED = {"embreex", "numba", "llvmlite", "pyoidn", "cffi", "pycparser"}
# a wheel is for CPython 3.11 alone, or for any Python 3 without compiled extensions
# (pyoidn loads its library with cffi; pycparser is pure Python)
TAGS = {("cp311", "cp311"), ("py3", "none")}


def _platform_wheels(platform: str = PLATFORM) -> list[str]:
    return packaging.wheels_by_platform(ROOT)[platform]


# ----------------------------------------------------------------------------- building

@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Run the documented command for this platform; return (zip path, the finished
    process)."""
    out_dir = tmp_path_factory.mktemp("dist")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "drt_addon", "package", "-o", str(out_dir),
                           "--platform", PLATFORM, *KERNEL_OPTIONS],
                          cwd=ROOT, capture_output=True, text=True, timeout=900)
    seconds = time.perf_counter() - t0
    assert proc.returncode == 0, f"package failed ({proc.returncode}):\n{proc.stderr}"
    lines = proc.stdout.strip().splitlines()
    assert lines, f"package printed no zip path; stderr:\n{proc.stderr}"
    print(f"package --platform {PLATFORM}: {seconds:.1f} s, "
          f"{os.path.getsize(lines[-1]) / 1e6:.1f} MB")
    return lines[-1], proc


def test_package_command_prints_the_zip_it_built(built):
    zip_path, proc = built
    m = _manifest()
    assert proc.stdout.strip().splitlines() == [zip_path]  # one platform, one line
    assert os.path.basename(zip_path) == f"{m['id']}-{m['version']}-linux_x64.zip"
    assert os.path.isfile(zip_path) and zipfile.is_zipfile(zip_path)
    assert "validated" in proc.stderr
    # Only that zip: no other platform's, and no staging folder left behind.
    assert os.listdir(os.path.dirname(zip_path)) == [os.path.basename(zip_path)]


def test_package_rejects_a_platform_the_manifest_does_not_list(tmp_path):
    # macos-x64 is not listed: numba 0.68.1 and llvmlite 0.50.0 have no Intel-macOS wheels.
    proc = subprocess.run([sys.executable, "-m", "drt_addon", "package", "-o", str(tmp_path),
                           "--platform", "macos-x64"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("drt: error:") and "Traceback" not in proc.stderr
    assert "macos-x64" in proc.stderr and os.listdir(tmp_path) == []


def test_package_rejects_a_file_as_output_dir(tmp_path):
    not_a_dir = tmp_path / "file.txt"
    not_a_dir.write_text("x")
    proc = subprocess.run([sys.executable, "-m", "drt_addon", "package", "-o", str(not_a_dir)],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("drt: error:") and "Traceback" not in proc.stderr


def test_validate_accepts_the_zip_and_rejects_a_broken_one(built, tmp_path):
    zip_path, _ = built
    ok = _validate(zip_path)
    assert ok.returncode == 0, ok.stdout + ok.stderr
    # The same zip with the manifest's `id` removed must fail: the check can fail.
    broken = str(tmp_path / "broken.zip")
    with zipfile.ZipFile(zip_path) as src, zipfile.ZipFile(broken, "w") as dst:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "blender_manifest.toml":
                data = b"\n".join(line for line in data.split(b"\n")
                                  if not line.startswith(b"id ="))
            dst.writestr(info, data)
    bad = _validate(broken)
    assert bad.returncode != 0, bad.stdout + bad.stderr


def test_zip_holds_the_addon_tracer_and_wheels_only(built):
    zip_path, _ = built
    with zipfile.ZipFile(zip_path) as z:
        names = z.namelist()
        zipped_manifest = tomllib.loads(z.read("blender_manifest.toml").decode())
    # The repository's manifest with platforms and wheels narrowed to this platform (which
    # the tool also records under [build.generated], the table Blender installs from).
    wheels = _platform_wheels()
    generated = zipped_manifest["build"].pop("generated")
    assert generated == {"platforms": [PLATFORM], "wheels": wheels}
    assert zipped_manifest == {**_manifest(), "platforms": [PLATFORM], "wheels": wheels}
    for required in ("blender_manifest.toml", "__init__.py", "drt_addon/__init__.py",
                     "drt_addon/render_engine.py", "drt_addon/engine_link.py",
                     "engine/__init__.py", "engine/accel.py", "engine/render.py",
                     "engine/bsdf/data/ggx_energy.npz",    # the multiscatter tables
                     "engine/bsdf/data/specular_albedo.npz"):   # the layering tables
        assert required in names, required
    zipped_wheels = sorted(n for n in names if n.endswith(".whl"))
    assert zipped_wheels == sorted(os.path.normpath(w).replace(os.sep, "/") for w in wheels)
    assert all(("manylinux" in w and w.endswith("x86_64.whl")) or w.endswith("-none-any.whl")
               for w in wheels)
    forbidden_tops = {"tests", "docs", "sample_blends", ".venv", ".git", ".ci", "build",
                      "renders", "requirements.txt", "pytest.ini", ".gitignore",
                      ".pytest_cache"}
    # The compiled kernels: Numba's index and code files, in the engine's cache layout.
    prebuilt = [n for n in names if n.startswith(PREBUILT) and not n.endswith("/")]
    assert any(n.endswith(".nbi") for n in prebuilt) and any(n.endswith(".nbc")
                                                             for n in prebuilt)
    assert all(n.endswith((".nbi", ".nbc")) for n in prebuilt), prebuilt
    assert any(n.startswith(PREBUILT + "engine_kernels/") for n in prebuilt)
    for name in names:
        assert name.split("/")[0] not in forbidden_tops, name
        assert "__pycache__" not in name and not name.endswith((".pyc", ".blend", ".zip")), name
        assert "numpy" not in name.lower(), f"numpy comes with Blender, not the zip: {name}"
    # Top level: the package, plus at most a README or licence text.
    extras = {n.split("/")[0] for n in names} - {"blender_manifest.toml", "__init__.py",
                                                 "drt_addon", "engine", "wheels"}
    assert all(x in names and x.upper().startswith(("README", "LICENSE", "COPYING"))
               for x in extras), sorted(extras)


def test_zip_bundles_the_pinned_wheels_for_linux(built):
    zip_path, _ = built
    pins = packaging.read_pins(ROOT)
    blender_ext = _blender_ext_module()
    found = set()
    with zipfile.ZipFile(zip_path) as z:
        members = {n for n in z.namelist() if n.endswith(".whl")}
        for member in sorted(members):
            dist, version, py_tag, abi_tag, plat = packaging.parse_wheel_filename(member)
            found.add(dist)
            assert version == pins[dist] and (py_tag, abi_tag) in TAGS, member
            assert plat == "any" or \
                blender_ext.blender_platforms_from_wheel_platform(plat) == [PLATFORM]
            # Byte for byte the wheel that was downloaded (and checked intact) in wheels/.
            with open(os.path.join(ROOT, member), "rb") as f:
                on_disk = hashlib.sha256(f.read()).hexdigest()
            assert hashlib.sha256(z.read(member)).hexdigest() == on_disk, member
            with zipfile.ZipFile(z.open(member)) as wheel:
                assert wheel.testzip() is None, member
    assert found == BUNDLED and len(members) == len(BUNDLED)


def test_manifest_has_one_pinned_wheel_of_each_package_for_every_platform():
    """The check `package` runs for all platforms, here without downloading anything:
    no listed platform lacks a wheel (macos-x64 was dropped for that reason)."""
    pins = packaging.read_pins(ROOT)
    per_platform = packaging.wheels_by_platform(ROOT)
    assert list(per_platform) == _manifest()["platforms"]
    assert "macos-x64" not in per_platform
    blender_ext = _blender_ext_module()
    for platform, wheels in per_platform.items():
        parsed = [packaging.parse_wheel_filename(w) for w in wheels]
        assert sorted(p[0] for p in parsed) == sorted(BUNDLED), platform
        for dist, version, py_tag, abi_tag, plat in parsed:
            assert version == pins[dist] and (py_tag, abi_tag) in TAGS
            assert plat == "any" or \
                platform in blender_ext.blender_platforms_from_wheel_platform(plat)
    # every wheel serves some platform (a pure-Python one, tagged "any", serves them all)
    assert sorted({w for ws in per_platform.values() for w in ws}) == \
        sorted(_manifest()["wheels"])


def test_packaging_refuses_a_platform_without_all_its_wheels(tmp_path):
    (tmp_path / "blender_manifest.toml").write_text(
        'id = "drt"\nplatforms = ["linux-x64", "windows-x64"]\nwheels = [\n'
        '  "./wheels/numba-0.68.1-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl",\n'
        '  "./wheels/numba-0.68.1-cp311-cp311-win_amd64.whl",\n'
        '  "./wheels/llvmlite-0.50.0-cp311-cp311-win_amd64.whl",\n]\n')
    (tmp_path / "requirements.txt").write_text("numba==0.68.1\nllvmlite==0.50.0\n")
    with pytest.raises(packaging.PackagingError, match="linux-x64 but has 0 llvmlite"):
        packaging.fetch_wheels(str(tmp_path), platforms=["linux-x64"])
    assert not (tmp_path / "wheels").exists()


def test_filtered_manifest_changes_only_platforms_and_wheels():
    with open(os.path.join(ROOT, "blender_manifest.toml"), encoding="utf-8") as f:
        text = f.read()
    wheels = _platform_wheels()
    filtered = packaging.manifest_text_for(text, [PLATFORM], wheels)
    assert tomllib.loads(filtered) == {**_manifest(), "platforms": [PLATFORM], "wheels": wheels}


@pytest.mark.parametrize("wheel, requirements, message", [
    ("embreex-4.3.0-cp311-cp311-win_amd64.whl", "embreex==4.4.0.post1\n", "pins"),
    ("numpy-1.26.4-cp311-cp311-win_amd64.whl", "numpy==1.26.4\n", "comes with Blender"),
    ("scipy-1.15.3-cp311-cp311-win_amd64.whl", "embreex==4.4.0.post1\n", "does not pin"),
])
def test_packaging_refuses_wheels_that_do_not_match_the_pins(tmp_path, wheel, requirements,
                                                            message):
    (tmp_path / "blender_manifest.toml").write_text(f'id = "drt"\nwheels = ["./wheels/{wheel}"]\n')
    (tmp_path / "requirements.txt").write_text(requirements)
    with pytest.raises(packaging.PackagingError, match=message):
        packaging.fetch_wheels(str(tmp_path))
    assert not (tmp_path / "wheels").exists()  # refused before any download


# ----------------------------------------------------------------------------- installing

# Runs in a fresh interpreter, as Blender would: install (or restart), enable, render.
SESSION = r"""
import json, os, site, sys, time
args = json.loads(sys.argv[1])
facts = {}

if args["hide_env"]:
    # A Blender's own Python has none of the bundled packages: hide this environment's
    # so that only the extension's wheels can provide them.
    import importlib.abc, importlib.machinery
    env_sites = {os.path.realpath(p) for p in site.getsitepackages()}
    class HideEnvPackages(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name not in args["hide_env"]:
                return None
            dirs = [p for p in sys.path if os.path.realpath(p) not in env_sites]
            spec = importlib.machinery.PathFinder.find_spec(name, dirs)
            if spec is None:
                raise ModuleNotFoundError(f"No module named {name!r} (environment's hidden)",
                                          name=name)
            return spec
    sys.meta_path.insert(0, HideEnvPackages())
    facts["env_before"] = {}
    for name in args["hide_env"]:
        try:
            facts["env_before"][name] = __import__(name).__file__
            del sys.modules[name]
        except ModuleNotFoundError:
            facts["env_before"][name] = None

if args["preimport_numba_from"]:
    # Something (another add-on, a startup script) imported numba before DRT registers:
    # numba.core.config has already read the environment, without NUMBA_CACHE_DIR.
    sys.path.insert(0, args["preimport_numba_from"])
    import numba
    facts["preimported_numba"] = numba.__file__
    facts["preimported_cache_dir"] = numba.core.config.CACHE_DIR
    sys.path.remove(args["preimport_numba_from"])

import bpy
import numpy as np

def drt_engine():
    return next((c for c in bpy.types.RenderEngine.__subclasses__()
                 if getattr(c, "bl_idname", None) == "DRT"), None)

facts["user_extensions"] = bpy.utils.user_resource("EXTENSIONS")
facts["drt_before"] = drt_engine() is not None
t0 = time.perf_counter()
if args["install"]:
    result = bpy.ops.extensions.package_install_files(
        filepath=args["zip"], repo="user_default", enable_on_install=True)
    facts["op"] = sorted(result)
    bpy.ops.wm.save_userpref()
else:
    # What Blender does at start-up: read the preferences, enable the add-ons they list.
    facts["op"] = sorted(bpy.ops.wm.read_userpref())
facts["enable_seconds"] = time.perf_counter() - t0
facts["enabled"] = args["pkg"] in bpy.context.preferences.addons

cls = drt_engine()
mod = sys.modules.get(cls.__module__) if cls else None
facts["engine_module"] = cls.__module__ if cls else None
facts["engine_file"] = getattr(mod, "__file__", None)
# the tracer loads with the first DRT render (after it, below)
facts["tracer_before_render"] = args["pkg"] + ".engine" in sys.modules

bpy.ops.wm.open_mainfile(filepath=args["blend"], load_ui=False)
scene = bpy.context.scene
scene.render.engine = "DRT"
scene.render.resolution_percentage = 12
scene.drt.samples = 2
scene.cycles.use_denoising = True      # Render > Denoise, through the bundled pyoidn
facts["expected_size"] = [scene.render.resolution_x * 12 // 100,
                          scene.render.resolution_y * 12 // 100]
t0 = time.perf_counter()
bpy.ops.render.render(write_still=False)
facts["render_seconds"] = time.perf_counter() - t0
facts["last_render"] = {k: mod.last_render.get(k) for k in ("ok", "error")} if mod else None
facts["denoised"] = bool(mod and "Noisy Image" in mod.last_render.get("passes", {}))
facts["warnings"] = list(mod.last_render.get("warnings", [])) if mod else None
tracer = sys.modules.get(args["pkg"] + ".engine")
facts["tracer_file"] = getattr(tracer, "__file__", None)

exr = os.path.join(args["tmp"], "render.exr")
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
bpy.data.images["Render Result"].save_render(filepath=exr, scene=scene)
img = bpy.data.images.load(exr)
w, h = img.size
px = np.empty(w * h * 4, dtype=np.float32)
img.pixels.foreach_get(px)
rgb = px.reshape(h, w, 4)[..., :3]
facts["size"] = [w, h]
facts["finite"] = bool(np.isfinite(rgb).all())
facts["min"], facts["max"] = float(rgb.min()), float(rgb.max())
facts["std"] = float(rgb.std())
facts["distinct"] = int(np.unique(rgb).size)

facts["module_files"] = {name: getattr(sys.modules.get(name), "__file__", None)
                         for name in ("numba", "llvmlite", "pyoidn", "cffi", "pycparser")}
# Embree: the library DRT loaded (the embreex wheel's; its Python binding is not used)
embree = sys.modules.get(args["pkg"] + ".engine.embree.library")
facts["module_files"]["embreex"] = getattr(getattr(embree, "_LIB", None), "drt_path", None)
facts["embreex_binding_imported"] = "embreex" in sys.modules

# Numba's view: where the add-on pointed the cache, whether the tracer caches at all, and
# what each compiled kernel of the tracer did (cache hit: loaded from disk; miss: compiled).
facts["env_cache_dir"] = os.environ.get("NUMBA_CACHE_DIR")
config = sys.modules.get("numba.core.config")
facts["numba_cache_dir"] = getattr(config, "CACHE_DIR", None)
jit = sys.modules.get(args["pkg"] + ".engine.kernels.jit")
cache = sys.modules.get(args["pkg"] + ".engine.kernels.kernel_cache")
facts["jit_cache"] = getattr(cache, "CACHE", None)
facts["shipped_root"] = getattr(cache, "SHIPPED_ROOT", None)
kernels = {}
if jit is not None:
    # the engine's kernels (jit.Kernel); a kernel's Numba dispatchers exist once it was
    # used: the one for Python once called, the callee one once typed by a caller
    for name, m in list(sys.modules.items()):
        if name == args["pkg"] + ".engine" or name.startswith(args["pkg"] + ".engine."):
            for v in list(vars(m).values()):
                if isinstance(v, jit.Kernel):
                    kernels[id(v)] = v
used = [d for k in kernels.values() for d in (k._dispatcher, k._callee)
        if d is not None and d.signatures]
facts["kernels"], facts["kernels_used"] = len(kernels), len(used)
facts["cache_hits"] = sum(sum(k.stats.cache_hits.values()) for k in used)
facts["cache_misses"] = sum(sum(k.stats.cache_misses.values()) for k in used)
facts["cache_paths"] = sorted({k.stats.cache_path for k in used if k.stats.cache_path})
if facts["env_cache_dir"]:
    try:  # is the cache folder writable in this session?
        probe = os.path.join(facts["env_cache_dir"], ".probe")
        open(probe, "w").close()
        os.remove(probe)
        facts["cache_dir_writable"] = True
    except OSError:
        facts["cache_dir_writable"] = False

facts["source_modules"] = sorted(m for m in sys.modules
                                 if m.split(".")[0] in ("drt_addon", "engine"))
facts["repo_on_path"] = [p for p in sys.path if os.path.realpath(p or ".") ==
                         os.path.realpath(args["repo"])]
print("FACTS " + json.dumps(facts))
"""

# Runs the rest of the command line with the first argument mounted read-only, in a new user
# and mount namespace (`unshare -rm`): even root cannot write there, unlike after a chmod.
READ_ONLY = ('mount --bind "$1" "$1" && mount -o remount,bind,ro "$1" "$1" && shift '
             '&& exec "$@"')


def _read_only_mounts_work(tmp) -> bool:
    probe = os.path.join(tmp, "ro_probe")
    os.makedirs(probe, exist_ok=True)
    if shutil.which("unshare") is None:
        return False
    # Exit status 0 only when the mount worked and a write into it failed.
    proc = subprocess.run(["unshare", "-rm", "sh", "-c", READ_ONLY, "sh", probe,
                           "sh", "-c", 'touch "$0/x" 2>/dev/null && exit 3; exit 0', probe],
                          capture_output=True, text=True, timeout=60)
    return proc.returncode == 0 and not os.path.exists(os.path.join(probe, "x"))


def _session(tmp, user_dir, zip_path, *, install, hide_env=(), preimport_numba_from=None,
             env_extra=None, read_only=None) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("BLENDER_USER_", "PYTHON", "NUMBA_", "DRT_"))}
    env["BLENDER_USER_RESOURCES"] = user_dir  # never the real ~/.config/blender
    env.update(env_extra or {})
    args = {"zip": zip_path, "blend": CORNELL, "pkg": PKG, "repo": ROOT, "tmp": str(tmp),
            "install": install, "hide_env": list(hide_env),
            "preimport_numba_from": preimport_numba_from}
    cmd = [sys.executable, "-I", "-c", SESSION, json.dumps(args)]
    if read_only:
        cmd = ["unshare", "-rm", "sh", "-c", READ_ONLY, "sh", read_only, *cmd]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=str(tmp), env=env, capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, f"Blender session failed:\n{proc.stdout}\n{proc.stderr}"
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("FACTS ")]
    assert lines, f"no FACTS line:\n{proc.stdout}\n{proc.stderr}"
    facts = json.loads(lines[-1][len("FACTS "):])
    facts["process_seconds"] = time.perf_counter() - t0
    print(json.dumps(facts, indent=1))  # shown with -s / on failure
    return facts


def _ext_cache_dir(user_dir) -> str:
    """Where bpy.utils.extension_path_user puts the extension's "numba_cache" folder."""
    return os.path.join(user_dir, "extensions", ".user", "user_default", "drt", "numba_cache")


def _site_packages(user_dir) -> str:
    """Where Blender unpacks the extensions' wheels."""
    return os.path.join(user_dir, "extensions", ".local", "lib",
                        f"python{sys.version_info[0]}.{sys.version_info[1]}", "site-packages")


def _cache_files(user_dir) -> dict[str, int]:
    """{path relative to the cache folder: modification time in ns} of every file there."""
    root = _ext_cache_dir(user_dir)
    found = {}
    for dirpath, _dirs, files in os.walk(root):
        for f in files:
            path = os.path.join(dirpath, f)
            found[os.path.relpath(path, root)] = os.stat(path).st_mtime_ns
    return found


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory):
    return str(tmp_path_factory.mktemp("blender_user"))


@pytest.fixture(scope="module")
def first_session(built, user_dir, tmp_path_factory):
    """Install from Disk in a Blender whose Python has none of the bundled packages, with
    an empty kernel cache. Returns (facts, the cache files afterwards)."""
    assert _cache_files(user_dir) == {}
    facts = _session(tmp_path_factory.mktemp("session1"), user_dir, built[0],
                     install=True, hide_env=sorted(BUNDLED))
    return facts, _cache_files(user_dir)


@pytest.fixture(scope="module")
def restart_session(first_session, built, user_dir, tmp_path_factory):
    """A second Blender start with the same user folder, nothing hidden. Returns (facts,
    the cache files afterwards)."""
    facts = _session(tmp_path_factory.mktemp("session2"), user_dir, built[0], install=False)
    return facts, _cache_files(user_dir)


@pytest.fixture(scope="module")
def preimported_session(restart_session, built, user_dir, tmp_path_factory):
    """A third start in which numba was imported before Blender enabled DRT."""
    return _session(tmp_path_factory.mktemp("session3"), user_dir, built[0], install=False,
                    preimport_numba_from=_site_packages(user_dir))


@pytest.fixture(scope="module")
def read_only_session(preimported_session, built, user_dir, tmp_path_factory):
    """A start in which the whole Blender user folder (the installed extension, its wheels'
    site-packages and its cache folder) and the home folder are read-only mounts: no
    writable cache anywhere. Where read-only bind mounts are unavailable, a start with
    DRT_NUMBA_CACHE=0 (jit.py's switch, which forces the same in-memory path) instead.
    Returns (facts, whether the folder was mounted read-only, the cache files before and
    after)."""
    tmp = tmp_path_factory.mktemp("session4")
    before = _cache_files(user_dir)
    mounted = _read_only_mounts_work(str(tmp))
    if mounted:
        home = os.path.join(user_dir, "home")  # inside the read-only mount
        os.makedirs(home, exist_ok=True)
        facts = _session(tmp, user_dir, built[0], install=False, read_only=user_dir,
                         env_extra={"HOME": home,
                                    "XDG_CACHE_HOME": os.path.join(home, ".cache")})
    else:
        facts = _session(tmp, user_dir, built[0], install=False,
                         env_extra={"DRT_NUMBA_CACHE": "0"})
    return facts, mounted, before, _cache_files(user_dir)


def _check_session(facts, user_dir):
    ext_dir = os.path.realpath(os.path.join(user_dir, "extensions"))
    assert os.path.realpath(facts["user_extensions"]) == ext_dir
    assert facts["op"] == ["FINISHED"]
    assert facts["enabled"], f"{PKG} is not among the enabled add-ons"
    # The engine and the tracer are the installed copies, never the source checkout.
    assert facts["engine_module"] == PKG + ".drt_addon.render_engine"
    assert not facts["tracer_before_render"]          # enabling DRT loads no tracer
    for key in ("engine_file", "tracer_file"):
        assert os.path.realpath(facts[key]).startswith(
            os.path.join(ext_dir, "user_default", "drt") + os.sep), (key, facts[key])
    assert facts["source_modules"] == [] and facts["repo_on_path"] == []
    # The render.
    assert facts["last_render"] == {"ok": True, "error": None}
    assert facts["denoised"], facts["warnings"]     # OIDN from the bundled pyoidn
    assert facts["size"] == facts["expected_size"]
    assert min(facts["size"]) >= 8
    assert facts["finite"]
    assert facts["max"] > 0.01 and facts["std"] > 1e-3 and facts["distinct"] > 10
    # numba, llvmlite, the denoiser's pyoidn, cffi and pycparser, and the Embree library
    # of the embreex wheel from the bundled wheels,
    # which Blender unpacked into extensions/.local, never from the Python environment
    # running this test; embreex's own Python binding is never imported.
    site_packages = os.path.realpath(_site_packages(user_dir)) + os.sep
    for name, path in facts["module_files"].items():
        assert path and os.path.realpath(path).startswith(site_packages), (name, path)
    assert not facts["embreex_binding_imported"]
    # The tracer's kernels were compiled by that numba (a render that used none would
    # not test it).
    assert facts["kernels_used"] > 0


def _check_cached_in_extension_folder(facts, user_dir):
    cache_dir = os.path.realpath(_ext_cache_dir(user_dir))
    assert os.path.realpath(facts["env_cache_dir"]) == cache_dir
    assert os.path.realpath(facts["numba_cache_dir"]) == cache_dir
    assert facts["jit_cache"] is True
    assert facts["cache_paths"] and all(
        os.path.realpath(p).startswith(cache_dir + os.sep) for p in facts["cache_paths"])


def _check_loaded_the_shipped_kernels(facts, user_dir):
    """Every kernel the render used came from the zip's prebuilt folder: nothing compiled."""
    shipped = os.path.join(user_dir, "extensions", "user_default", "drt", "engine", "kernels",
                           "prebuilt")
    assert os.path.realpath(facts["shipped_root"]) == os.path.realpath(shipped)
    assert facts["cache_hits"] > 0 and facts["cache_misses"] == 0, (
        facts["cache_hits"], facts["cache_misses"])


def test_install_from_disk_enables_and_renders(first_session, user_dir):
    """Install from Disk in a Blender whose Python has none of the bundled packages: the
    wheels alone work, and the first render compiles nothing: the kernels the zip ships
    load, though they were built under another package name."""
    facts, cache_after = first_session
    assert facts["env_before"] == {n: None for n in sorted(BUNDLED)}  # the hiding works
    assert not facts["drt_before"]                                      # DRT only once installed
    _check_session(facts, user_dir)
    _check_cached_in_extension_folder(facts, user_dir)
    _check_loaded_the_shipped_kernels(facts, user_dir)
    # nothing was compiled, so nothing was written to the user cache
    assert cache_after == {}, sorted(cache_after)
    # Numba's files in the installed extension are the shipped ones only.
    installed = os.path.join(user_dir, "extensions", "user_default", "drt")
    found = [os.path.relpath(os.path.join(d, f), installed) for d, _, fs in os.walk(installed)
             for f in fs if f.endswith((".nbi", ".nbc"))]
    assert found and all(p.startswith(os.path.join("engine", "kernels", "prebuilt") + os.sep)
                         for p in found), found


def test_after_restart_the_extension_is_enabled_and_prefers_its_wheel(restart_session,
                                                                      user_dir):
    """A second Blender start with the same user folder, nothing hidden: the extension is
    enabled from the saved preferences, Blender's site-packages order picks the bundled
    embreex and numba over the Python environment's, and the kernels load again."""
    facts, _ = restart_session
    assert not facts["drt_before"]
    _check_session(facts, user_dir)
    _check_cached_in_extension_folder(facts, user_dir)
    _check_loaded_the_shipped_kernels(facts, user_dir)


def test_renders_compile_and_write_nothing(first_session, restart_session):
    first, cache_first = first_session
    second, cache_second = restart_session
    assert cache_first == cache_second == {}
    assert first["cache_misses"] == second["cache_misses"] == 0
    print(f"first render {first['render_seconds']:.1f} s, "
          f"second render {second['render_seconds']:.1f} s")


def test_numba_imported_before_the_addon_still_uses_the_extension_cache(preimported_session,
                                                                        user_dir):
    """numba.core.config reads NUMBA_CACHE_DIR at import; the add-on reloads it when numba
    was imported first, so the cache folder is still the extension's."""
    facts = preimported_session
    assert os.path.realpath(facts["preimported_numba"]).startswith(
        os.path.realpath(_site_packages(user_dir)) + os.sep)
    assert facts["preimported_cache_dir"] == ""  # numba read no cache folder at import
    _check_session(facts, user_dir)
    _check_cached_in_extension_folder(facts, user_dir)
    _check_loaded_the_shipped_kernels(facts, user_dir)


def test_renders_from_a_read_only_user_folder(read_only_session, user_dir):
    """The installed extension, its cache folder and the home folder all read-only (a
    read-only bind mount, which binds root too): jit.py finds no writable cache location,
    yet the shipped kernels load, and nothing is written. Where such mounts are unavailable,
    DRT_NUMBA_CACHE=0 instead: every kernel compiles in memory, nothing is read or written
    on disk. (DRT_NUMBA_CACHE=0 is also tested in-process by tests/test_kernel_cache.py.)"""
    facts, mounted, before, after = read_only_session
    _check_session(facts, user_dir)
    assert facts["jit_cache"] is False
    if mounted:
        assert facts["cache_dir_writable"] is False  # the mount really is read-only
        _check_loaded_the_shipped_kernels(facts, user_dir)
    else:
        assert facts["shipped_root"] is None
        assert facts["cache_paths"] == [] and facts["cache_hits"] == 0
    assert after == before
