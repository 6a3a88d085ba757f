"""Build the installable Blender extension zip from a source checkout.

    python -m drt_addon package [-o DIR]

1. Every wheel that `blender_manifest.toml` lists under `wheels = [...]` must be the
   version pinned in `requirements.txt`; missing ones are downloaded with
   `pip download --no-deps --only-binary=:all:` into `./wheels/` (gitignored).
2. `blender_ext.py build` (Blender's extension tool, the same code as
   `blender --command extension build`, shipped inside the bpy wheel) writes
   `DIR/<id>-<version>.zip`; `blender_ext.py validate` then checks that zip.

Pure Python: nothing here imports bpy (the tool is found with importlib's find_spec).
"""
from __future__ import annotations

import glob
import importlib.util
import os
import re
import subprocess
import sys
import tempfile
import tomllib
import zipfile

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MANIFEST = "blender_manifest.toml"
REQUIREMENTS = "requirements.txt"
DEFAULT_OUTPUT_DIR = os.path.join(REPO_ROOT, "build")
# Blender bundles numpy; a second copy in the extension would shadow it.
NEVER_BUNDLED = {"numpy"}


class PackagingError(Exception):
    """A packaging step failed; the message is one line for the user."""


def _log(message: str) -> None:
    print(f"drt: {message}", file=sys.stderr, flush=True)


def _normalize(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def read_manifest(root: str = REPO_ROOT) -> dict:
    path = os.path.join(root, MANIFEST)
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise PackagingError(f"{path} not found (run from a DRT source checkout)") from None
    except tomllib.TOMLDecodeError as e:
        raise PackagingError(f"{path}: {e}") from None


def read_pins(root: str = REPO_ROOT) -> dict[str, str]:
    """`name==version` lines of requirements.txt, keyed by normalized name."""
    path = os.path.join(root, REQUIREMENTS)
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except FileNotFoundError:
        raise PackagingError(f"{path} not found (run from a DRT source checkout)") from None
    pins = {}
    for line in lines:
        m = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*==\s*([^\s;#]+)", line)
        if m:
            pins[_normalize(m.group(1))] = m.group(2)
    return pins


def parse_wheel_filename(filename: str) -> tuple[str, str, str, str, str]:
    """(distribution, version, python tag, abi tag, platform tag) of a wheel file name."""
    parts = os.path.basename(filename)[:-len(".whl")].split("-")
    if not filename.endswith(".whl") or len(parts) not in (5, 6):
        raise PackagingError(f"not a wheel file name: {filename}")
    return parts[0], parts[1], parts[-3], parts[-2], parts[-1]


def _wheel_is_complete(path: str, dist: str, version: str) -> bool:
    """An intact wheel (CRCs check out) of exactly `dist` `version`."""
    if not zipfile.is_zipfile(path):
        return False
    try:
        with zipfile.ZipFile(path) as z:
            if f"{dist}-{version}.dist-info/METADATA" not in z.namelist():
                return False
            return z.testzip() is None
    except (zipfile.BadZipFile, OSError):
        return False


def fetch_wheels(root: str = REPO_ROOT, python: str = sys.executable) -> list[str]:
    """Make sure every wheel the manifest lists exists under `root`, downloading the
    missing ones from the package index. Returns their absolute paths."""
    wheels = read_manifest(root).get("wheels") or []
    pins = read_pins(root)
    paths = []
    for rel in wheels:
        dest = os.path.normpath(os.path.join(root, rel))
        filename = os.path.basename(dest)
        dist, version, py_tag, _abi, plat_tag = parse_wheel_filename(filename)
        name = _normalize(dist)
        if name in NEVER_BUNDLED:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {dist} comes with Blender")
        if name not in pins:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {REQUIREMENTS} "
                                 f"does not pin {dist}")
        if pins[name] != version:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {REQUIREMENTS} pins "
                                 f"{dist}=={pins[name]}: update the wheel names")
        paths.append(dest)
        if os.path.exists(dest) and _wheel_is_complete(dest, dist, version):
            continue
        m = re.fullmatch(r"cp(\d)(\d+)", py_tag)
        if not m:
            raise PackagingError(f"cannot tell the Python version of {filename}")
        _log(f"downloading {filename}")
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        with tempfile.TemporaryDirectory(dir=os.path.dirname(dest)) as tmp:
            cmd = [python, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
                   "--no-deps", "--only-binary=:all:",
                   "--python-version", f"{m.group(1)}.{m.group(2)}", "--implementation", "cp",
                   *[a for tag in plat_tag.split(".") for a in ("--platform", tag)],
                   f"{dist}=={version}", "--dest", tmp]
            proc = subprocess.run(cmd, capture_output=True, text=True)
            got = os.path.join(tmp, filename)
            if proc.returncode != 0 or not os.path.exists(got):
                found = ", ".join(os.listdir(tmp)) or "nothing"
                detail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
                raise PackagingError(f"pip download of {filename} failed (got {found}): "
                                     f"{detail}")
            if not _wheel_is_complete(got, dist, version):
                raise PackagingError(f"downloaded {filename} is not an intact wheel")
            os.replace(got, dest)  # atomic: a concurrent build never sees half a wheel
    return paths


def find_blender_ext() -> str:
    """blender_ext.py from the installed bpy module (bpy/<ver>/scripts/addons_core/bl_pkg/cli)."""
    spec = importlib.util.find_spec("bpy")  # locates the package without importing it
    for location in (spec.submodule_search_locations or []) if spec else []:
        found = sorted(glob.glob(os.path.join(location, "*", "scripts", "addons_core", "bl_pkg",
                                              "cli", "blender_ext.py")))
        if found:
            return found[-1]
    raise PackagingError("Blender's extension tool (blender_ext.py) not found: install the "
                         "bpy module (requirements.txt), or build with "
                         "`blender --command extension build`")


def _blender_ext(tool: str, python: str, *args: str) -> str:
    proc = subprocess.run([python, tool, *args], capture_output=True, text=True)
    output = (proc.stdout + proc.stderr).strip()
    if proc.returncode != 0:
        lines = [line for line in output.splitlines() if line.strip()]
        raise PackagingError(f"blender_ext {args[0]} failed: " + " | ".join(lines[-5:]))
    return output


def package(output_dir: str | None = None, root: str = REPO_ROOT,
            python: str = sys.executable) -> str:
    """Download the pinned wheels, build the extension zip into `output_dir`, validate it
    and return the zip's absolute path."""
    output_dir = os.path.abspath(output_dir or DEFAULT_OUTPUT_DIR)
    manifest = read_manifest(root)
    if not (manifest.get("id") and manifest.get("version")):
        raise PackagingError(f"{MANIFEST} needs an id and a version")
    tool = find_blender_ext()
    fetch_wheels(root, python)
    try:
        os.makedirs(output_dir, exist_ok=True)
    except OSError as e:
        raise PackagingError(f"cannot create the output folder {output_dir}: {e.strerror}") \
            from None
    zip_path = os.path.join(output_dir, f"{manifest['id']}-{manifest['version']}.zip")
    _blender_ext(tool, python, "build", "--source-dir", root, "--output-filepath", zip_path)
    _blender_ext(tool, python, "validate", zip_path)
    if not os.path.isfile(zip_path):
        raise PackagingError(f"blender_ext build reported success but wrote no {zip_path}")
    _log(f"built and validated {zip_path} ({os.path.getsize(zip_path) / 1e6:.1f} MB)")
    return zip_path

