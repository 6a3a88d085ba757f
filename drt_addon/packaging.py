"""Build the installable Blender extension zips, one per platform, from a source checkout.

    python -m drt_addon package [-o DIR] [--platform PLATFORM ...]

1. Every wheel that `blender_manifest.toml` lists under `wheels = [...]` must be the
   version pinned in `requirements.txt` (numpy never: it comes with Blender), and every
   platform under `platforms = [...]` must have exactly one wheel of each bundled
   distribution (embreex, numba, llvmlite).
2. The wheels of the chosen platforms (default: all of them) that are missing are
   downloaded with `pip download --no-deps --only-binary=:all:` into `./wheels/`
   (gitignored) and checked to be intact.
3. A staging copy of the files the build would take (the `[build]` exclude patterns of
   the manifest decide, with Blender's own pattern matcher), plus the chosen wheels
   (hard links where possible) and a copy of the manifest whose `platforms` and `wheels`
   name only the chosen platforms, is built with `blender_ext.py build --split-platforms`
   (Blender's extension tool, the same code as `blender --command extension build`,
   shipped inside the bpy wheel): one `DIR/<id>-<version>-<platform>.zip` per platform,
   each holding only its own wheels. `blender_ext.py validate` then checks every zip.

The llvmlite wheel alone is 40-60 MB per platform, hence one zip per platform and the
--platform option, so that a build (and the test) only downloads what it needs.

Pure Python: nothing here imports bpy (the tool is found with importlib's find_spec and
loaded by path for its platform and path-pattern helpers, which import no bpy).
"""
from __future__ import annotations

import functools
import glob
import importlib.util
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
import zipfile

from . import prebuilt_kernels

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MANIFEST = "blender_manifest.toml"
REQUIREMENTS = "requirements.txt"
DEFAULT_OUTPUT_DIR = os.path.join(REPO_ROOT, "build")
# Blender bundles numpy; a second copy in the extension would shadow it.
NEVER_BUNDLED = {"numpy"}
# The Python of Blender 4.2 to 5.x, for wheels tagged for any Python 3 ("py3")
BLENDER_PYTHON = "3.11"
# The tool's exclusions when a manifest has no [build] table (blender_ext.py build).
TOOL_DEFAULT_EXCLUDES = ["__pycache__/", ".*", "/*.zip", "*.blend[1-9]"]


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


@functools.lru_cache(maxsize=None)
def _load_tool(path: str):
    spec = importlib.util.spec_from_file_location("_drt_blender_ext", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def blender_ext_module():
    """Blender's extension tool as a module: its wheel-platform mapping and path patterns
    are the ones `build --split-platforms` uses, so DRT's checks agree with the build."""
    return _load_tool(find_blender_ext())


def manifest_platforms(root: str = REPO_ROOT) -> list[str]:
    platforms = read_manifest(root).get("platforms")
    if not (isinstance(platforms, list) and platforms
            and all(isinstance(p, str) and p for p in platforms)):
        raise PackagingError(f"{MANIFEST} must list its platforms (the bundled wheels are "
                             "platform-specific)")
    return platforms


def wheels_by_platform(root: str = REPO_ROOT) -> dict[str, list[str]]:
    """{platform: the manifest's wheels (as written there) that Blender would install on
    it}, in manifest order. Every listed platform must get exactly one wheel of each
    bundled distribution, and every wheel must serve at least one listed platform."""
    platforms = manifest_platforms(root)
    wheels = read_manifest(root).get("wheels") or []
    tool = blender_ext_module()
    result: dict[str, list[str]] = {p: [] for p in platforms}
    dists = []
    for rel in wheels:
        dist = _normalize(parse_wheel_filename(rel)[0])
        if dist not in dists:
            dists.append(dist)
        served = [p for p in platforms
                  if tool.blender_platform_compatible_with_wheel_platform_from_filepath(p, rel)]
        if not served:
            raise PackagingError(f"{MANIFEST} bundles {os.path.basename(rel)}, which is for "
                                 f"none of its platforms ({', '.join(platforms)})")
        for p in served:
            result[p].append(rel)
    for p, rels in result.items():
        for dist in dists:
            n = sum(_normalize(parse_wheel_filename(r)[0]) == dist for r in rels)
            if n != 1:
                raise PackagingError(
                    f"{MANIFEST} lists the platform {p} but has {n} {dist} wheels for it "
                    f"(exactly one needed): add its wheel or drop the platform")
    return result


def _check_pins(root: str, wheels: list[str]) -> None:
    pins = read_pins(root)
    for rel in wheels:
        filename = os.path.basename(rel)
        dist, version, *_ = parse_wheel_filename(filename)
        name = _normalize(dist)
        if name in NEVER_BUNDLED:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {dist} comes with Blender")
        if name not in pins:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {REQUIREMENTS} "
                                 f"does not pin {dist}")
        if pins[name] != version:
            raise PackagingError(f"{MANIFEST} bundles {filename}, but {REQUIREMENTS} pins "
                                 f"{dist}=={pins[name]}: update the wheel names")


