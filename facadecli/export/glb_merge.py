"""Merge .glb files into one without holding them all: a streaming writer.

Each input's binary chunk is appended to a temporary file as it is read; only the JSON
(nodes, meshes, accessors: a few kilobytes a building) stays in memory. The output is
assembled at the end and renamed into place, so a city of any size merges in flat memory.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import struct
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from facadecli.export.atomic import atomic_output

MAGIC = 0x46546C67  # "glTF"
JSON_CHUNK = 0x4E4F534A
BIN_CHUNK = 0x004E4942

# glTF arrays whose entries point at each other, and the fields that point
_REFERENCES = {
    "bufferViews": [],
    "accessors": [("bufferView", "bufferViews")],
    "images": [("bufferView", "bufferViews")],
    "samplers": [],
    "textures": [("source", "images"), ("sampler", "samplers")],
    "materials": [],
    "meshes": [],
    "nodes": [("mesh", "meshes")],
}


def read_glb(data: bytes) -> tuple[dict[str, Any], bytes]:
    magic, _, length = struct.unpack_from("<III", data, 0)
    if magic != MAGIC:
        raise ValueError("not a glb file")
    offset, document, binary = 12, None, b""
    while offset < length:
        size, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8 : offset + 8 + size]
        if kind == JSON_CHUNK:
            document = json.loads(chunk)
        elif kind == BIN_CHUNK:
            binary = chunk
        offset += 8 + size
    if document is None:
        raise ValueError("glb without a JSON chunk")
    return document, binary


def merge_glb(
    parts: Iterable[tuple[str, Path | bytes]], target: Path, extras: dict[str, Any] | None = None
) -> None:
    """Write one glb holding every (name, file or glb bytes) part under a root node of that
    name; with ``extras``, as the scene's ``extras`` (glTF's place for application data)."""
    merged: dict[str, Any] = {key: [] for key in _REFERENCES}
    scene: dict[str, Any] = {"nodes": []}
    if extras is not None:
        scene["extras"] = extras
    merged.update(
        asset={"version": "2.0", "generator": "facadecli"},
        scenes=[scene],
        scene=0,
        extensionsUsed=[],
    )
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, binary_path = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".bin", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as binary:
            known: dict[bytes, int] = {}  # a picture's digest -> its merged image
            seen: dict[str, dict[str, int]] = {}  # shared kinds' entries already merged
            for name, path in parts:
                document, chunk = read_glb(path.read_bytes() if isinstance(path, Path) else path)
                document, chunk = _known_images(document, chunk, known, len(merged["images"]))
                _append(merged, document, name, binary.tell(), seen)
                binary.write(chunk)
                binary.write(b"\0" * (-len(chunk) % 4))
            length = binary.tell()
        _write(merged, binary_path, length, target)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(binary_path)


def _known_images(
    document: dict[str, Any], chunk: bytes, known: dict[bytes, int], first: int
) -> tuple[dict[str, Any], bytes]:
    """The document and its binary chunk without the pictures an earlier part already
    brought (every building of a city built from one spec carries the same library
    textures): its textures point at the merged images instead (``first`` is where this
    part's images will start), and the chunk keeps only the other buffer views."""
    images = document.get("images", [])
    views = document.get("bufferViews", [])
    dropped: set[int] = set()
    sources: list[int] = []  # this part's image -> its merged image, less ``first``
    kept: list[dict[str, Any]] = []
    for image in images:
        view = views[image["bufferView"]] if "bufferView" in image else None
        if view is None:
            sources.append(len(kept))
            kept.append(image)
            continue
        start = view.get("byteOffset", 0)
        digest = hashlib.sha256(chunk[start : start + view["byteLength"]]).digest()
        if digest in known:
            sources.append(known[digest] - first)
            dropped.add(image["bufferView"])
        else:
            known[digest] = first + len(kept)
            sources.append(len(kept))
            kept.append(image)
    if not dropped:
        return document, chunk
    order = [i for i in range(len(views)) if i not in dropped]
    renumbered = {old: new for new, old in enumerate(order)}
    pieces: list[bytes] = []
    offset = 0
    new_views = []
    for old in order:
        view = dict(views[old])
        start = view.get("byteOffset", 0)
        pieces.append(chunk[start : start + view["byteLength"]] + b"\0" * (-view["byteLength"] % 4))
        view["byteOffset"] = offset
        offset += len(pieces[-1])
        new_views.append(view)
    document = dict(document)
    document["bufferViews"] = new_views
    document["accessors"] = [
        {**a, "bufferView": renumbered[a["bufferView"]]} if "bufferView" in a else a
        for a in document.get("accessors", [])
    ]
    document["images"] = [
        {**image, "bufferView": renumbered[image["bufferView"]]} if "bufferView" in image else image
        for image in kept
    ]
    document["textures"] = [
        {**texture, "source": sources[texture["source"]]} if "source" in texture else texture
        for texture in document.get("textures", [])
    ]
    return document, b"".join(pieces)


#: kinds whose equal entries (by content, once their references are renumbered) are
#: stored once: a city's buildings share one material of each kind and its textures
_SHARED = ("samplers", "textures", "materials")


def _append(
    merged: dict[str, Any],
    document: dict[str, Any],
    name: str,
    offset: int,
    seen: dict[str, dict[str, int]],
) -> None:
    """Add a part's entries to the merged document, renumbering their references; a
    sampler, texture or material equal to one already merged (``seen``: its canonical
    JSON -> its index) is not added again, and what pointed at it points at that one."""
    base = {key: len(merged[key]) for key in _REFERENCES}
    where: dict[str, list[int]] = {}  # this part's index -> its merged index, by kind
    for key, links in _REFERENCES.items():
        where[key] = []
        for entry in document.get(key, []):
            entry = dict(entry)
            for field, target in links:
                if field in entry and target == "images":  # may be an earlier part's
                    entry[field] += base["images"]  # (see _known_images)
                elif field in entry:
                    entry[field] = where[target][entry[field]]
            if key == "bufferViews":
                entry["buffer"] = 0
                entry["byteOffset"] = entry.get("byteOffset", 0) + offset
            if key == "nodes" and "children" in entry:
                entry["children"] = [child + base["nodes"] for child in entry["children"]]
            if key == "materials":
                entry = _renumber_textures(entry, where["textures"])
            if key == "meshes":
                entry["primitives"] = [_primitive(p, where) for p in entry["primitives"]]
            if key in _SHARED:
                canonical = json.dumps(entry, sort_keys=True, separators=(",", ":"))
                known = seen.setdefault(key, {})
                if canonical not in known:
                    known[canonical] = len(merged[key])
                    merged[key].append(entry)
                where[key].append(known[canonical])
                continue
            where[key].append(len(merged[key]))
            merged[key].append(entry)
    for extension in document.get("extensionsUsed", []):
        if extension not in merged["extensionsUsed"]:
            merged["extensionsUsed"].append(extension)
    scene = document.get("scenes", [{}])[document.get("scene", 0)]
    roots = [node + base["nodes"] for node in scene.get("nodes", [])]
    merged["nodes"].append({"name": name, "children": roots})
    merged["scenes"][0]["nodes"].append(len(merged["nodes"]) - 1)


def _primitive(primitive: dict[str, Any], where: dict[str, list[int]]) -> dict[str, Any]:
    shifted = dict(primitive)
    accessors = where["accessors"]
    shifted["attributes"] = {k: accessors[v] for k, v in primitive["attributes"].items()}
    if "indices" in primitive:
        shifted["indices"] = accessors[primitive["indices"]]
    if "material" in primitive:
        shifted["material"] = where["materials"][primitive["material"]]
    return shifted


def _renumber_textures(value: Any, textures: list[int]) -> Any:
    """A copy of a material with its texture references (nested ``{"index": i}`` objects)
    pointing at the merged textures."""
    if isinstance(value, dict):
        return {
            key: (
                {**item, "index": textures[item["index"]]}
                if key.endswith("Texture") and isinstance(item, dict) and "index" in item
                else _renumber_textures(item, textures)
            )
            for key, item in value.items()
        }
    if isinstance(value, list):
        return [_renumber_textures(item, textures) for item in value]
    return value


def _write(merged: dict[str, Any], binary_path: str, length: int, target: Path) -> None:
    merged["buffers"] = [{"byteLength": length}]
    for key in list(merged):
        if isinstance(merged[key], list) and not merged[key]:
            del merged[key]
    text = json.dumps(merged, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + (8 + length if length else 0)
    with atomic_output(target) as out, open(binary_path, "rb") as binary:
        out.write(struct.pack("<III", MAGIC, 2, total))
        out.write(struct.pack("<II", len(text), JSON_CHUNK))
        out.write(text)
        if length:
            out.write(struct.pack("<II", length, BIN_CHUNK))
            shutil.copyfileobj(binary, out, 1 << 20)
