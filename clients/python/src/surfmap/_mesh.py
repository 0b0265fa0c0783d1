"""Mesh inputs: a path, bytes, or ``(vertices, faces)`` arrays, as the bytes to upload."""

from __future__ import annotations

import io
import os
from typing import Any, Optional, Tuple

_HINTS = {".obj": "obj", ".off": "off", ".ply": "ply", ".stl": "stl"}


def is_mesh_id(x: Any) -> bool:
    """A stored mesh's id: 64 lowercase hex digits (the sha256 of its bytes)."""
    return isinstance(x, str) and len(x) == 64 and all(c in "0123456789abcdef" for c in x)


def obj_bytes(vertices: Any, faces: Any) -> bytes:
    """A Wavefront OBJ of an (n, 3) float array and an (m, 3) 0-based int array."""
    import numpy as np

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be an (n, 3) array, got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be an (m, 3) integer array, got shape {f.shape} of {f.dtype}")
    buf = io.BytesIO()
    np.savetxt(buf, v, fmt="v %.17g %.17g %.17g")
    np.savetxt(buf, f.astype(np.int64) + 1, fmt="f %d %d %d")
    return buf.getvalue()


def mesh_input(mesh: Any, fmt: Optional[str] = None) -> Tuple[bytes, Optional[str]]:
    """The bytes of `mesh` and a format hint (``obj``, ``off``, ``ply``, ``stl``, or None:
    the server tells from the content)."""
    if isinstance(mesh, (bytes, bytearray, memoryview)):
        return bytes(mesh), fmt
    if isinstance(mesh, (str, os.PathLike)):
        path = os.fspath(mesh)
        with open(path, "rb") as fh:
            data = fh.read()
        return data, fmt or _HINTS.get(os.path.splitext(path)[1].lower())
    if isinstance(mesh, tuple) and len(mesh) == 2:
        return obj_bytes(*mesh), "obj"
    if isinstance(mesh, dict) and "vertices" in mesh and "faces" in mesh:
        return obj_bytes(mesh["vertices"], mesh["faces"]), "obj"
    raise TypeError(
        f"a mesh is a path, bytes, (vertices, faces) arrays or {{'vertices', 'faces'}}, not {type(mesh).__name__}"
    )
