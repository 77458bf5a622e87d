"""Merge .glb files into one without holding them all: a streaming writer.

Each input's binary chunk is appended to a temporary file as it is read, and so are the
entries of the JSON arrays that grow with every part (buffer views, accessors, meshes,
nodes, the scene's nodes: tens of kilobytes a building as Python objects); only what
the parts share (materials, textures, samplers, the distinct images) stays in memory.
The output is assembled at the end and renamed into place, its bytes those of the
whole document dumped at once, so a city of any size merges in flat memory.
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
from typing import Any, BinaryIO
from urllib.parse import quote, unquote

import numpy as np

from facadecli.export.atomic import atomic_output
from facadecli.export.instancing import (
    EXTENSION,
    MIN_INSTANCES,
    instancing_nodes,
    mesh_digest,
    node_matrix,
    placements,
    trs,
)

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


#: the arrays that grow with every part, spooled to disk as they grow (:class:`_Spool`)
_SPOOLED = ("bufferViews", "accessors", "meshes", "nodes")


class _Spool:
    """A JSON array written to a temporary file an entry at a time: its entries' compact
    JSON, comma-separated, as ``json.dumps`` of the whole array would write them."""

    def __init__(self, file: BinaryIO, key: str):
        self.file = file
        self.key = key
        self.count = 0

    def __len__(self) -> int:
        return self.count

    def append(self, entry: Any) -> None:
        if self.count:
            self.file.write(b",")
        self.file.write(json.dumps(entry, separators=(",", ":")).encode("utf-8"))
        self.count += 1

    @property
    def marker(self) -> str:
        """What stands for the array in the document until it is assembled (:func:`_write`)."""
        return f"\0spool:{self.key}\0"


def merge_glb(
    parts: Iterable[tuple[str, Path | bytes]],
    target: Path,
    extras: dict[str, Any] | None = None,
    instanced: bool = False,
) -> None:
    """Write one glb holding every (name, file or glb bytes) part under a root node of that
    name; with ``extras``, as the scene's ``extras`` (glTF's place for application data).

    With ``instanced``, the parts' instanced nodes (``EXT_mesh_gpu_instancing``, as
    :func:`instance_nodes` makes them) are gathered across parts: each mesh stored once
    (equal by content, :func:`.mesh_digest`), drawn by one node with every part's
    instances, under a root node ``instanced``. The arrays that grow with the parts are
    spooled to disk as they grow (:class:`_Spool`)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    with contextlib.ExitStack() as stack:

        def spooled() -> BinaryIO:
            fd, path = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".bin", dir=target.parent)
            stack.callback(_unlink, path)
            return stack.enter_context(os.fdopen(fd, "w+b"))

        binary = spooled()
        merged: dict[str, Any] = {key: [] for key in _REFERENCES}
        merged.update({key: _Spool(spooled(), key) for key in _SPOOLED})
        scene: dict[str, Any] = {"nodes": _Spool(spooled(), "scene")}
        if extras is not None:
            scene["extras"] = extras
        merged.update(
            asset={"version": "2.0", "generator": "facadecli"},
            scenes=[scene],
            scene=0,
            extensionsUsed=[],
        )
        known: dict[bytes, int] = {}  # a picture's digest -> its merged image
        seen: dict[str, dict[str, int]] = {}  # shared kinds' entries already merged
        groups: dict[str, list[Any]] = {}  # a mesh's digest -> [merged mesh, placements]
        for name, path in parts:
            document, chunk = read_glb(path.read_bytes() if isinstance(path, Path) else path)
            if isinstance(path, Path):
                document = _rebased(document, path, target)
            first: dict[str, int] = {}  # new meshes' digests -> their index in the part
            if instanced:
                document, chunk, first = _gather(document, chunk, groups)
            document, chunk = _known_images(document, chunk, known, len(merged["images"]))
            where = _append(merged, document, name, binary.tell(), seen)
            for digest, mesh in first.items():
                groups[digest][0] = where["meshes"][mesh]
            binary.write(chunk)
            binary.write(b"\0" * (-len(chunk) % 4))
        if groups:
            extra = bytearray()
            found = [(mesh, np.vstack(placed)) for mesh, placed in groups.values()]
            added = instancing_nodes(merged, extra, found, binary.tell())
            binary.write(extra)
            merged["nodes"].append({"name": "instanced", "children": added})
            scene["nodes"].append(len(merged["nodes"]) - 1)
            if EXTENSION not in merged["extensionsUsed"]:
                merged["extensionsUsed"].append(EXTENSION)
        _write(merged, binary, binary.tell(), target)


