"""GPU instancing of a glb's repeated parts (glTF's ``EXT_mesh_gpu_instancing``).

A mesh placed by many nodes is drawn once, at every placement: one node carries the
mesh and, as accessors, each instance's translation, rotation (a unit quaternion) and
scale. Only nodes without children whose transform is a rotation and a positive scale
along its own axes (what a façade's parts are on a wall: turned about the vertical,
stretched along the wall and up it) become instances; their placements are kept to
float32, as glTF stores them.

:func:`.glb_merge.instance_nodes` does it to one glb (a building's), and
:func:`.glb_merge.merge_glb` gathers the instances of equal meshes (:func:`mesh_digest`)
across the buildings of a city into one node each.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from typing import Any

import numpy as np

EXTENSION = "EXT_mesh_gpu_instancing"
FLOAT = 5126  # glTF's componentType for float32
MIN_INSTANCES = 2  # a mesh placed fewer times stays a plain node
# a façade's part of fewer triangles (a pane, a window's recess: a box's 12 or fewer) is
# merged with its building: storing it at every placement costs less than a draw call
MIN_TRIANGLES = 13


def node_matrix(node: dict[str, Any]) -> np.ndarray:
    """A node's local transform as a 4x4 matrix (``matrix``, or T x R x S)."""
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=float).reshape(4, 4).T  # column-major
    matrix = np.eye(4)
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    matrix[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    matrix[:3, :3] *= np.asarray(node.get("scale", (1.0, 1.0, 1.0)), dtype=float)
    matrix[:3, 3] = node.get("translation", (0.0, 0.0, 0.0))
    return matrix


def trs(matrix: np.ndarray) -> np.ndarray | None:
    """A transform as (translation, rotation x y z w, scale), 10 numbers; None when it is
    not a rotation times a positive scale along the axes (a shear, a mirror)."""
    linear = matrix[:3, :3]
    scale = np.linalg.norm(linear, axis=0)
    if np.any(scale < 1e-9) or not np.allclose(matrix[3], (0, 0, 0, 1)):
        return None
    rotation = linear / scale
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-6):
        return None
    if np.linalg.det(rotation) < 0:
        return None
    return np.concatenate([matrix[:3, 3], _quaternion(rotation), scale])


def _quaternion(rotation: np.ndarray) -> np.ndarray:
    """A rotation matrix as a unit quaternion (x, y, z, w), w >= 0."""
    (a, b, c), (d, e, f), (g, h, i) = rotation
    trace = a + e + i
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = ((h - f) / s, (c - g) / s, (d - b) / s, 0.25 * s)
    elif a > e and a > i:
        s = 2.0 * np.sqrt(1.0 + a - e - i)
        q = (0.25 * s, (b + d) / s, (c + g) / s, (h - f) / s)
    elif e > i:
        s = 2.0 * np.sqrt(1.0 + e - a - i)
        q = ((b + d) / s, 0.25 * s, (f + h) / s, (c - g) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + i - a - e)
        q = ((c + g) / s, (f + h) / s, 0.25 * s, (d - b) / s)
    found = np.asarray(q, dtype=float)
    found /= np.linalg.norm(found)
    return -found if found[3] < 0 else found


def instancing_nodes(
    document: dict[str, Any],
    binary: bytearray,
    groups: Sequence[tuple[int, np.ndarray]],
    offset: int = 0,
) -> list[int]:
    """Add a node for each (mesh, placements (n, 10) as :func:`trs` gives them) with
    ``EXT_mesh_gpu_instancing``, its accessors' data appended to ``binary``, which starts
    ``offset`` bytes into buffer 0; returns the new nodes' indices."""
    added = []
    for mesh, placements in groups:
        attributes = {}
        for name, columns, kind in (
            ("TRANSLATION", slice(0, 3), "VEC3"),
            ("ROTATION", slice(3, 7), "VEC4"),
            ("SCALE", slice(7, 10), "VEC3"),
        ):
            values = np.ascontiguousarray(placements[:, columns], dtype="<f4")
            binary.extend(b"\0" * (-len(binary) % 4))
            document.setdefault("bufferViews", []).append(
                {"buffer": 0, "byteOffset": offset + len(binary), "byteLength": values.nbytes}
            )
            binary.extend(values.tobytes())
            accessors = document.setdefault("accessors", [])
            accessors.append(
                {
                    "bufferView": len(document["bufferViews"]) - 1,
                    "componentType": FLOAT,
                    "count": len(values),
                    "type": kind,
                }
            )
            attributes[name] = len(accessors) - 1
        extension = {EXTENSION: {"attributes": attributes}}
        document["nodes"].append({"mesh": mesh, "extensions": extension})
        added.append(len(document["nodes"]) - 1)
    if added and EXTENSION not in document.setdefault("extensionsUsed", []):
        document["extensionsUsed"].append(EXTENSION)
    return added


def placements(document: dict[str, Any], chunk: bytes, node: dict[str, Any]) -> np.ndarray:
    """An instanced node's placements, (n, 10) float32 as stored (see :func:`trs`)."""
    attributes = node["extensions"][EXTENSION]["attributes"]
    count = document["accessors"][next(iter(attributes.values()))]["count"]
    columns = []
    for name, default in (
        ("TRANSLATION", (0.0, 0.0, 0.0)),
        ("ROTATION", (0.0, 0.0, 0.0, 1.0)),
        ("SCALE", (1.0, 1.0, 1.0)),
    ):
        if name in attributes:
            columns.append(_read(document, chunk, attributes[name]).reshape(count, len(default)))
        else:
            columns.append(np.tile(np.asarray(default, dtype=np.float32), (count, 1)))
    return np.hstack(columns)


def _read(document: dict[str, Any], chunk: bytes, accessor: int) -> np.ndarray:
    entry = document["accessors"][accessor]
    view = document["bufferViews"][entry["bufferView"]]
    start = view.get("byteOffset", 0) + entry.get("byteOffset", 0)
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[entry["type"]]
    return np.frombuffer(chunk, dtype="<f4", count=entry["count"] * width, offset=start).copy()


def mesh_digest(document: dict[str, Any], chunk: bytes, mesh: int, materials: Sequence[str]) -> str:
    """What makes a mesh itself: each primitive's mode, material (``materials``: the
    document's material -> an identity shared across documents) and accessors, bytes and
    all; equal digests draw the same."""
    digest = hashlib.sha256()
    for primitive in document["meshes"][mesh]["primitives"]:
        used = sorted(primitive["attributes"].items())
        if "indices" in primitive:
            used.append(("indices", primitive["indices"]))
        material = primitive.get("material")
        head = {"mode": primitive.get("mode", 4), "material": None}
        if material is not None:
            head["material"] = materials[material]
        digest.update(json.dumps(head, sort_keys=True).encode())
        for name, index in used:
            entry = document["accessors"][index]
            view = document["bufferViews"][entry["bufferView"]]
            start = view.get("byteOffset", 0)
            shape = {k: entry.get(k) for k in ("componentType", "count", "type", "byteOffset")}
            digest.update(json.dumps([name, shape], sort_keys=True).encode())
            digest.update(chunk[start : start + view["byteLength"]])
    return digest.hexdigest()