def fetch_wheels(root: str = REPO_ROOT, python: str = sys.executable,
                 platforms: list[str] | None = None) -> list[str]:
    """Make sure the wheels the manifest lists for `platforms` (default: all its wheels)
    exist under `root`, downloading the missing ones from the package index. Every listed
    wheel is checked against the pins first, before anything is downloaded. Returns the
    absolute paths of the wheels for `platforms`."""
    wheels = read_manifest(root).get("wheels") or []
    _check_pins(root, wheels)
    if platforms is not None:
        per_platform = wheels_by_platform(root)
        chosen = {rel for p in platforms for rel in per_platform[p]}
        wheels = [rel for rel in wheels if rel in chosen]
    paths = []
    for rel in wheels:
        dest = os.path.normpath(os.path.join(root, rel))
        filename = os.path.basename(dest)
        dist, version, py_tag, _abi, plat_tag = parse_wheel_filename(filename)
        paths.append(dest)
        if os.path.exists(dest) and _wheel_is_complete(dest, dist, version):
            continue
        m = re.fullmatch(r"cp(\d)(\d+)", py_tag) or \
            (py_tag == "py3" and re.fullmatch(r"(\d)\.(\d+)", BLENDER_PYTHON))
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


def _blender_ext(tool: str, python: str, *args: str) -> str:
    proc = subprocess.run([python, tool, *args], capture_output=True, text=True)
    output = (proc.stdout + proc.stderr).strip()
    if proc.returncode != 0:
        lines = [line for line in output.splitlines() if line.strip()]
        raise PackagingError(f"blender_ext {args[0]} failed: " + " | ".join(lines[-5:]))
    return output


def _toml_array(key: str, items: list[str]) -> str:
    # json.dumps of a plain string is a valid TOML basic string.
    one_line = f"{key} = [{', '.join(json.dumps(i) for i in items)}]"
    if len(one_line) <= 88:
        return one_line
    return f"{key} = [\n" + "".join(f"  {json.dumps(i)},\n" for i in items) + "]"


def manifest_text_for(text: str, platforms: list[str], wheels: list[str]) -> str:
    """The manifest `text` with its `platforms` and `wheels` arrays replaced (comments and
    everything else kept); checked by parsing both."""
    new = text
    for key, items in (("platforms", platforms), ("wheels", wheels)):
        new, n = re.subn(rf"(?ms)^{key}\s*=\s*\[.*?\]", lambda _m: _toml_array(key, items),
                         new, count=1)
        if n != 1:
            raise PackagingError(f"{MANIFEST} has no top-level `{key} = [...]` to filter")
    try:
        old_d, new_d = tomllib.loads(text), tomllib.loads(new)
    except tomllib.TOMLDecodeError as e:
        raise PackagingError(f"filtering {MANIFEST} failed: {e}") from None
    old_d.update(platforms=platforms, wheels=wheels)
    if new_d != old_d:
        raise PackagingError(f"filtering {MANIFEST} changed more than platforms and wheels")
    return new


def _link_or_copy(src: str, dst: str) -> None:
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    try:
        os.link(src, dst)  # wheels are large: no copy when on the same file system
    except OSError:
        shutil.copy2(src, dst)


def _stage(root: str, stage: str, manifest: dict, platforms: list[str],
           wheels: list[str]) -> None:
    """Fill `stage` with what `blender_ext.py build` would take from `root`, the chosen
    wheels, and the manifest filtered to `platforms` and `wheels`."""
    tool = blender_ext_module()
    build = manifest.get("build") or {}
    skip = {os.path.normpath(MANIFEST)} | {os.path.normpath(w) for w in
                                           manifest.get("wheels") or []}
    stage_real = os.path.realpath(stage)
    if build.get("paths") is not None:
        raise PackagingError(f"{MANIFEST}: [build] paths is not supported here; list "
                             "exclusions in paths_exclude_pattern")
    # The tool's own walk: symbolic links are skipped, directories are tested with a
    # trailing "/", paths are root-relative with forward slashes.
    match = tool.PathPatternMatch(build.get("paths_exclude_pattern", TOOL_DEFAULT_EXCLUDES))
    for dirpath, dirnames, filenames in os.walk(root):
        rel_dir = os.path.relpath(dirpath, root)
        rel_dir = "" if rel_dir == "." else rel_dir.replace(os.sep, "/") + "/"
        dirnames[:] = [d for d in dirnames
                       if not os.path.islink(os.path.join(dirpath, d))
                       and rel_dir + d != prebuilt_kernels.FOLDER.replace(os.sep, "/")
                       and os.path.realpath(os.path.join(dirpath, d)) != stage_real
                       and not match.test_path(rel_dir + d + "/")]
        for f in filenames:
            src = os.path.join(dirpath, f)
            rel = rel_dir + f
            if (os.path.islink(src) or not os.path.isfile(src) or match.test_path(rel)
                    or os.path.normpath(rel) in skip):
                continue
            dst = os.path.join(stage, *rel.split("/"))
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copy2(src, dst)
    for rel in wheels:
        _link_or_copy(os.path.join(root, rel), os.path.join(stage, rel))
    with open(os.path.join(root, MANIFEST), encoding="utf-8") as f:
        text = f.read()
    with open(os.path.join(stage, MANIFEST), "w", encoding="utf-8") as f:
        f.write(manifest_text_for(text, platforms, wheels))