def _rebased(document: dict[str, Any], part: Path, target: Path) -> dict[str, Any]:
    """A part's document with the pictures it names by relative URI (a run's shared
    ``textures/``, texture_store.py) named relative to ``target`` instead."""
    images = document.get("images", [])
    if not any(relative_uri(image) for image in images):
        return document
    moved = []
    for image in images:
        if (uri := relative_uri(image)) is not None:
            image = {**image, "uri": uri_from(target, part.parent / unquote(uri))}
        moved.append(image)
    return {**document, "images": moved}


def uri_from(beside: Path, target: Path) -> str:
    """The URI of the file ``target`` relative to the folder of the file ``beside``
    (posix separators, percent-encoded as URIs are)."""
    relative = os.path.relpath(os.path.abspath(target), os.path.abspath(beside.parent))
    return quote(Path(relative).as_posix())


def relative_uri(image: Any) -> str | None:
    """An image's URI when it names a file by a relative URI (not embedded in the glb, not
    a data URI nor another scheme, not an absolute path), else None."""
    uri = image.get("uri") if isinstance(image, dict) else None
    if isinstance(uri, str) and uri and ":" not in uri and not uri.startswith("/"):
        return uri
    return None


def _unlink(path: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


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
        if view is None:  # a picture beside the model: the same URI is the same picture
            digest = b"uri:" + str(image.get("uri", "")).encode("utf-8")
        else:
            start = view.get("byteOffset", 0)
            digest = hashlib.sha256(chunk[start : start + view["byteLength"]]).digest()
        if digest in known:
            sources.append(known[digest] - first)
            if view is not None:
                dropped.add(image["bufferView"])
        else:
            known[digest] = first + len(kept)
            sources.append(len(kept))
            kept.append(image)
    if len(kept) == len(images):
        return document, chunk
    order = [i for i in range(len(views)) if i not in dropped]
    renumbered = {old: new for new, old in enumerate(order)}
    new_views, packed = packed_views(views, order, chunk)
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
    return document, packed


#: kinds whose equal entries (by content, once their references are renumbered) are
#: stored once: a city's buildings share one material of each kind and its textures
_SHARED = ("samplers", "textures", "materials")


def _append(
    merged: dict[str, Any],
    document: dict[str, Any],
    name: str,
    offset: int,
    seen: dict[str, dict[str, int]],
) -> dict[str, list[int]]:
    """Add a part's entries to the merged document, renumbering their references; a
    sampler, texture or material equal to one already merged (``seen``: its canonical
    JSON -> its index) is not added again, and what pointed at it points at that one.
    Returns where each of the part's entries went, by kind."""
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
            if key == "nodes" and EXTENSION in entry.get("extensions", {}):
                attributes = entry["extensions"][EXTENSION]["attributes"]
                moved = {k: where["accessors"][v] for k, v in attributes.items()}
                entry["extensions"] = {EXTENSION: {"attributes": moved}}
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
    return where


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


def _write(merged: dict[str, Any], binary: BinaryIO, length: int, target: Path) -> None:
    """The glb assembled into ``target``: the JSON chunk with each spooled array copied in
    where its marker stands, then the binary chunk."""
    merged["buffers"] = [{"byteLength": length}]
    spools = [value for value in merged.values() if isinstance(value, _Spool)]
    spools.append(merged["scenes"][0]["nodes"])
    for key in list(merged):
        if isinstance(merged[key], list | _Spool) and not len(merged[key]):
            del merged[key]
    text = json.dumps(merged, separators=(",", ":"), default=lambda spool: spool.marker)
    pieces: list[bytes | _Spool] = []
    for spool in spools:  # in the order they stand in the text
        marker = json.dumps(spool.marker)
        if marker not in text:  # an empty array, left out
            continue
        before, text = text.split(marker, 1)
        pieces += [before.encode("utf-8") + b"[", spool, b"]"]
    pieces.append(text.encode("utf-8"))
    size = sum(len(p) if isinstance(p, bytes) else p.file.tell() for p in pieces)
    padding = b" " * (-size % 4)
    size += len(padding)
    total = 12 + 8 + size + (8 + length if length else 0)
    with atomic_output(target) as out:
        out.write(struct.pack("<III", MAGIC, 2, total))
        out.write(struct.pack("<II", size, JSON_CHUNK))
        for piece in pieces:
            out.write(piece if isinstance(piece, bytes) else b"")
            if isinstance(piece, _Spool):
                _copy(piece.file, out)
        out.write(padding)
        if length:
            out.write(struct.pack("<II", length, BIN_CHUNK))
            _copy(binary, out)


def _copy(spool: BinaryIO, out: BinaryIO) -> None:
    spool.flush()
    spool.seek(0)
    shutil.copyfileobj(spool, out, 1 << 20)


def glb(document: dict[str, Any], binary: bytes) -> bytes:
    """A glb of a document and its binary chunk (buffer 0)."""
    padded = bytes(binary) + b"\0" * (-len(binary) % 4)
    if padded:
        document = {**document, "buffers": [{"byteLength": len(binary)}]}
    text = json.dumps(document, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + (8 + len(padded) if padded else 0)
    pieces = [struct.pack("<III", MAGIC, 2, total), struct.pack("<II", len(text), JSON_CHUNK), text]
    if padded:
        pieces += [struct.pack("<II", len(padded), BIN_CHUNK), padded]
    return b"".join(pieces)


def instance_nodes(data: bytes) -> bytes:
    """A glb whose meshes placed by :data:`.MIN_INSTANCES` or more childless nodes (each a
    rotation and a positive scale, :func:`.trs`) are each one instanced node instead
    (``EXT_mesh_gpu_instancing``), a root of the scene; the rest as it was."""
    document, chunk = read_glb(data)
    nodes = document.get("nodes", [])
    by_mesh: dict[int, list[tuple[int, np.ndarray]]] = {}
    for index, node in enumerate(nodes):
        if "mesh" in node and not node.get("children") and "extensions" not in node:
            found = trs(_world(nodes, index))
            if found is not None:
                by_mesh.setdefault(node["mesh"], []).append((index, found))
    groups = {mesh: found for mesh, found in by_mesh.items() if len(found) >= MIN_INSTANCES}
    if not groups:
        return data
    binary = bytearray(chunk[: document["buffers"][0]["byteLength"]])
    order = sorted(groups)
    added = instancing_nodes(
        document, binary, [(mesh, np.array([p for _, p in groups[mesh]])) for mesh in order]
    )
    scene = document["scenes"][document.get("scene", 0)]
    scene["nodes"] = [*scene.get("nodes", []), *added]
    gone = {index for found in groups.values() for index, _ in found}
    document, binary_out = _without(document, bytes(binary), gone, set())
    return glb(document, binary_out)


def _world(nodes: list[dict[str, Any]], index: int) -> np.ndarray:
    """A node's transform in its scene: its ancestors' and its own."""
    parents = {child: i for i, node in enumerate(nodes) for child in node.get("children", [])}
    matrix = node_matrix(nodes[index])
    while index in parents:
        index = parents[index]
        matrix = node_matrix(nodes[index]) @ matrix
    return matrix


def _gather(
    document: dict[str, Any], chunk: bytes, groups: dict[str, list[Any]]
) -> tuple[dict[str, Any], bytes, dict[str, int]]:
    """Take a part's instanced nodes out of it, their placements (in the part's frame)
    added to ``groups`` by their mesh's digest; a mesh an earlier part brought is dropped
    with its accessors and bytes. Returns the part without them, its chunk, and the
    digests of the meshes first seen here, with their index in the returned part."""
    nodes = document.get("nodes", [])
    identities = _material_identities(document, chunk)
    taken: set[int] = set()
    dropped: set[int] = set()
    first: dict[str, int] = {}
    for index, node in enumerate(nodes):
        if EXTENSION not in node.get("extensions", {}) or node.get("children"):
            continue
        placed = placements(document, chunk, node)
        world = _world(nodes, index)
        if not np.allclose(world, np.eye(4)):
            placed = np.array([trs(world @ _matrix(p)) for p in placed], dtype=np.float32)
        digest = mesh_digest(document, chunk, node["mesh"], identities)
        if digest in groups:
            groups[digest][1].append(placed)
            if digest not in first:
                dropped.add(node["mesh"])
        else:
            groups[digest] = [-1, [placed]]
            first[digest] = node["mesh"]
        taken.add(index)
    document, chunk, meshes = _without(document, chunk, taken, dropped, with_meshes=True)
    return document, chunk, {digest: meshes[mesh] for digest, mesh in first.items()}


def _matrix(placement: np.ndarray) -> np.ndarray:
    t, (x, y, z, w), s = placement[:3], placement[3:7], placement[7:10]
    node = {"translation": list(t), "rotation": [x, y, z, w], "scale": list(s)}
    return node_matrix(node)


def _material_identities(document: dict[str, Any], chunk: bytes) -> list[str]:
    """Each material as text that is the same in any glb for the same look: its textures
    named by their picture's bytes and their sampler instead of their index."""
    textures, images = document.get("textures", []), document.get("images", [])
    views, samplers = document.get("bufferViews", []), document.get("samplers", [])

    def picture(index: int) -> dict[str, Any]:
        texture = textures[index]
        image = images[texture["source"]] if "source" in texture else {}
        key = image.get("uri", "")
        if "bufferView" in image:
            view = views[image["bufferView"]]
            start = view.get("byteOffset", 0)
            key = hashlib.sha256(chunk[start : start + view["byteLength"]]).hexdigest()
        sampler = samplers[texture["sampler"]] if "sampler" in texture else None
        return {"image": key, "sampler": sampler, "extensions": texture.get("extensions")}

    def named(value: Any) -> Any:
        if isinstance(value, dict):
            return {
                key: (
                    {**item, "index": picture(item["index"])}
                    if key.endswith("Texture") and isinstance(item, dict) and "index" in item
                    else named(item)
                )
                for key, item in value.items()
            }
        if isinstance(value, list):
            return [named(item) for item in value]
        return value

    return [json.dumps(named(m), sort_keys=True) for m in document.get("materials", [])]


def _without(
    document: dict[str, Any],
    chunk: bytes,
    nodes_gone: set[int],
    meshes_gone: set[int],
    with_meshes: bool = False,
) -> Any:
    """The document and chunk without the given nodes and meshes (a mesh a remaining node
    draws stays), nor the accessors and bytes only they used; with ``with_meshes``, also
    the old mesh index -> the new."""
    document = dict(document)
    nodes = document.get("nodes", [])
    kept_nodes = [i for i in range(len(nodes)) if i not in nodes_gone]
    node_at = {old: new for new, old in enumerate(kept_nodes)}
    drawn = {nodes[i]["mesh"] for i in kept_nodes if "mesh" in nodes[i]}
    meshes = document.get("meshes", [])
    kept_meshes = [i for i in range(len(meshes)) if i not in meshes_gone or i in drawn]
    mesh_at = {old: new for new, old in enumerate(kept_meshes)}
    used: set[int] = set()  # accessors
    for i in kept_meshes:
        for primitive in meshes[i]["primitives"]:
            used.update(primitive["attributes"].values())
            if "indices" in primitive:
                used.add(primitive["indices"])
    for i in kept_nodes:
        instancing = nodes[i].get("extensions", {}).get(EXTENSION, {})
        used.update(instancing.get("attributes", {}).values())
    accessors = document.get("accessors", [])
    kept_accessors = sorted(used)
    accessor_at = {old: new for new, old in enumerate(kept_accessors)}
    views = document.get("bufferViews", [])
    needed = {accessors[i]["bufferView"] for i in kept_accessors if "bufferView" in accessors[i]}
    needed |= {image["bufferView"] for image in document.get("images", []) if "bufferView" in image}
    kept_views = sorted(needed)
    view_at = {old: new for new, old in enumerate(kept_views)}
    new_views, binary = packed_views(views, kept_views, chunk)
    new_nodes = []
    for i in kept_nodes:
        node = dict(nodes[i])
        if "children" in node:
            node["children"] = [node_at[c] for c in node["children"] if c in node_at]
            if not node["children"]:
                del node["children"]
        if "mesh" in node:
            node["mesh"] = mesh_at[node["mesh"]]
        if EXTENSION in node.get("extensions", {}):
            attributes = node["extensions"][EXTENSION]["attributes"]
            moved = {k: accessor_at[v] for k, v in attributes.items()}
            node["extensions"] = {**node["extensions"], EXTENSION: {"attributes": moved}}
        new_nodes.append(node)
    new_meshes = []
    for i in kept_meshes:
        mesh = dict(meshes[i])
        mesh["primitives"] = [
            {
                **p,
                "attributes": {k: accessor_at[v] for k, v in p["attributes"].items()},
                **({"indices": accessor_at[p["indices"]]} if "indices" in p else {}),
            }
            for p in mesh["primitives"]
        ]
        new_meshes.append(mesh)
    document["nodes"] = new_nodes
    document["meshes"] = new_meshes
    document["accessors"] = [
        {**accessors[i], "bufferView": view_at[accessors[i]["bufferView"]]}
        if "bufferView" in accessors[i]
        else accessors[i]
        for i in kept_accessors
    ]
    document["bufferViews"] = new_views
    document["images"] = [
        {**image, "bufferView": view_at[image["bufferView"]]} if "bufferView" in image else image
        for image in document.get("images", [])
    ]
    scenes = []
    for scene in document.get("scenes", []):
        roots = [node_at[n] for n in scene.get("nodes", []) if n in node_at]
        scenes.append({**scene, "nodes": roots})
    document["scenes"] = scenes
    for key in ("meshes", "accessors", "bufferViews", "images", "nodes"):
        if not document[key]:
            del document[key]
    if not binary:
        document.pop("buffers", None)
    else:
        document["buffers"] = [{"byteLength": len(binary)}]
    return (document, binary, mesh_at) if with_meshes else (document, binary)


def packed_views(
    views: list[dict[str, Any]], order: list[int], chunk: bytes
) -> tuple[list[dict[str, Any]], bytes]:
    """The buffer views ``order`` names, in that order, and their bytes packed one after
    another (each padded to 4 bytes), their offsets moved to match."""
    pieces: list[bytes] = []
    offset = 0
    packed = []
    for old in order:
        view = dict(views[old])
        start = view.get("byteOffset", 0)
        pieces.append(chunk[start : start + view["byteLength"]] + b"\0" * (-view["byteLength"] % 4))
        view["byteOffset"] = offset
        offset += len(pieces[-1])
        packed.append(view)
    return packed, b"".join(pieces)
