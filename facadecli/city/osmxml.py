"""Checking an OSM XML extract (``.osm``, ``.osm.gz``, ``.osm.bz2``) before libosmium reads
it: one streaming pass with expat, inflating a compressed file a chunk at a time.

libosmium stops at the first value it cannot take (a coordinate ``nan``, an id past
int64, a tag value past 1,024 bytes) with a message that names no place, and reads any
number of inflated bytes. This pass holds the file to the limits (inflated bytes, tag
text, ids) and to what libosmium takes: the formats of its values, the elements inside a
node, way or relation, each way once and in libosmium's order. What breaks one is a
SpecError at its line and column, naming the element, with the fix. It also finds where
each element tagged as a building starts, to place the features libosmium cannot draw.
"""

from __future__ import annotations

import bz2
import gzip
import io
import re
import zlib
from array import array
from collections.abc import Callable
from pathlib import Path
from typing import Any
from xml.parsers import expat

from facadecli.city.landcover import COVER_KEYS
from facadecli.errors import SpecError
from facadecli.limits import (
    OSM_ID_MAX,
    OSM_INFLATION_FREE,
    OSM_INFLATION_MAX,
    OSM_TEXT_CHARS_MAX,
    OSM_XML_BYTES_MAX,
)

CHUNK = 1 << 20  # bytes inflated and parsed at a time
HINT = "export the extract again (osmium cat, JOSM, the OSM website), or fix the value"
KEYS = ("building", "building:part")
INSIDE = {  # what libosmium takes inside an element (anything else is an error)
    "node": ("tag",),
    "way": ("nd", "tag"),
    "relation": ("member", "tag"),
    "tag": (),
    "nd": (),
    "member": (),
}
SORT = "sort it: osmium sort FILE -o SORTED.osm"
ELEMENTS = ("node", "way", "relation")


class Places:
    """Where each element tagged as a building starts, (kind, id) -> (line, column): 17
    bytes an element in arrays, not a dict of tuples; looked up by bisection in the
    elements sorted by kind and id (sorted when first looked up, stable: an element
    given twice is found at its first place)."""

    def __init__(self) -> None:
        self.kinds = array("b")  # ELEMENTS' index
        self.ids = array("q")
        self.lines = array("L")
        self.columns = array("L")
        self.order: Any = None  # numpy: the elements' places here, sorted by kind and id

    def __len__(self) -> int:
        return len(self.ids)

    def add(self, kind: str, oid: int, place: tuple[int, int]) -> None:
        """The element's place, unless it is the element added last (its other tag)."""
        code = ELEMENTS.index(kind)
        if self.ids and self.ids[-1] == oid and self.kinds[-1] == code:
            return
        self.kinds.append(code)
        self.ids.append(oid)
        self.lines.append(place[0])
        self.columns.append(place[1])
        self.order = None

    def get(self, kind: str, oid: int) -> tuple[int, int] | None:
        import numpy as np

        if self.order is None:
            kinds = np.frombuffer(self.kinds, dtype=np.int8)
            self.order = np.lexsort((np.frombuffer(self.ids, dtype=np.int64), kinds))
        wanted = (ELEMENTS.index(kind), oid)
        low, high = 0, len(self.order)
        while low < high:  # the first place whose (kind, id) is not below the wanted
            middle = (low + high) // 2
            at = int(self.order[middle])
            if (self.kinds[at], self.ids[at]) < wanted:
                low = middle + 1
            else:
                high = middle
        if low == len(self.order):
            return None
        at = int(self.order[low])
        if (self.kinds[at], self.ids[at]) != wanted:
            return None
        return self.lines[at], self.columns[at]


_ID = re.compile(r"-?\d{1,19}", re.ASCII)
_COUNT = re.compile(r"\d{1,10}", re.ASCII)  # version, changeset: 32-bit
_UID = re.compile(r"-?\d{1,10}", re.ASCII)
_COORDINATE = re.compile(r"-?(?:\d{1,12}(?:\.\d{0,20})?|\.\d{1,20})(?:[eE][-+]?\d{1,2})?", re.ASCII)
_TIMESTAMP = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", re.ASCII)


def xml_opener(path: Path) -> tuple[Callable[[], io.BufferedIOBase], bool]:
    """How to open the file as XML bytes, and whether it is compressed."""
    name = path.name.lower()
    if name.endswith(".gz"):
        return lambda: gzip.open(path, "rb"), True
    if name.endswith(".bz2"):
        return lambda: bz2.open(path, "rb"), True
    return lambda: path.open("rb"), False


def inflated_limit(compressed_bytes: int) -> int:
    """Bytes a compressed extract of this size may inflate to (OSM_INFLATION_MAX times its
    size, at least OSM_INFLATION_FREE, at most OSM_XML_BYTES_MAX)."""
    ratio = max(OSM_INFLATION_FREE, OSM_INFLATION_MAX * compressed_bytes)
    return min(OSM_XML_BYTES_MAX, ratio)