def zip_name(manifest: dict, platform: str) -> str:
    """The file name `blender_ext.py build --split-platforms` gives `platform`'s zip."""
    return f"{manifest['id']}-{manifest['version']}-{platform.replace('-', '_')}.zip"


def package(output_dir: str | None = None, root: str = REPO_ROOT,
            python: str = sys.executable, platforms: list[str] | None = None,
            kernel_tiers: tuple | None = None, kernel_scenes: tuple | None = None) -> list[str]:
    """Download the pinned wheels of `platforms` (default: every platform in the manifest),
    build one extension zip per platform into `output_dir`, validate them and return their
    absolute paths (in the manifest's platform order). The zip of this machine's platform
    also holds its kernels compiled for `kernel_tiers` (default: prebuilt_kernels' tiers;
    () for none) by rendering `kernel_scenes` (default: `compile`'s scenes)."""
    output_dir = os.path.abspath(output_dir or DEFAULT_OUTPUT_DIR)
    manifest = read_manifest(root)
    if not (manifest.get("id") and manifest.get("version")):
        raise PackagingError(f"{MANIFEST} needs an id and a version")
    listed = manifest_platforms(root)
    if platforms:
        unknown = [p for p in platforms if p not in listed]
        if unknown:
            raise PackagingError(f"{MANIFEST} does not list the platform "
                                 f"{', '.join(unknown)} (it lists {', '.join(listed)})")
    chosen = [p for p in listed if not platforms or p in platforms]
    tool = find_blender_ext()
    per_platform = wheels_by_platform(root)
    fetch_wheels(root, python, chosen)
    wheels = [w for w in manifest.get("wheels") or [] if any(w in per_platform[p]
                                                              for p in chosen)]
    try:
        os.makedirs(output_dir, exist_ok=True)
    except OSError as e:
        raise PackagingError(f"cannot create the output folder {output_dir}: {e.strerror}") \
            from None
    zips = [os.path.join(output_dir, zip_name(manifest, p)) for p in chosen]
    host = prebuilt_kernels.host_platform()
    with_kernels = host if host in chosen and kernel_tiers != () else None
    # the zip with kernels is built from a stage of its own (the others must not hold them)
    others = [p for p in chosen if p != with_kernels]
    groups = ([[with_kernels]] if with_kernels else []) + ([others] if others else [])
    with tempfile.TemporaryDirectory(prefix=".drt-stage-", dir=output_dir) as work:
        kernels = None
        if with_kernels:
            kernels = os.path.join(work, "kernels")
            try:
                prebuilt_kernels.build(kernels, kernel_tiers, kernel_scenes, python,
                                       log=_log)
            except RuntimeError as e:
                raise PackagingError(str(e)) from None
        for n, group in enumerate(groups):
            stage = os.path.join(work, f"stage{n}")
            group_wheels = [w for w in wheels if any(w in per_platform[p] for p in group)]
            _stage(root, stage, manifest, group, group_wheels)
            if group == [with_kernels]:
                shutil.copytree(kernels, os.path.join(stage, prebuilt_kernels.FOLDER),
                                ignore=shutil.ignore_patterns("*.lock"))
            _blender_ext(tool, python, "build", "--source-dir", stage, "--output-dir",
                         output_dir, "--split-platforms")
    for zip_path in zips:
        if not os.path.isfile(zip_path):
            raise PackagingError(f"blender_ext build reported success but wrote no {zip_path}")
        _blender_ext(tool, python, "validate", zip_path)
        _log(f"built and validated {zip_path} ({os.path.getsize(zip_path) / 1e6:.1f} MB)")
    return zips
