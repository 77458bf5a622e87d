"""A glb's triangles as a viewer places them, GPU instances (``EXT_mesh_gpu_instancing``)
included: read apart from the code that writes them (trimesh's transformations)."""

from __future__ import annotations

from collections import defaultdict
from typing import Any

import numpy as np
import trimesh

from facadecli.export.glb_merge import read_glb

WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
TYPES = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}


def _read(document: dict[str, Any], chunk: bytes, index: int) -> np.ndarray:
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    width = WIDTH[accessor["type"]]
    found = np.frombuffer(
        chunk, dtype=TYPES[accessor["componentType"]], count=accessor["count"] * width, offset=start
    )
    return found.reshape(accessor["count"], width) if width > 1 else found


def _local(node: dict[str, Any]) -> np.ndarray:
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=float).reshape(4, 4).T
    x, y, z, w = node.get("rotation", (0, 0, 0, 1))
    matrix = trimesh.transformations.quaternion_matrix((w, x, y, z))
    matrix[:3, :3] = matrix[:3, :3] @ np.diag(node.get("scale", (1, 1, 1)))
    matrix[:3, 3] = node.get("translation", (0, 0, 0))
    return matrix


def placed_triangles(data: bytes) -> dict[str, np.ndarray]:
    """The scene's triangles in the world, (n, 3, 3), by material name."""
    document, chunk = read_glb(data)
    nodes = document.get("nodes", [])
    found: dict[str, list[np.ndarray]] = defaultdict(list)

    def visit(index: int, parent: np.ndarray) -> None:
        node = nodes[index]
        world = parent @ _local(node)
        if "mesh" in node:
            instances = [np.eye(4)]
            extension = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
            if extension:
                columns = extension["attributes"]
                t = _read(document, chunk, columns["TRANSLATION"])
                r = _read(document, chunk, columns["ROTATION"])
                s = _read(document, chunk, columns["SCALE"])
                instances = [
                    _local({"translation": a, "rotation": b, "scale": c})
                    for a, b, c in zip(t, r, s, strict=True)
                ]
            for primitive in document["meshes"][node["mesh"]]["primitives"]:
                points = _read(document, chunk, primitive["attributes"]["POSITION"]).astype(float)
                corners = points[_read(document, chunk, primitive["indices"]).astype(np.int64)]
                corners = np.hstack([corners, np.ones((len(corners), 1))])
                material = primitive.get("material")
                name = "" if material is None else document["materials"][material].get("name", "")
                for instance in instances:
                    moved = corners @ (world @ instance).T
                    found[name].append(moved[:, :3].reshape(-1, 3, 3))
        for child in node.get("children", []):
            visit(child, world)

    scene = document["scenes"][document.get("scene", 0)]
    for root in scene["nodes"]:
        visit(root, np.eye(4))
    return {name: np.concatenate(parts) for name, parts in found.items()}
