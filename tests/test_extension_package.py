"""The extension zip, end to end, along the path a Blender 4.2+ user takes:

`python -m drt_addon package` builds and validates the zip; the zip holds the add-on, the
tracer and the embreex wheels and nothing of the development tree; installed with Blender's
own operator into a throwaway user extension repository it is enabled as
`bl_ext.user_default.drt` and renders the Cornell box with the DRT engine.

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
import subprocess
import sys
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


# ----------------------------------------------------------------------------- building

@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Run the documented command; return (zip path, the command's stdout and stderr)."""
    out_dir = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([sys.executable, "-m", "drt_addon", "package", "-o", str(out_dir)],
                          cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, f"package failed ({proc.returncode}):\n{proc.stderr}"
    lines = proc.stdout.strip().splitlines()
    assert lines, f"package printed no zip path; stderr:\n{proc.stderr}"
    return lines[-1], proc


def test_package_command_prints_the_zip_it_built(built):
    zip_path, proc = built
    m = _manifest()
    assert os.path.basename(zip_path) == f"{m['id']}-{m['version']}.zip"
    assert os.path.isfile(zip_path) and zipfile.is_zipfile(zip_path)
    assert "validated" in proc.stderr


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
    for required in ("blender_manifest.toml", "__init__.py", "drt_addon/__init__.py",
                     "drt_addon/render_engine.py", "drt_addon/engine_link.py",
                     "engine/__init__.py", "engine/accel.py", "engine/render.py"):
        assert required in names, required
    wheels = zipped_manifest["wheels"]
    assert wheels == _manifest()["wheels"]
    for w in wheels:
        assert os.path.normpath(w).replace(os.sep, "/") in names, w
    assert any("manylinux" in w and w.endswith("x86_64.whl") for w in wheels)
    forbidden_tops = {"tests", "docs", "sample_blends", ".venv", ".git", ".ci", "build",
                      "renders", "requirements.txt", "pytest.ini", ".gitignore",
                      ".pytest_cache"}
    for name in names:
        assert name.split("/")[0] not in forbidden_tops, name
        assert "__pycache__" not in name and not name.endswith((".pyc", ".blend", ".zip")), name
        assert "numpy" not in name.lower(), f"numpy comes with Blender, not the zip: {name}"
    # Top level: the package, plus at most a README or licence text.
    extras = {n.split("/")[0] for n in names} - {"blender_manifest.toml", "__init__.py",
                                                 "drt_addon", "engine", "wheels"}
    assert all(x in names and x.upper().startswith(("README", "LICENSE", "COPYING"))
               for x in extras), sorted(extras)


def test_bundled_wheels_are_the_pinned_embreex_for_every_listed_platform(built):
    zip_path, _ = built
    pin = packaging.read_pins(ROOT)["embreex"]
    m = _manifest()
    blender_ext = _blender_ext_module()
    covered = set()
    with zipfile.ZipFile(zip_path) as z:
        for rel in m["wheels"]:
            dist, version, py_tag, abi_tag, plat = packaging.parse_wheel_filename(rel)
            assert (dist, version, py_tag, abi_tag) == ("embreex", pin, "cp311", "cp311"), rel
            covered.update(blender_ext.blender_platforms_from_wheel_platform(plat))
            member = os.path.normpath(rel).replace(os.sep, "/")
            with open(os.path.join(ROOT, rel), "rb") as f:
                on_disk = hashlib.sha256(f.read()).hexdigest()
            assert hashlib.sha256(z.read(member)).hexdigest() == on_disk, rel
    # Each listed platform has its wheel, and no wheel is for an unlisted platform.
    assert covered == set(m["platforms"])


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
SESSION = r'''
import json, os, site, sys, time
args = json.loads(sys.argv[1])
facts = {}

if args["hide_env_embreex"]:
    # A Blender's own Python has no embreex: hide the one in this environment's
    # site-packages so that only the extension's bundled wheel can provide it.
    import importlib.abc, importlib.machinery
    env_sites = {os.path.realpath(p) for p in site.getsitepackages()}
    class HideEnvEmbreex(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name != "embreex":
                return None
            dirs = [p for p in sys.path if os.path.realpath(p) not in env_sites]
            spec = importlib.machinery.PathFinder.find_spec(name, dirs)
            if spec is None:
                raise ModuleNotFoundError("No module named 'embreex' (environment's hidden)",
                                          name=name)
            return spec
    sys.meta_path.insert(0, HideEnvEmbreex())
    try:
        import embreex
        facts["embreex_before"] = embreex.__file__
        del sys.modules["embreex"]
    except ModuleNotFoundError:
        facts["embreex_before"] = None

import bpy
import numpy as np

def drt_engine():
    return next((c for c in bpy.types.RenderEngine.__subclasses__()
                 if getattr(c, "bl_idname", None) == "DRT"), None)

facts["user_extensions"] = bpy.utils.user_resource("EXTENSIONS")
facts["drt_before"] = drt_engine() is not None
if args["install"]:
    result = bpy.ops.extensions.package_install_files(
        filepath=args["zip"], repo="user_default", enable_on_install=True)
    facts["op"] = sorted(result)
    bpy.ops.wm.save_userpref()
else:
    # What Blender does at start-up: read the preferences, enable the add-ons they list.
    facts["op"] = sorted(bpy.ops.wm.read_userpref())
facts["enabled"] = args["pkg"] in bpy.context.preferences.addons

cls = drt_engine()
mod = sys.modules.get(cls.__module__) if cls else None
facts["engine_module"] = cls.__module__ if cls else None
facts["engine_file"] = getattr(mod, "__file__", None)
tracer = sys.modules.get(args["pkg"] + ".engine")
facts["tracer_file"] = getattr(tracer, "__file__", None)

bpy.ops.wm.open_mainfile(filepath=args["blend"], load_ui=False)
scene = bpy.context.scene
scene.render.engine = "DRT"
scene.render.resolution_percentage = 12
scene.drt.samples = 2
facts["expected_size"] = [scene.render.resolution_x * 12 // 100,
                          scene.render.resolution_y * 12 // 100]
t0 = time.perf_counter()
bpy.ops.render.render(write_still=False)
facts["render_seconds"] = time.perf_counter() - t0
facts["last_render"] = {k: mod.last_render.get(k) for k in ("ok", "error")} if mod else None

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

emb = sys.modules.get("embreex")
facts["embreex_file"] = getattr(emb, "__file__", None)
facts["source_modules"] = sorted(m for m in sys.modules
                                 if m.split(".")[0] in ("drt_addon", "engine"))
facts["repo_on_path"] = [p for p in sys.path if os.path.realpath(p or ".") ==
                         os.path.realpath(args["repo"])]
print("FACTS " + json.dumps(facts))
'''


def _session(tmp, user_dir, zip_path, *, install, hide_env_embreex) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("BLENDER_USER_", "PYTHON"))}
    env["BLENDER_USER_RESOURCES"] = user_dir  # never the real ~/.config/blender
    args = {"zip": zip_path, "blend": CORNELL, "pkg": PKG, "repo": ROOT, "tmp": str(tmp),
            "install": install, "hide_env_embreex": hide_env_embreex}
    proc = subprocess.run([sys.executable, "-I", "-c", SESSION, json.dumps(args)],
                          cwd=str(tmp), env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"Blender session failed:\n{proc.stdout}\n{proc.stderr}"
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("FACTS ")]
    assert lines, f"no FACTS line:\n{proc.stdout}\n{proc.stderr}"
    facts = json.loads(lines[-1][len("FACTS "):])
    print(json.dumps(facts, indent=1))  # shown with -s / on failure
    return facts


