"""The on-disk cache of `converge`: reference images and measured curves, so a second
run of the same study, or a study against the same long reference, renders nothing twice.

An entry's key is a hash of what determines it: the .blend's absolute path, size and
modification time, the resolution, the engine and its settings, the sample counts, the
Blender version, and (for a curve) the reference's key. Editing the file or any setting
makes a new key; stale entries are just never read again (delete the folder to free
the space). Default folder: $XDG_CACHE_HOME/drt/converge, else ~/.cache/drt/converge.
"""
from __future__ import annotations

import hashlib
import json
import os

import numpy as np

CACHE_VERSION = 1


def default_cache_dir() -> str:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "drt", "converge")


def file_identity(path: str) -> dict:
    st = os.stat(path)
    return {"path": os.path.abspath(path), "size": st.st_size, "mtime_ns": st.st_mtime_ns}


class ConvergeCache:
    """Entries under `directory` (created on first write); None: no caching at all."""

    def __init__(self, directory: str | None):
        self.directory = directory

    @staticmethod
    def key(**parts) -> str:
        text = json.dumps({"version": CACHE_VERSION, **parts}, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:32]

    def _path(self, key: str, ext: str) -> str | None:
        return None if self.directory is None else os.path.join(self.directory, key + ext)

    def _writable(self) -> bool:
        if self.directory is None:
            return False
        try:
            os.makedirs(self.directory, exist_ok=True)
            return True
        except OSError:
            return False

    def load_arrays(self, key: str) -> dict | None:
        """The arrays and the JSON `meta` saved under `key`, or None."""
        path = self._path(key, ".npz")
        if path is None or not os.path.exists(path):
            return None
        try:
            with np.load(path) as data:
                out = {name: data[name] for name in data.files if name != "meta"}
                out["meta"] = json.loads(str(data["meta"]))
            return out
        except (OSError, ValueError, KeyError):
            return None          # a damaged entry is rendered again

    def save_arrays(self, key: str, meta: dict, **arrays) -> None:
        if not self._writable():
            return
        path = self._path(key, ".npz")
        tmp = path + ".tmp.npz"
        np.savez_compressed(tmp, meta=np.array(json.dumps(meta)), **arrays)
        os.replace(tmp, path)

    def load_json(self, key: str) -> dict | None:
        path = self._path(key, ".json")
        if path is None or not os.path.exists(path):
            return None
        try:
            with open(path) as f:
                return json.load(f)
        except (OSError, ValueError):
            return None

    def save_json(self, key: str, value: dict) -> None:
        if not self._writable():
            return
        path = self._path(key, ".json")
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(value, f)
        os.replace(tmp, path)