def too_big(file: str, most: int, compressed: bool) -> SpecError:
    if compressed:
        message = (
            f"the extract inflates to more than {most:,} bytes (limits: {OSM_INFLATION_MAX} "
            f"times its compressed size, {OSM_XML_BYTES_MAX:,} bytes of OSM XML)"
        )
    else:
        message = f"the extract is longer than {most:,} bytes (limit of OSM XML)"
    return SpecError.at(
        file,
        None,
        None,
        message,
        "cut the extract to the district (osmium extract --bbox), or give it as .osm.pbf",
    )


def check_xml(path: Path) -> Places:
    """Check the extract (see the module); the places of its building ways and relations."""
    file = str(path)
    opener, compressed = xml_opener(path)
    size = path.stat().st_size
    most = inflated_limit(size) if compressed else OSM_XML_BYTES_MAX
    if not compressed and size > most:
        raise too_big(file, most, compressed)
    parser = expat.ParserCreate()
    checker = _Checker(file, parser)
    parser.StartElementHandler = checker.start
    parser.EndElementHandler = checker.end
    parser.EntityDeclHandler = checker.entity
    inflated = 0
    try:
        with opener() as stream:
            while chunk := stream.read(CHUNK):
                inflated += len(chunk)
                if inflated > most:
                    raise too_big(file, most, compressed)
                parser.Parse(chunk, False)
        parser.Parse(b"", True)
    except expat.ExpatError as error:
        message = f"not OSM XML: {expat.ErrorString(error.code)}"
        raise SpecError.at(file, error.lineno, error.offset + 1, message, HINT) from None
    except (OSError, EOFError, zlib.error, ValueError) as error:  # a bad gz or bz2 stream
        kind = "gzip" if path.name.lower().endswith(".gz") else "bzip2"
        message = f"cannot inflate the {kind} stream: {error}" if compressed else str(error)
        raise SpecError.at(file, None, None, message, "download the extract again") from None
    if not checker.root:
        raise SpecError.at(file, 1, 1, "not OSM XML: no <osm> element", HINT)
    return checker.places


def _placed(kind: str, attributes: dict[str, str]) -> bool:
    """Whether a tag makes its element's place worth keeping: a building's, or a land-cover
    way's or relation's (a warning names its line)."""
    key = attributes.get("k")
    return key in KEYS or (kind != "node" and key in COVER_KEYS)


class _Checker:
    """expat's handlers: each element's attributes checked as it starts."""

    def __init__(self, file: str, parser: expat.XMLParserType):
        self.file = file
        self.parser = parser
        self.root = False
        self.object: tuple[str, int] | None = None  # the node, way or relation open
        self.places = Places()
        self.at = (1, 1)  # where the open object starts
        self.seen: set[tuple[str, int]] = set()  # relations (ways are checked in order)
        self.way: tuple[int, int] | None = None  # the last way's place in libosmium's order
        self.open: list[str] = []  # the elements open, outermost first

    def fail(self, message: str, hint: str = HINT) -> SpecError:
        line, col = self.parser.CurrentLineNumber, self.parser.CurrentColumnNumber + 1
        return SpecError.at(self.file, line, col, message, hint)

    def entity(self, *_: object) -> None:
        raise self.fail("an entity declaration: OSM XML has none", "remove the DOCTYPE")

    def start(self, name: str, attributes: dict[str, str]) -> None:
        if not self.root:
            if name != "osm":
                raise self.fail(f"not OSM XML: the root element is <{name}>, not <osm>")
            self.root = True
            return
        who = self._who(name, attributes)
        parent = self.open[-1] if self.open else "osm"
        self.open.append(name)
        if name not in INSIDE.get(parent, (name,)):
            allowed = " and ".join(f"<{e}>" for e in INSIDE[parent])
            takes = f"only {allowed}" if allowed else "no element"
            raise self.fail(f"{who}: libosmium takes {takes} inside <{parent}>")
        if name == "member" and "type" not in attributes:
            raise self.fail(f"{who}: a member without a type (node, way or relation)")
        for key, value in attributes.items():
            problem = _problem(name, key, value)
            if problem is not None:
                raise self.fail(f"{who}: {problem}")
        if name in ("node", "way", "relation"):
            self.object = (name, int(attributes.get("id", "0")))
            self.at = (self.parser.CurrentLineNumber, self.parser.CurrentColumnNumber + 1)
            self._once(name, who)
        elif name == "tag" and self.object is not None and _placed(self.object[0], attributes):
            self.places.add(*self.object, self.at)

    def _once(self, name: str, who: str) -> None:
        """Each way and relation once, and the ways in the order of their ids, as
        libosmium takes them (it refuses two versions, or ways out of order)."""
        if self.object is None or name == "node":
            return
        oid = self.object[1]
        if name == "way":  # in order (:func:`_order`): a repeat is one too few to be sorted
            if self.way is not None and _order(oid) < self.way:
                message = f"{who} comes after way {_id_of(self.way)}: the extract is not sorted"
                raise self.fail(message, SORT)
            twice, self.way = _order(oid) == self.way, _order(oid)
        else:  # relations: fewer, kept in a set
            twice = self.object in self.seen
            self.seen.add(self.object)
        if twice:
            raise self.fail(
                f"{who} is in the file twice (a history or change file?)",
                "give an extract with one version of each object",
            )

    def end(self, name: str) -> None:
        if self.open:
            self.open.pop()
        if name in ("node", "way", "relation"):
            self.object = None

    def _who(self, name: str, attributes: dict[str, str]) -> str:
        """The element, for a message: 'way 10', 'a tag of way 10', '<bounds>'."""
        if name in ("node", "way", "relation", "changeset"):
            text = attributes.get("id", "")
            plain = text.removeprefix("-").isdigit() and len(text) < 40
            return f"{name} {text if plain else _show(text)}"
        if self.object is not None:
            kind, oid = self.object
            article = "an" if name[0] in "aeiou" else "a"
            return f"{article} <{name}> of {kind} {oid}"
        return f"<{name}>"


