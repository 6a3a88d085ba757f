"""Linked libraries that could not be found when the .blend was opened.

Blender opens such a file anyway and puts empty placeholders where the linked data was
(`ID.is_missing`): a linked object renders as nothing, a linked material as none. Cycles
renders it so, and so does DRT, but never silently: each missing library is reported once,
naming the file and what it should have brought."""
from __future__ import annotations

import os

import bpy


def missing_library_messages(data=None) -> list:
    """One message per linked library that is missing (none when all were found)."""
    data = data if data is not None else bpy.data
    messages = []
    for lib in data.libraries:
        path = bpy.path.abspath(lib.filepath, library=lib.library)
        if not getattr(lib, "is_missing", False) and os.path.exists(path):
            continue
        lost = sorted(f"{type(i).__name__} {i.name!r}" for i in getattr(lib, "users_id", ())
                      if getattr(i, "is_missing", False))       # users_id: Blender 4.2+
        shown = ", ".join(lost[:5]) + (f" and {len(lost) - 5} more" if len(lost) > 5 else "")
        messages.append(f"linked library {lib.filepath!r} not found ({os.path.normpath(path)})"
                        f"; {len(lost)} linked data-block(s) from it are missing from the "
                        f"render" + (f": {shown}" if lost else ""))
    return messages
