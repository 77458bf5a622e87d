"""Hostile inputs at the spec, asset and grammar-layout doors of ``facade``, generated from a
seed: each ``<door>_case(seed, workdir)`` writes one input under ``workdir`` and returns the
``facade`` arguments (without the program name) that read it.

The builders (``glb``, ``instanced_glb``, ``staggered_rects``, ...) are shared with the
tests of each reproducer (``tests/test_hostile_inputs.py``). Run this module to try many
cases as subprocesses: ``python -m tests.fuzz.spec_doors [cases per door]``.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))

# -- glTF --------------------------------------------------------------------------------


def glb(document: Any, binary: bytes = b"") -> bytes:
    """A binary glTF file of a JSON document and an optional binary chunk."""
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def mesh_document(triangles: int, nodes: list[dict[str, Any]]) -> tuple[dict[str, Any], bytes]:
    """A glTF document with one mesh of ``triangles`` (indexed, all on one triangle) shown by
    ``nodes`` (every node a root of the scene), and its binary chunk."""
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    indices = bytes([0, 1, 2]) * triangles
    indices += b"\0" * (-len(indices) % 4)
    document = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(indices) + len(positions)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 3 * triangles},
            {"buffer": 0, "byteOffset": len(indices), "byteLength": len(positions)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5121, "count": 3 * triangles, "type": "SCALAR"},
            {
                "bufferView": 1,
                "componentType": 5126,
                "count": 3,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 0],
            },
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
        "nodes": nodes,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "scene": 0,
    }
    return document, indices + positions


def instanced_glb(triangles: int, instances: int) -> bytes:
    """One mesh shown by ``instances`` nodes side by side."""
    nodes = [{"mesh": 0, "translation": [i, 0, 0]} for i in range(instances)]
    return glb(*mesh_document(triangles, nodes))


def chain_glb(depth: int) -> bytes:
    """A mesh at the end of a chain of ``depth`` nodes, each the child of the one before."""
    nodes: list[dict[str, Any]] = [
        {"children": [i + 1], "translation": [0.001, 0, 0]} for i in range(depth - 1)
    ]
    nodes.append({"mesh": 0})
    document, binary = mesh_document(1, nodes)
    document["scenes"] = [{"nodes": [0]}]
    return glb(document, binary)


ASSET_SPEC = """\
version: 1
name: assets
canvas: {{width: 4.0, height: 3.0}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1.0, F: 3.0}}
patterns: {{x: "A^+", y: F}}
layers:
  - {{name: wall, x: x, y: y, shapes: [{{match: {{x: A, y: F}}, mesh: {mesh}}}]}}
"""

# -- layouts -----------------------------------------------------------------------------


def staggered_rects(count: int, side: float = 0.5) -> list[tuple[float, float, float, float]]:
    """``count`` squares on a slanted line, each edge a little off the others' edges."""
    return [(i * 1.0001, i * 1.0003, i * 1.0001 + side, i * 1.0003 + side) for i in range(count)]


def layout_json(rects: list[tuple[float, float, float, float]], label: str = "window") -> str:
    entries = [{"label": label, "x0": x0, "y0": y0, "x1": x1, "y1": y1} for x0, y0, x1, y1 in rects]
    return json.dumps(entries)


def cmp_object(top: float, bottom: float, left: float, right: float, label: str) -> str:
    return (
        f"<object><points><x>{top!r}</x><x>{bottom!r}</x><y>{left!r}</y><y>{right!r}</y>"
        f"</points><label>3</label><labelname>{label}</labelname><flag>1</flag></object>"
    )


def layout_cmp(rects: list[tuple[float, float, float, float]], label: str = "window") -> str:
    """The rectangles as a CMP annotation (x down, y across, in 0..1 of the extent)."""
    width = max(r[2] for r in rects)
    height = max(r[3] for r in rects)
    objects = [cmp_object(0.0, 1.0, 0.0, 1.0, "facade")]
    for x0, y0, x1, y1 in rects:
        top, bottom = 1 - y1 / height, 1 - y0 / height
        objects.append(cmp_object(top, bottom, x0 / width, x1 / width, label))
    return "\n".join(objects) + "\n"