def _order(oid: int) -> tuple[int, int]:
    """An id's place in libosmium's order: 0, -1, -2, ..., then 1, 2, ..."""
    return (0, -oid) if oid <= 0 else (1, oid)


def _id_of(order: tuple[int, int]) -> int:
    return order[1] if order[0] else -order[1]


def _an_id(key: str, value: str) -> str | None:
    if _ID.fullmatch(value) and abs(int(value)) <= OSM_ID_MAX:
        return None
    return f"{key} {_show(value)} is not an OSM id (an integer of at most {OSM_ID_MAX:,})"


def _a_count(key: str, value: str) -> str | None:
    if _COUNT.fullmatch(value) and int(value) < 2**32:
        return None
    return f"{key} {_show(value)} is not a count (0 to 4,294,967,295)"


def _a_user(key: str, value: str) -> str | None:
    if _UID.fullmatch(value) and -(2**31) <= int(value) < 2**32:
        return None
    return f"uid {_show(value)} is not a user id"


def _a_time(key: str, value: str) -> str | None:
    if _TIMESTAMP.fullmatch(value):
        return None
    return f"{key} {_show(value)} is not a time (YYYY-MM-DDThh:mm:ssZ)"


def _a_truth(key: str, value: str) -> str | None:
    return None if value in ("true", "false") else f"{key} {_show(value)} is neither true nor false"


def _a_latitude(key: str, value: str) -> str | None:
    if _COORDINATE.fullmatch(value) and abs(float(value)) <= 90:
        return None
    return f"{key} {_show(value)} is not a latitude"


def _a_longitude(key: str, value: str) -> str | None:
    if _COORDINATE.fullmatch(value) and abs(float(value)) <= 180:
        return None
    return f"{key} {_show(value)} is not a longitude"


def _a_text(key: str, value: str) -> str | None:
    if len(value) <= OSM_TEXT_CHARS_MAX:
        return None
    what = {"k": "a tag key", "v": "a tag value", "role": "a role", "user": "a user name"}[key]
    return f"{what} of {len(value):,} characters (limit: {OSM_TEXT_CHARS_MAX}, as in OSM itself)"


Check = Callable[[str, str], "str | None"]
CHECKS: dict[str, Check] = {  # attribute -> why its value is one libosmium or the limits refuse
    "id": _an_id,
    "ref": _an_id,
    "version": _a_count,
    "changeset": _a_count,
    "num_changes": _a_count,
    "comments_count": _a_count,
    "uid": _a_user,
    "timestamp": _a_time,
    "created_at": _a_time,
    "closed_at": _a_time,
    "visible": _a_truth,
    "open": _a_truth,
    **dict.fromkeys(("lat", "minlat", "maxlat", "min_lat", "max_lat"), _a_latitude),
    **dict.fromkeys(("lon", "minlon", "maxlon", "min_lon", "max_lon"), _a_longitude),
    **dict.fromkeys(("k", "v", "role", "user"), _a_text),
}


def _problem(element: str, key: str, value: str) -> str | None:
    """Why an attribute's value is one libosmium (or the limits) refuses, if it is."""
    check = CHECKS.get(key)
    if check is not None:
        return check(key, value)
    if key == "type" and element == "member" and value not in ("node", "way", "relation"):
        return f"member type {_show(value)} is not node, way or relation"
    return None


def _show(value: str, width: int = 40) -> str:
    text = value if len(value) <= width else value[: width - 3] + "..."
    return "'" + text.encode("unicode_escape").decode("ascii") + "'"
