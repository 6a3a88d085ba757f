"""Cryptomatte: per pixel, the objects, materials or assets it shows and how much of it
each covers, as Cycles writes them (the Cryptomatte standard of Friedman and Jones,
Psyop 2015).

Each name is hashed with MurmurHash3_32 (seed 0) and the hash stored as a float32 whose
bits are the hash with the exponent kept off 0 and 255 (no denormals, infinities or
NaNs), Cycles' `util_hash_to_float`. A pixel's coverage of a name is the share of its
camera samples whose first hit carries that name; the `depth` names of largest coverage
are written, as (id, coverage) pairs, two to an RGBA pass. The manifest (name -> hash
as 8 hex digits) goes into the render result's metadata, from which Blender's
Cryptomatte node turns a picked name back into its id.

What names a hit carries (engine.scene): its object's `object_name` (an instance: its
place's own), the object's `asset_name` (its topmost parent, Cycles' Asset), and the
name of the material of its triangle.
"""
from __future__ import annotations

import json

import numpy as np

KINDS = ("object", "material", "asset")
_M32 = 0xFFFFFFFF


def murmur3_32(data: bytes, seed: int = 0) -> int:
    """MurmurHash3's 32-bit x86 hash of `data` (Appleby's reference)."""
    c1, c2 = 0xCC9E2D51, 0x1B873593
    h = seed & _M32
    n = len(data) // 4 * 4
    for i in range(0, n, 4):
        k = int.from_bytes(data[i:i + 4], "little")
        k = (k * c1) & _M32
        k = ((k << 15) | (k >> 17)) & _M32
        k = (k * c2) & _M32
        h ^= k
        h = ((h << 13) | (h >> 19)) & _M32
        h = (h * 5 + 0xE6546B64) & _M32
    tail = data[n:]
    k = 0
    for i, b in enumerate(tail):
        k |= b << (8 * i)
    if tail:
        k = (k * c1) & _M32
        k = ((k << 15) | (k >> 17)) & _M32
        k = (k * c2) & _M32
        h ^= k
    h ^= len(data)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & _M32
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & _M32
    h ^= h >> 16
    return h


def hash_to_float(h: int) -> np.float32:
    """The float32 id of hash h: its bits, the exponent clamped to [1, 254]."""
    exponent = min(max((h >> 23) & 0xFF, 1), 254)
    bits = (h & 0x80000000) | (exponent << 23) | (h & 0x7FFFFF)
    return np.array([bits], np.uint32).view(np.float32)[0]


def name_id(name: str) -> tuple[int, np.float32]:
    """(hash, float32 id) of a name, hashed as UTF-8."""
    h = murmur3_32(name.encode("utf-8"))
    return h, hash_to_float(h)


def manifest(names) -> str:
    """The manifest of the metadata: JSON {name: hash as 8 hex digits}."""
    return json.dumps({n: f"{name_id(n)[0]:08x}" for n in sorted(set(names))},
                      separators=(",", ":"))


def layer_key(layer_name: str) -> str:
    """The metadata prefix of a Cryptomatte layer ("ViewLayer.CryptoObject"):
    "cryptomatte/" and the first 7 hex digits of the layer name's hash."""
    return f"cryptomatte/{murmur3_32(layer_name.encode('utf-8')):08x}"[:19]


def metadata(layer_name: str, names) -> dict:
    """The render result's metadata fields of one Cryptomatte layer."""
    key = layer_key(layer_name)
    return {f"{key}/name": layer_name, f"{key}/hash": "MurmurHash3_32",
            f"{key}/conversion": "uint32_to_float32", f"{key}/manifest": manifest(names)}


def ranked(pixel: np.ndarray, ids: np.ndarray, n_pixels: int, samples: int, depth: int):
    """The `depth` ids of largest coverage per pixel, from one id per camera sample
    (`pixel` its pixel, `ids` float32; samples that hit nothing left out) of `samples`
    per pixel: (ids (n_pixels, depth) float32, coverage (n_pixels, depth) float32), 0
    where a pixel shows fewer names. Ties rank by id, as the order of hashes."""
    out_id = np.zeros((n_pixels, depth), np.float32)
    out_cov = np.zeros((n_pixels, depth), np.float32)
    if len(pixel) == 0:
        return out_id, out_cov
    bits = ids.astype(np.float32).view(np.uint32).astype(np.int64)
    keys, counts = np.unique(pixel.astype(np.int64) << 32 | bits, return_counts=True)
    pix, bits = keys >> 32, keys & 0xFFFFFFFF
    order = np.lexsort((bits, -counts, pix))          # per pixel, largest coverage first
    pix, bits, counts = pix[order], bits[order], counts[order]
    first = np.searchsorted(pix, pix, side="left")
    rank = np.arange(len(pix)) - first
    keep = rank < depth
    out_id[pix[keep], rank[keep]] = bits[keep].astype(np.uint32).view(np.float32)
    out_cov[pix[keep], rank[keep]] = counts[keep] / float(samples)
    return out_id, out_cov


class HitNames:
    """The names a hit carries, as float32 ids: per triangle mesh (in the accelerator's
    order), per instance place (its object-table row) and per material."""

    def __init__(self, ctx):
        ordered = ctx.accel.ordered_meshes
        self.names = {kind: set() for kind in KINDS}
        mesh_names = [(_object_name(m), _asset_name(m)) for m in ordered]
        self._mesh = {kind: self._ids(kind, [pair[i] for pair in mesh_names])
                      for i, kind in enumerate(("object", "asset"))}
        self._mesh_of = ctx.surfaces.mesh_of
        rows = ctx.accel.instance_count
        self._place = {kind: np.zeros(rows, np.float32) for kind in ("object", "asset")}
        for proto in ctx.accel.prototypes:
            inst = proto.mesh.instances
            pairs = inst.names or ((_object_name(proto.mesh), _asset_name(proto.mesh)),)
            ids = np.zeros(len(inst), np.int64) if inst.name_ids is None else inst.name_ids
            for i, kind in enumerate(("object", "asset")):
                table = self._ids(kind, [pair[i] for pair in pairs])
                self._place[kind][proto.first_row:proto.first_row + len(inst)] = table[ids]
        self._material = self._ids("material", [m.name for m in ctx.scene.materials])

    def _ids(self, kind, names) -> np.ndarray:
        self.names[kind].update(names)
        return np.array([name_id(n)[1] for n in names] or [0.0], np.float32)

    def of(self, kind: str, prim, inst, material) -> np.ndarray:
        """The float32 ids of hits on triangles `prim` of places `inst` (-1: none) of
        material indices `material`."""
        if kind == "material":
            return self._material[np.minimum(material, len(self._material) - 1)]
        ids = self._mesh[kind][self._mesh_of(prim)]
        placed = inst >= 0
        if placed.any():
            ids[placed] = self._place[kind][inst[placed]]
        return ids


def _object_name(mesh) -> str:
    return getattr(mesh, "object_name", "") or mesh.name


def _asset_name(mesh) -> str:
    return getattr(mesh, "asset_name", "") or _object_name(mesh)
