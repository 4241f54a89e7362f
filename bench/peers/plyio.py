# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Minimal PLY vertex reader and binary writer for the peer benchmark (numpy only).

read_ply() returns the vertex element as {property name: 1-D numpy array}. It reads
ascii, binary_little_endian and binary_big_endian files with scalar properties of any PLY
type (char/uchar/short/ushort/int/uint/float/double and their int8..float64 aliases).
Elements that come before "vertex" are skipped when they have only scalar properties;
list properties are accepted only in elements after the vertex element (e.g. faces).
"""

from __future__ import annotations

import numpy as np

_TYPES = {
    "char": "i1", "int8": "i1",
    "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4",
    "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4",
    "double": "f8", "float64": "f8",
}


class PlyError(ValueError):
    """Malformed or unsupported PLY file; the message names the file."""


def _parse_header(path, f):
    if f.readline().strip() != b"ply":
        raise PlyError(f"{path}: not a PLY file (missing 'ply' magic)")
    fmt = None
    elements = []  # [name, count, [(prop name, type or None for lists, list types or None)]]
    while True:
        line = f.readline()
        if not line:
            raise PlyError(f"{path}: header has no end_header")
        words = line.decode("ascii", "replace").split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "end_header":
            break
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property":
            if not elements:
                raise PlyError(f"{path}: property before any element")
            if words[1] == "list":
                if words[2] not in _TYPES or words[3] not in _TYPES:
                    raise PlyError(f"{path}: unsupported list types '{words[2]} {words[3]}'")
                elements[-1][2].append((words[4], None, (_TYPES[words[2]], _TYPES[words[3]])))
            else:
                if words[1] not in _TYPES:
                    raise PlyError(f"{path}: unsupported property type '{words[1]}'")
                elements[-1][2].append((words[2], _TYPES[words[1]], None))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise PlyError(f"{path}: unsupported format '{fmt}'")
    return fmt, elements


def read_ply(path) -> dict:
    """Returns the vertex properties of a PLY file as {name: numpy array of length N}."""
    with open(path, "rb") as f:
        fmt, elements = _parse_header(path, f)
        if fmt == "ascii":
            lines = f.read().decode("ascii").splitlines()
            row = 0
            for name, count, props in elements:
                if name == "vertex":
                    if any(t is None for _, t, _ in props):
                        raise PlyError(f"{path}: list property in the vertex element")
                    table = np.loadtxt(lines[row:row + count], ndmin=2,
                                       dtype=np.float64).reshape(count, len(props))
                    return {p: table[:, i].astype(t) for i, (p, t, _) in enumerate(props)}
                row += count
            raise PlyError(f"{path}: no vertex element")
        endian = "<" if fmt == "binary_little_endian" else ">"
        for name, count, props in elements:
            if any(t is None for _, t, _ in props):
                raise PlyError(f"{path}: list property in element '{name}' before the vertices")
            dtype = np.dtype([(p, endian + t) for p, t, _ in props])
            if name != "vertex":
                f.seek(count * dtype.itemsize, 1)
                continue
            data = np.fromfile(f, dtype=dtype, count=count)
            if data.shape[0] != count:
                raise PlyError(f"{path}: truncated ({data.shape[0]} of {count} vertices)")
            return {p: data[p].astype(np.dtype(t)) for p, t, _ in props}
        raise PlyError(f"{path}: no vertex element")


def read_mesh_ply(path) -> tuple[np.ndarray, np.ndarray]:
    """A binary triangle mesh: vertex positions (N x 3 float64) and faces (F x 3 int64); the
    vertex element's scalar properties and one list property of triangles in the face element
    (what pointform's write_mesh and the CGAL peers write)."""
    with open(path, "rb") as f:
        fmt, elements = _parse_header(path, f)
        if fmt == "ascii":
            raise PlyError(f"{path}: only binary PLY meshes are read here")
        endian = "<" if fmt == "binary_little_endian" else ">"
        positions = faces = None
        for name, count, props in elements:
            if name == "vertex":
                dtype = np.dtype([(p, endian + t) for p, t, _ in props])
                v = np.fromfile(f, dtype=dtype, count=count)
                positions = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
            elif name == "face" and len(props) == 1 and props[0][1] is None:
                count_type, index_type = props[0][2]
                dtype = np.dtype([("n", endian + count_type), ("i", endian + index_type, (3,))])
                fc = np.fromfile(f, dtype=dtype, count=count)
                if np.any(fc["n"] != 3):
                    raise PlyError(f"{path}: faces that are not triangles")
                faces = fc["i"].astype(np.int64)
            else:
                raise PlyError(f"{path}: unexpected element '{name}'")
        if positions is None or faces is None:
            raise PlyError(f"{path}: no vertices or no faces")
        return positions, faces


def write_ply(path, columns: dict, comment: str | None = None) -> None:
    """Writes {name: 1-D array} as the vertex element of a binary little-endian PLY."""
    names = {"i1": "char", "u1": "uchar", "i2": "short", "u2": "ushort", "i4": "int",
             "u4": "uint", "f4": "float", "f8": "double"}
    count = len(next(iter(columns.values())))
    dtype = np.dtype([(k, "<" + np.asarray(v).dtype.str[1:]) for k, v in columns.items()])
    data = np.empty(count, dtype=dtype)
    header = ["ply", "format binary_little_endian 1.0"]
    if comment:
        header.append(f"comment {comment}")
    header.append(f"element vertex {count}")
    for k, v in columns.items():
        v = np.asarray(v)
        if v.shape != (count,):
            raise ValueError(f"column '{k}' has shape {v.shape}, expected ({count},)")
        header.append(f"property {names[v.dtype.str[1:]]} {k}")
        data[k] = v
    header.append("end_header")
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        data.tofile(f)


def positions(vertex: dict) -> np.ndarray:
    """N by 3 positions (x y z) in their stored precision."""
    return np.stack([vertex["x"], vertex["y"], vertex["z"]], axis=1)


def normals(vertex: dict) -> np.ndarray | None:
    """N by 3 normals (nx ny nz) as float64, or None when the file has none."""
    if not all(k in vertex for k in ("nx", "ny", "nz")):
        return None
    return np.stack([vertex["nx"], vertex["ny"], vertex["nz"]], axis=1).astype(np.float64)
