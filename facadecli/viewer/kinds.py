"""Whether a file is what its name says, before a page inlines it: a ``.glb`` is glTF 2.0
binary with a JSON chunk that parses, an ``.svg`` is XML whose root is ``<svg>`` with no
document type (so no entity of any kind, inside or outside), a ``.png`` starts with the
PNG signature, a ``.geojson`` is a JSON FeatureCollection. Each check returns why the
bytes are not of their kind, or None."""

from __future__ import annotations

import json
import struct
from collections.abc import Callable
from xml.parsers import expat

GLB_MAGIC = b"glTF"
GLB_JSON = 0x4E4F534A  # the first chunk's type, "JSON"
GLB_BIN = 0x004E4942  # "BIN\0"
SVG_NAMESPACE = "http://www.w3.org/2000/svg"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def glb_problem(data: bytes) -> str | None:
    """Why ``data`` is not a glTF 2.0 binary, or None: the 12-byte header (magic, version
    2, the file's length), chunks that fit the file, the first one JSON: an object whose
    ``asset.version`` is 2.x."""
    if len(data) < 20 or data[:4] != GLB_MAGIC:
        return "not a glTF binary (it does not start with 'glTF')"
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2:
        return f"glTF binary version {version}, not 2"
    if length != len(data):
        return f"its header says {length:,} bytes, the file holds {len(data):,}"
    at, types = 12, []
    while at < length:
        if length - at < 8:
            return f"a chunk header cut short at byte {at:,}"
        size, kind = struct.unpack_from("<II", data, at)
        if size > length - at - 8:
            return f"a chunk of {size:,} bytes at byte {at:,} runs past the end of the file"
        types.append((kind, at + 8, size))
        at += 8 + size
    if not types or types[0][0] != GLB_JSON:
        return "its first chunk is not JSON"
    if any(kind != GLB_BIN for kind, _, _ in types[1:2]):
        return "its second chunk is not the binary buffer"
    _, start, size = types[0]
    try:
        document = json.loads(data[start : start + size].decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return "its JSON chunk is not JSON"
    asset = document.get("asset") if isinstance(document, dict) else None
    version_text = asset.get("version") if isinstance(asset, dict) else None
    if not isinstance(version_text, str) or not version_text.startswith("2."):
        return "its JSON chunk has no glTF 2 'asset.version'"
    return None


class _Refused(Exception):
    pass


def svg_problem(data: bytes) -> str | None:
    """Why ``data`` is not an SVG document, or None: well-formed XML, no document type
    declaration (a DTD is where entities, inside or outside, come from), its root ``svg``
    in the SVG namespace."""
    parser = expat.ParserCreate(namespace_separator=" ")
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    roots: list[str] = []

    def refuse(*_: object) -> None:
        raise _Refused

    def start(name: str, _attributes: object) -> None:
        if not roots:
            roots.append(name)

    parser.StartDoctypeDeclHandler = refuse
    parser.EntityDeclHandler = refuse
    parser.ExternalEntityRefHandler = refuse  # type: ignore[assignment]
    parser.StartElementHandler = start
    try:
        parser.Parse(data, True)
    except _Refused:
        return "it declares a document type (DTD): an SVG page inlines none"
    except expat.ExpatError as error:
        return f"not XML: {expat.ErrorString(error.code)} at line {error.lineno}"
    except RecursionError:
        return "not XML: nested too deep"
    if roots != [f"{SVG_NAMESPACE} svg"]:
        return "its root element is not <svg> in the SVG namespace"
    return None


def png_problem(data: bytes) -> str | None:
    """Why ``data`` is not a PNG image, or None (its 8-byte signature)."""
    return None if data.startswith(PNG_SIGNATURE) else "not a PNG image (no PNG signature)"


def geojson_problem(data: bytes) -> str | None:
    """Why ``data`` is not a GeoJSON FeatureCollection (a city's land cover), or None."""
    try:
        document = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return "not JSON"
    if not isinstance(document, dict) or document.get("type") != "FeatureCollection":
        return "not a GeoJSON FeatureCollection"
    return None


CHECKS: dict[str, Callable[[bytes], str | None]] = {
    ".glb": glb_problem,
    ".svg": svg_problem,
    ".png": png_problem,
    ".geojson": geojson_problem,
}


def kind_problem(suffix: str, data: bytes) -> str | None:
    """Why a file named ``*suffix`` holding ``data`` is not of that kind, or None."""
    check = CHECKS.get(suffix.lower())
    return "not a kind of file a page shows" if check is None else check(data)
