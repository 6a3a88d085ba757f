"""One channel of an uncompressed scanline OpenEXR file, read with NumPy: what Blender's
Python API cannot give of a render (a pass other than Combined, such as Cycles' Debug
Sample Count). Blender writes such a file with its output set to multilayer OpenEXR,
codec None, 32-bit float.

The format (OpenEXR's "Technical Introduction"): a magic number and version, a header of
attributes (name, type, size, value) up to an empty name (a multipart file: one header
per part, then an empty one), one 64-bit offset per chunk (per part, in order), then each
chunk (its part number in a multipart file): its y, its byte count, and the channels in
the header's (alphabetical) order, each a row of values (HALF 2 bytes, FLOAT and UINT 4);
uncompressed, a chunk is one scanline.
"""
from __future__ import annotations

import struct

import numpy as np

_MAGIC = 20000630
_MULTIPART = 0x1000
_TYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}


def _attributes(data: bytes, at: int):
    """({name: (type, value bytes)} of the header at `at`, offset after it)."""
    out = {}
    while data[at] != 0:
        name_end = data.index(b"\0", at)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        value = data[type_end + 5:type_end + 5 + size]
        out[data[at:name_end].decode()] = (data[name_end + 1:type_end].decode(), value)
        at = type_end + 5 + size
    return out, at + 1


def _headers(data: bytes):
    """([header, ...], offset after them, multipart): a multipart file (Blender's
    multilayer EXR: one part per pass) has several, ended by an empty one."""
    magic, version = struct.unpack_from("<ii", data, 0)
    if magic != _MAGIC:
        raise ValueError("not an OpenEXR file")
    multipart = bool(version & _MULTIPART)
    headers, at = [], 8
    while True:
        attrs, at = _attributes(data, at)
        headers.append(attrs)
        if not multipart:
            return headers, at, False
        if data[at] == 0:
            return headers, at + 1, True


def _channels(value: bytes):
    """[(name, pixel type)] of a chlist attribute."""
    out, at = [], 0
    while value[at] != 0:
        end = value.index(b"\0", at)
        (kind,) = struct.unpack_from("<i", value, end + 1)
        out.append((value[at:end].decode(), kind))
        at = end + 1 + 16
    return out


def read_channel(path: str, name: str) -> np.ndarray:
    """(h, w) float64 of channel `name` (e.g. "ViewLayer.Debug Sample Count.X"), row 0
    at the top."""
    with open(path, "rb") as f:
        data = f.read()
    headers, at, multipart = _headers(data)
    found = []
    for part, attrs in enumerate(headers):
        x0, y0, x1, y1 = struct.unpack("<iiii", attrs["dataWindow"][1])
        h = y1 - y0 + 1
        chunks = struct.unpack("<i", attrs["chunkCount"][1])[0] if "chunkCount" in attrs \
            else h
        channels = _channels(attrs["channels"][1])
        found += [c for c, _ in channels]
        if name in found[-len(channels):]:
            break
        at += 8 * chunks                              # this part's offset table
    else:
        raise KeyError(f"{path} has no channel {name!r}; it has {found}")
    if attrs["compression"][1][0] != 0:
        raise ValueError(f"{path}: compressed; write it with codec None")
    w = x1 - x0 + 1
    offsets = np.frombuffer(data, "<u8", count=chunks, offset=at)
    out = np.empty((h, w))
    skip = 4 if multipart else 0                      # a chunk's part number
    for start in offsets:
        (y,) = struct.unpack_from("<i", data, int(start) + skip)
        row, at = y - y0, int(start) + skip + 8       # after y and the byte count
        for c, kind in channels:
            dtype = _TYPES[kind]
            if c == name:
                out[row] = np.frombuffer(data, dtype, count=w, offset=at)
            at += w * dtype.itemsize
    return out


def read_string(path: str, name: str) -> str:
    """A string attribute of the (first part's) header, e.g. Cycles'
    "cycles.ViewLayer.samples": the samples it rendered."""
    with open(path, "rb") as f:
        data = f.read()
    kind, value = _headers(data)[0][0][name]
    if kind != "string":
        raise ValueError(f"{name} is a {kind}, not a string")
    return value.decode()
