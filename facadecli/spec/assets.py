"""The files a spec names (meshes, textures), checked before anything uses them: readable,
of their kind, finite, not empty, and within the limits of :mod:`facadecli.limits`.

Counts are read from the files' headers first (cheap, no allocation of the geometry), so a
file beyond the limits is refused before it is loaded."""

from __future__ import annotations

import json
import re
import struct
from pathlib import Path
from typing import Any

from facadecli.limits import (
    GLTF_DEPTH_MAX,
    GLTF_NODES_MAX,
    MESH_BYTES_MAX,
    MESH_FACES_MAX,
    TEXTURE_PIXELS_MAX,
    TEXTURE_SIDE_MAX,
)

INSTANCES_CAP = 2**62  # copies of one node counted (a shared subtree can double at each level)


def mesh_problem(path: Path) -> str | None:
    """What is wrong with a mesh file, or None."""
    size = path.stat().st_size
    if size == 0:
        return "is empty"
    if size > MESH_BYTES_MAX:
        return f"is {size:,} bytes, more than a mesh file may be ({MESH_BYTES_MAX:,})"
    data = path.read_bytes()
    suffix = path.suffix.lower()
    counted = _declared_faces(suffix, data, path.parent)
    if isinstance(counted, str):
        return counted
    if counted is not None and counted > MESH_FACES_MAX:
        instanced = " (each instance in its scene counted)" if suffix in (".glb", ".gltf") else ""
        return (
            f"has {counted:,} triangles{instanced}, more than the limit of triangles of one "
            f"mesh file ({MESH_FACES_MAX:,})"
        )
    import numpy as np

    try:
        mesh = load_mesh(path, data)
    except Exception as error:  # a file trimesh cannot read, whatever the reason
        return f"cannot be read as a mesh ({type(error).__name__}: {error})"
    faces = getattr(mesh, "faces", None)
    vertices = getattr(mesh, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0:
        return "holds no triangles"
    if len(faces) > MESH_FACES_MAX:
        return (
            f"has {len(faces):,} triangles, more than the limit of triangles of one mesh "
            f"file ({MESH_FACES_MAX:,})"
        )
    if not np.isfinite(vertices).all():
        return "has vertices that are not finite numbers (NaN or infinity)"
    return None


def load_mesh(path: Path, data: bytes | None = None) -> Any:
    """The mesh in a file (its scenes flattened), as trimesh reads it, from its bytes: the
    file names no other file trimesh would read (an OBJ's ``mtllib``, its textures), except
    a .gltf's buffers and images, which ``mesh_problem`` checks first."""
    import io
    import warnings

    import numpy as np
    import trimesh  # only for specs that name mesh files

    # a node transform of 1e308 makes infinities: refused by the caller, not warned of here
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        if path.suffix.lower() == ".gltf":
            return trimesh.load(path, force="mesh")
        data = path.read_bytes() if data is None else data
        return trimesh.load(io.BytesIO(data), file_type=path.suffix.lower()[1:], force="mesh")


def _declared_faces(suffix: str, data: bytes, folder: Path) -> int | str | None:
    """The triangle count a mesh file's header declares (None when it does not say), or
    what is wrong with the header."""
    if suffix == ".obj":
        if re.search(rb"(?mi)^[ \t]*v[ \t][^\n]*\b(nan|inf)", data):
            return "has vertices that are not finite numbers (NaN or infinity)"
        return len(re.findall(rb"(?m)^[ \t]*f[ \t]", data))
    if suffix == ".stl":
        if data[:5].lower() == b"solid" and b"facet" in data[:1024]:
            return data.count(b"facet normal")
        if len(data) < 84:
            return "is too short to be an STL file"
        (count,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * count != len(data):
            return f"declares {count:,} triangles but holds {(len(data) - 84) // 50:,}"
        return int(count)
    if suffix == ".ply":
        found = re.search(rb"element face (\d+)", data[:4096])
        return int(found.group(1)) if found else "has no 'element face' in its header"
    if suffix in (".glb", ".gltf"):
        return _gltf_faces(suffix, data, folder)
    return None


def _gltf_faces(suffix: str, data: bytes, folder: Path) -> int | str:
    if suffix == ".glb":
        if len(data) < 20 or data[:4] != b"glTF":
            return "is not a binary glTF file (no 'glTF' header)"
        length, chunk_length, chunk_type = struct.unpack_from("<I I I", data, 8)
        if length != len(data) or chunk_type != 0x4E4F534A or 20 + chunk_length > len(data):
            return "has a glTF header that does not match its length"
        text = data[20 : 20 + chunk_length]
    else:
        text = data
    try:
        document = json.loads(text)
        accessors = document.get("accessors", [])
        mesh_faces = []
        for mesh in document.get("meshes", []):
            faces = 0
            for primitive in mesh.get("primitives", []):
                if "indices" in primitive:
                    accessor = primitive["indices"]
                else:
                    accessor = primitive["attributes"]["POSITION"]
                faces += int(accessors[_index(accessor, len(accessors))]["count"]) // 3
            mesh_faces.append(faces)
        outside = _files_problem(document, suffix, folder)
        return outside if outside is not None else _instanced_faces(document, mesh_faces)
    except (ValueError, KeyError, IndexError, TypeError, AttributeError, RecursionError):
        return "has a glTF JSON part that is not valid glTF"


def _files_problem(document: dict[str, Any], suffix: str, folder: Path) -> str | None:
    """What is wrong with the files a glTF names for its buffers and images, or None: a
    .glb holds its own (a ``data:`` URI at most); a .gltf's are regular files next to it,
    inside its folder (no link out of it), each within ``MESH_BYTES_MAX``."""
    for kind in ("buffers", "images"):
        for item in document.get(kind, []):
            uri = item.get("uri")
            if uri is None or (isinstance(uri, str) and uri.startswith("data:")):
                continue
            if not isinstance(uri, str):
                raise TypeError("uri")
            if suffix == ".glb":
                return f"names a file for its {kind} ('{uri[:80]}'): a .glb holds its own"
            base = folder.resolve()
            named = (base / uri).resolve()
            if ":" in uri or not named.is_relative_to(base) or not named.is_file():
                return f"names '{uri[:80]}' for its {kind}: not a file in its folder"
            if named.stat().st_size > MESH_BYTES_MAX:
                return f"names '{uri[:80]}' for its {kind}, larger than {MESH_BYTES_MAX:,} bytes"
    return None


def _instanced_faces(document: dict[str, Any], mesh_faces: list[int]) -> int | str:
    """Triangles of the glTF's meshes as its scenes place them: a mesh counts once for every
    path from a scene to a node that shows it (loading flattens the scenes, so 400 nodes
    showing one mesh hold 400 copies of it). The node graph is read first, bounded by
    ``GLTF_NODES_MAX`` nodes and ``GLTF_DEPTH_MAX`` levels, and must have no cycle."""
    nodes = document.get("nodes", [])
    if not isinstance(nodes, list):
        raise TypeError("nodes")
    if len(nodes) > GLTF_NODES_MAX:
        return (
            f"has {len(nodes):,} nodes, more than the limit of nodes of one mesh file "
            f"({GLTF_NODES_MAX:,})"
        )
    children: list[list[int]] = []
    for node in nodes:
        kids = node.get("children", [])
        children.append([_index(kid, len(nodes)) for kid in kids])
    roots = [
        _index(root, len(nodes))
        for scene in document.get("scenes", [])
        for root in scene.get("nodes", [])
    ]
    parents = [0] * len(nodes)
    for kids in children:
        for kid in kids:
            parents[kid] += 1
    if not roots:  # no scene: the nodes no other node holds
        roots = [index for index, count in enumerate(parents) if count == 0]
    # Kahn's order: parents before children; a node never reached is on a cycle
    instances = [0] * len(nodes)
    depth = [1] * len(nodes)
    for root in roots:
        instances[root] += 1
    waiting = list(parents)
    ready = [index for index, count in enumerate(waiting) if count == 0]
    ordered = 0
    while ready:
        index = ready.pop()
        ordered += 1
        for kid in children[index]:
            instances[kid] = min(instances[kid] + instances[index], INSTANCES_CAP)
            depth[kid] = max(depth[kid], depth[index] + 1)
            waiting[kid] -= 1
            if waiting[kid] == 0:
                ready.append(kid)
    if ordered < len(nodes):
        return "has a node graph with a cycle (a node is its own ancestor), which glTF forbids"
    deepest = max(depth, default=0)
    if deepest > GLTF_DEPTH_MAX:
        return (
            f"nests its nodes {deepest:,} levels deep, more than the limit of node depth "
            f"of one mesh file ({GLTF_DEPTH_MAX})"
        )
    total = 0
    for index, node in enumerate(nodes):
        mesh = node.get("mesh")
        if mesh is not None:
            total += instances[index] * mesh_faces[_index(mesh, len(mesh_faces))]
    return max(total, sum(mesh_faces))


def _index(value: object, length: int) -> int:
    """``value`` as an index into a glTF array of ``length`` items (a ValueError if not)."""
    if type(value) is not int or not 0 <= value < length:
        raise ValueError(f"{value!r} is not an index")
    return value


def texture_problem(path: Path) -> str | None:
    """What is wrong with a texture image, or None."""
    import warnings

    from PIL import Image, UnidentifiedImageError

    if path.stat().st_size == 0:
        return "is empty"
    try:
        with warnings.catch_warnings():  # the size is checked here, against our own limit
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(path)
        with image:
            width, height = image.size
            if max(width, height) > TEXTURE_SIDE_MAX or width * height > TEXTURE_PIXELS_MAX:
                return (
                    f"is {width:,} x {height:,} pixels, more than a texture may be "
                    f"({TEXTURE_SIDE_MAX:,} a side, {TEXTURE_PIXELS_MAX:,} in all)"
                )
            image.load()  # the pixels, within the limit: a truncated or corrupt file fails
    except UnidentifiedImageError:
        return "is not a PNG or JPEG image"
    except (OSError, ValueError, SyntaxError, Image.DecompressionBombError) as error:
        return f"cannot be read as an image ({error})"
    return None