@pytest.fixture(scope="module")
def user_dir(tmp_path_factory):
    return str(tmp_path_factory.mktemp("blender_user"))


@pytest.fixture(scope="module")
def first_session(built, user_dir, tmp_path_factory):
    return _session(tmp_path_factory.mktemp("session1"), user_dir, built[0],
                    install=True, hide_env_embreex=True)


@pytest.fixture(scope="module")
def restart_session(first_session, built, user_dir, tmp_path_factory):
    return _session(tmp_path_factory.mktemp("session2"), user_dir, built[0],
                    install=False, hide_env_embreex=False)


def _check_session(facts, user_dir):
    ext_dir = os.path.realpath(os.path.join(user_dir, "extensions"))
    assert os.path.realpath(facts["user_extensions"]) == ext_dir
    assert facts["op"] == ["FINISHED"]
    assert facts["enabled"], f"{PKG} is not among the enabled add-ons"
    # The engine and the tracer are the installed copies, never the source checkout.
    assert facts["engine_module"] == PKG + ".drt_addon.render_engine"
    for key in ("engine_file", "tracer_file"):
        assert os.path.realpath(facts[key]).startswith(
            os.path.join(ext_dir, "user_default", "drt") + os.sep), (key, facts[key])
    assert facts["source_modules"] == [] and facts["repo_on_path"] == []
    # The render.
    assert facts["last_render"] == {"ok": True, "error": None}
    assert facts["size"] == facts["expected_size"]
    assert min(facts["size"]) >= 8
    assert facts["finite"]
    assert facts["max"] > 0.01 and facts["std"] > 1e-3 and facts["distinct"] > 10
    # embreex from the bundled wheel, which Blender unpacked into extensions/.local.
    assert os.path.realpath(facts["embreex_file"]).startswith(
        os.path.join(ext_dir, ".local", "lib") + os.sep), facts["embreex_file"]


def test_install_from_disk_enables_and_renders(first_session, user_dir):
    """Install from Disk in a Blender whose Python has no embreex: the wheel alone works."""
    assert first_session["embreex_before"] is None  # the hiding works: a real check
    assert not first_session["drt_before"]          # DRT only exists once installed
    _check_session(first_session, user_dir)


def test_after_restart_the_extension_is_enabled_and_prefers_its_wheel(restart_session,
                                                                      user_dir):
    """A second Blender start with the same user folder, nothing hidden: the extension is
    enabled from the saved preferences and Blender's site-packages order picks the
    bundled embreex over one installed in the Python environment."""
    assert not restart_session["drt_before"]
    _check_session(restart_session, user_dir)
