"""A run's texture pictures stored once: ``textures/<digest>.png`` in the output folder,
named by a hash of their bytes, and referenced by relative URI from every model of the
run that draws them (glTF ``images[].uri``, USD asset paths).

A city's buildings wear a few library materials, and each material's three pictures
(base colour, normal, occlusion-roughness-metallic) weigh about 1.6 MiB a building when
each glb embeds its own copies; stored once, a town of any size holds each picture once
(docs/textures.md says why this design and what it saves).

**Content addressing.** A picture's file name is the first :data:`DIGEST_HEX` hexadecimal
digits of the SHA-256 of its PNG bytes: the same picture gets the same name on every
run, machine, worker and scheduler, and two pictures never share one, so nothing is
decided by which worker wrote first. A file is written only when its name is missing,
atomically (a temporary file renamed into place): a name that exists holds its whole
picture, whoever wrote it. A model is written after the pictures it names, so a model on
disk never names a missing picture (``--resume`` keeps it only while they are there).
A run ends by removing the pictures none of its models names (:func:`prune`).
"""

from __future__ import annotations

import hashlib
import json
import os
import posixpath
import re
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any
from urllib.parse import unquote

from facadecli.export.atomic import write_atomic
from facadecli.export.glb_merge import glb, packed_views, read_glb, relative_uri, uri_from

FOLDER = "textures"  # in the output folder
DIGEST_HEX = 32  # hexadecimal digits of a picture's SHA-256 in its name (128 bits)
PICTURE = re.compile(rf"[0-9a-f]{{{DIGEST_HEX}}}\.(?:png|jpg)")  # a stored picture's name
MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
JPEG_SIGNATURE = b"\xff\xd8\xff"


def picture_name(data: bytes) -> str:
    """A picture's file name in the store: a hash of its bytes, and its kind's suffix (a
    spec's own texture may be a JPEG, which glTF keeps as it is)."""
    suffix = ".jpg" if data.startswith(JPEG_SIGNATURE) else ".png"
    return hashlib.sha256(data).hexdigest()[:DIGEST_HEX] + suffix


def unpadded(data: bytes) -> bytes:
    """A PNG as encoded, without the zero bytes a glb pads its buffer views with to four
    bytes (so a picture from a glb and the same picture encoded for USD are one file)."""
    if data.startswith(PNG_SIGNATURE):
        end = data.rfind(b"IEND")
        if end >= 0:
            return data[: end + 8]  # the chunk's type and its CRC
    return data


class TextureStore:
    """The pictures of one run, in ``folder`` (the run's ``textures/``)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.written = 0  # pictures this store wrote (the others were there)

    def put(self, data: bytes) -> Path:
        """The picture's file, written unless it is there already."""
        path = self.folder / picture_name(data)
        if not path.is_file():
            self.folder.mkdir(parents=True, exist_ok=True)
            write_atomic(path, data)
            self.written += 1
        return path

    def uri(self, data: bytes, beside: Path) -> str:
        """The picture stored, and its URI relative to the file ``beside`` that names it."""
        return uri_from(beside, self.put(data))


def externalised(data: bytes, store: TextureStore, beside: Path) -> bytes:
    """A glb (to be written at ``beside``) whose embedded pictures are in ``store``
    instead, each image an ``uri`` relative to the glb, its bytes out of the binary
    chunk; a glb without embedded pictures as it was."""
    document, chunk = read_glb(data)
    images = document.get("images", [])
    if not any("bufferView" in image for image in images):
        return data
    views = document.get("bufferViews", [])
    moved: dict[int, str] = {}  # buffer view -> the URI of its picture
    for image in images:
        if "bufferView" in image:
            view = views[image["bufferView"]]
            start = view.get("byteOffset", 0)
            picture = unpadded(chunk[start : start + view["byteLength"]])
            moved[image["bufferView"]] = store.uri(picture, beside)
    document = dict(document)
    document["images"] = [
        {
            **{k: v for k, v in image.items() if k not in ("bufferView", "mimeType")},
            "uri": moved[image["bufferView"]],
        }
        if "bufferView" in image
        else image
        for image in images
    ]
    return _without_views(document, chunk, set(moved))


def embedded(data: bytes, read: Callable[[str], bytes]) -> bytes:
    """A glb whose pictures named by relative URI (``read`` gives a URI's bytes) are in
    its binary chunk instead: a model that stands alone (a page inlines it)."""
    document, chunk = read_glb(data)
    images = document.get("images", [])
    external = [
        i
        for i, image in enumerate(images if isinstance(images, list) else [])
        if relative_uri(image)
    ]
    if not external:
        return data
    document = dict(document)
    views = list(document.get("bufferViews", []))
    binary = bytearray(chunk)
    new_images = [dict(image) for image in images]
    for index in external:
        uri = new_images[index].pop("uri")
        picture = read(uri)
        binary += b"\0" * (-len(binary) % 4)
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(picture)})
        binary += picture
        new_images[index]["bufferView"] = len(views) - 1
        new_images[index]["mimeType"] = MIME.get(posixpath.splitext(uri)[1].lower(), "image/png")
    document["images"] = new_images
    document["bufferViews"] = views
    return glb(document, bytes(binary))


def image_uris(glb_file: Path) -> list[str]:
    """The relative URIs of a glb's pictures, each once (its JSON chunk read, not its
    binary)."""
    with open(glb_file, "rb") as handle:
        header = handle.read(20)
        if len(header) < 20:
            return []
        size = int.from_bytes(header[12:16], "little")
        document = json.loads(handle.read(size))
    uris = (relative_uri(image) for image in document.get("images", []))
    return list(dict.fromkeys(unquote(uri) for uri in uris if uri))


def pictures_missing(glb_file: Path) -> list[Path]:
    """The pictures a glb names by relative URI that are not beside it where it says."""
    return [
        glb_file.parent / uri
        for uri in image_uris(glb_file)
        if not (glb_file.parent / uri).is_file()
    ]


def prune(folder: Path, glbs: Iterable[Path]) -> list[Path]:
    """Remove the pictures of ``folder`` that none of ``glbs`` names (an earlier run's,
    whose buildings changed since: a resumed run leaves the folder a fresh run would);
    returns them. A run's USD stages name the same pictures as its glb files."""
    if not folder.is_dir():
        return []
    named = {
        os.path.normpath(os.path.abspath(glb.parent / uri))
        for glb in glbs
        if glb.is_file()
        for uri in image_uris(glb)
    }
    removed = []
    for entry in sorted(os.scandir(folder), key=lambda entry: entry.name):
        if PICTURE.fullmatch(entry.name) and os.path.abspath(entry.path) not in named:
            os.unlink(entry.path)
            removed.append(Path(entry.path))
    return removed


def _without_views(document: dict[str, Any], chunk: bytes, gone: Iterable[int]) -> bytes:
    """The glb of a document without the buffer views ``gone``, renumbered."""
    views = document.get("bufferViews", [])
    dropped = set(gone)
    order = [i for i in range(len(views)) if i not in dropped]
    renumbered = {old: new for new, old in enumerate(order)}
    new_views, packed = packed_views(views, order, chunk)
    document["bufferViews"] = new_views
    document["accessors"] = [
        {**a, "bufferView": renumbered[a["bufferView"]]} if "bufferView" in a else a
        for a in document.get("accessors", [])
    ]
    if not new_views:
        document.pop("bufferViews")
    if not packed:
        document.pop("buffers", None)
    return glb(document, packed)
