"""CityJSON 2.0 of a city's buildings: LOD2.2 solids with semantic surfaces.

Each building becomes a ``Building`` CityObject (with ``BuildingPart`` children when it has
several volumes; an outline drawn with ``building:part`` features is one ``Building`` with
its tags, its parts its ``BuildingPart`` children: :func:`grouped`), each volume one
closed ``Solid`` whose surfaces face outwards: a
GroundSurface at its base (an OuterCeilingSurface when the base is above the ground, as
under a part lifted by ``min_height``), a WallSurface per footprint edge (base to eaves),
WallSurfaces for the roof's infill (gable ends, at party walls too: the roof stands
still at the volume's ``still`` walls, as the glb's does), and RoofSurfaces (the roof's coplanar
triangles merged into polygons; a flat roof is the footprint at the eaves, without the
parapet the glb's walls carry).

Vertices are integer millimetres: ``transform`` scales by 0.001 and translates by the run's
origin, so a footprint's local metres (relative to that origin) become vertices directly.
A building is first a CityJSONFeature (its CityObjects and its own vertices, indices from
0), which a worker can make and keep on its own; features are then merged, each one's
indices offset by the vertices before it: in memory (:func:`cityjson_document`) or
streamed to a file one at a time (:class:`CityJSONWriter`), both in linear time and to the
same bytes. Key order is fixed by construction, so the same input gives the same bytes.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
import os
import shutil
import tempfile
from array import array
from collections import Counter, deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, BinaryIO

import numpy as np
import shapely
import trimesh
from shapely.geometry.polygon import orient

from facadecli.city.footprints import Footprint, typed
from facadecli.city.georef import reference_system
from facadecli.city.roofs import roof_meshes
from facadecli.city.s3db import POST, Post, Volume, outline_of, roof_outlines
from facadecli.export.atomic import atomic_output, write_atomic

VERSION = "2.0"
LOD = "2.2"
UNITS = 1000  # vertex units a metre: millimetres
SCALE = 1 / UNITS
NEAR = 1.0  # squared vertex units: a vertex this close to an edge lies on it (T-junction)
APART = 4.0  # squared vertex units: ... unless this close to an end (a sliver's corner)
SNAP = (3, 10, 30)  # vertex units: a roof's point this near a point of its volume is that
# point (the first; the others when the shell does not close without its slivers)
COPLANAR = 1e-10  # 1 - cos of the angle between normals of triangles merged into a polygon
SURFACE_TYPES = (
    "GroundSurface",
    "OuterCeilingSurface",
    "WallSurface",
    "RoofSurface",
    "ClosureSurface",  # a podium's top under the tower standing on it
)

Ring = list[int]  # vertex indices, not closed
Surface = list[Ring]  # the exterior ring, then the holes
Point = tuple[int, int, int]


@dataclass(frozen=True)
class BuildingSolids:
    """A building's input: its id, its volumes, and JSON-safe attributes (height, roof type,
    status, OSM tags, ...), written as they are (keys sorted)."""

    id: str
    volumes: Sequence[Volume]
    attributes: dict[str, Any] = field(default_factory=dict)


def building_object(building: BuildingSolids) -> dict[str, Any]:
    """The building as a CityJSONFeature: ``{"type": "CityJSONFeature", "id",
    "CityObjects", "vertices"}``, vertex indices into its own integer vertices (mm from the
    run's origin). One volume: a ``Building`` with the solid. Several: a ``Building``
    holding the attributes, with a ``BuildingPart`` child ``<id>-part<n>`` per volume (its
    attributes: roofType, minHeight, eavesHeight and measuredHeight, the top's height above
    the ground). A volume whose surfaces do not close into a shell (a roof shape this
    module cannot stitch) is written as a MultiSurface with the same semantics."""
    if not building.volumes:
        raise ValueError(f"building '{building.id}' has no volume")
    vertices = _Vertices()
    geometries = [_geometry(volume, vertices) for volume in building.volumes]
    attributes = dict(sorted(_json_safe(dict(building.attributes)).items()))
    objects: dict[str, Any] = {}
    posts: dict[str, dict[str, Any]] = {}  # a volume's owner -> its posts' object
    if len(geometries) == 1:
        owners = [building.id]
    else:
        owners = [f"{building.id}-part{n}" for n in range(1, len(geometries) + 1)]
    for owner, volume in zip(owners, building.volumes, strict=True):
        if volume.posts:
            posts[owner] = _object(
                "BuildingInstallation",
                {"function": "posts"},
                geometry=_posts(volume.posts, vertices),
                parents=[owner],
            )
    if len(geometries) == 1:
        own = [f"{building.id}-posts"] if posts else []
        objects[building.id] = _object(
            "Building", attributes, geometry=geometries[0], **_children(own)
        )
    else:
        objects[building.id] = _object("Building", attributes, children=owners)
        for child, volume, geometry in zip(owners, building.volumes, geometries, strict=True):
            objects[child] = _object(
                "BuildingPart",
                _part_attributes(volume, geometry, vertices.points),
                geometry=geometry,
                parents=[building.id],
                **_children([f"{child}-posts"] if child in posts else []),
            )
    for owner, installation in posts.items():
        objects[f"{owner}-posts"] = installation
    return {
        "type": "CityJSONFeature",
        "id": building.id,
        "CityObjects": objects,
        "vertices": [list(p) for p in vertices.points],
    }


@dataclass(frozen=True)
class Outline:
    """A building drawn as an outline with ``building:part`` features inside: its id, its
    attributes (its tags: name, address, ...) and the ids of the features written for
    it, in the order they come (what is built of the outline itself, under its own id,
    and its parts)."""

    id: str
    attributes: dict[str, Any]
    members: tuple[str, ...]


def building_with_parts(outline: Outline, features: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """One CityJSONFeature for an outline and the features (:func:`building_object`) of
    its members: a ``Building`` with the outline's id and attributes (``measuredHeight``
    the top of its tallest member), whose ``children`` are
    each part's building, now a ``BuildingPart`` with the outline as its parent (a
    part's own parts stay its children). What is built of the outline itself (its
    feature has the outline's id) stays the Building's geometry. Vertices shared by
    two members are written once."""
    vertices = _Vertices()
    moved: list[dict[str, dict[str, Any]]] = []
    for feature in features:
        table = [vertices.add((int(x), int(y), int(z))) for x, y, z in feature["vertices"]]
        moved.append(
            {key: _renumbered(value, table) for key, value in feature["CityObjects"].items()}
        )
    own = next((m for f, m in zip(features, moved, strict=True) if f["id"] == outline.id), None)
    head: dict[str, Any] = dict(own[outline.id]) if own is not None else {"type": "Building"}
    attributes = dict(head.get("attributes", {}))
    if own is None:
        attributes = dict(sorted(_json_safe(dict(outline.attributes)).items()))
    children = list(head.get("children", []))
    objects: dict[str, Any] = {}
    parts: dict[str, Any] = {}
    for feature, objects_of in zip(features, moved, strict=True):
        for key, value in objects_of.items():
            if key == outline.id:
                continue
            if key == feature["id"]:  # a part's building: a part of the outline's
                value = {**value, "type": "BuildingPart", "parents": [outline.id]}
                children.append(key)
            parts[key] = _ordered(value)
    tops = [
        parts[key]["attributes"]["measuredHeight"]
        for key in children
        if isinstance(parts.get(key, {}).get("attributes", {}).get("measuredHeight"), (int, float))
    ]
    own_top = attributes.get("measuredHeight")
    if isinstance(own_top, (int, float)) and not isinstance(own_top, bool):
        tops.append(own_top)
    if tops:
        attributes = dict(sorted({**attributes, "measuredHeight": max(tops)}.items()))
    objects[outline.id] = _ordered({**head, "attributes": attributes, "children": children})
    objects.update(parts)
    return {
        "type": "CityJSONFeature",
        "id": outline.id,
        "CityObjects": objects,
        "vertices": [list(p) for p in vertices.points],
    }


def outlines(
    footprints: Iterable[Footprint], replaced: dict[str, list[str]], written: Iterable[str]
) -> list[Outline]:
    """The outlines with parts (``replaced``: outline id -> its parts' ids, a part in
    several outlines belonging to the first by id) of which a part is among the
    features ``written`` (ids, in their order, taken as they come: only the places of
    outlines and parts are kept): their typed tags, and their members in that order."""
    parent = outline_of(replaced)
    order = {key: index for index, key in enumerate(written) if key in parent or key in replaced}
    by_id = {footprint.id: footprint for footprint in footprints}
    found = []
    for key in sorted(replaced):
        parts = [p for p in replaced[key] if p in order and parent[p] == key]
        if not parts or key not in by_id:
            continue
        members = sorted([key, *parts] if key in order else parts, key=order.__getitem__)
        found.append(Outline(key, typed(by_id[key].properties), tuple(members)))
    return found


def grouped(
    features: Iterable[dict[str, Any]], outlines: Sequence[Outline]
) -> Iterator[dict[str, Any]]:
    """The features, those of an outline's members merged into one
    (:func:`building_with_parts`), which comes where its last member came; the others as
    they are. Only the members of outlines not yet complete are held."""
    owner = {member: outline for outline in outlines for member in outline.members}
    held: dict[str, list[dict[str, Any]]] = {}
    for feature in features:
        outline = owner.get(feature["id"])
        if outline is None:
            yield feature
            continue
        members = held.setdefault(outline.id, [])
        members.append(feature)
        if len(members) == len(outline.members):
            yield building_with_parts(outline, members)
            del held[outline.id]
    for key, members in held.items():  # members that never came: what there is
        outline = next(o for o in outlines if o.id == key)
        yield building_with_parts(outline, members)


def _renumbered(value: dict[str, Any], table: list[int]) -> dict[str, Any]:
    """A CityObject with its geometries' vertex indices looked up in ``table``."""
    if "geometry" not in value:
        return value
    return {
        **value,
        "geometry": [
            {**g, "boundaries": _lookup(g["boundaries"], table)} for g in value["geometry"]
        ],
    }


def _lookup(boundaries: Any, table: list[int]) -> Any:
    if isinstance(boundaries, list):
        return [_lookup(item, table) for item in boundaries]
    return table[boundaries]


def _ordered(value: dict[str, Any]) -> dict[str, Any]:
    """A CityObject's members in the order :func:`_object` writes them."""
    order = ("type", "attributes", "children", "geometry", "parents")
    return {key: value[key] for key in order if key in value and value[key] not in ([], {})}


def cityjson_header(crs: str, origin: tuple[float, float], name: str) -> dict[str, Any]:
    """The document without CityObjects nor vertices: type, version, transform (0.001,
    translated to ``origin``), metadata (title; referenceSystem, see
    :func:`reference_system`)."""
    metadata: dict[str, Any] = {}
    system = reference_system(crs)
    if system is not None:
        metadata["referenceSystem"] = system
    metadata["title"] = name
    return {
        "type": "CityJSON",
        "version": VERSION,
        "transform": {
            "scale": [SCALE, SCALE, SCALE],
            "translate": [float(origin[0]), float(origin[1]), 0.0],
        },
        "metadata": metadata,
    }


def cityjson_document(
    buildings: Iterable[BuildingSolids], crs: str, origin: tuple[float, float], name: str
) -> dict[str, Any]:
    """The CityJSON 2.0 document of ``buildings``, in their order (see
    :func:`cityjson_header` for the metadata; the geographicalExtent is the vertices').
    Raises ValueError for two CityObjects with one id."""
    objects: dict[str, Any] = {}
    vertices: list[list[int]] = []
    extent = _Extent()
    for building in buildings:
        feature = building_object(building)
        offset = len(vertices)
        for key, value in feature["CityObjects"].items():
            if key in objects:
                raise ValueError(f"two CityObjects with the id '{key}'")
            objects[key] = _shifted(value, offset)
        vertices.extend(feature["vertices"])
        extent.add(feature["vertices"])
    document = cityjson_header(crs, origin, name)
    document["metadata"] = extent.metadata(document)
    document["CityObjects"] = objects
    document["vertices"] = vertices
    return document


def cityjson_bytes(document: dict[str, Any]) -> bytes:
    """Compact JSON (ASCII, no NaN) of a document or a feature, in its keys' order."""
    return json.dumps(document, separators=(",", ":"), allow_nan=False).encode("ascii")


def write_cityjson(path: str | Path, document: dict[str, Any]) -> None:
    """Write a document, or a feature, as compact JSON on one line, atomically. A feature's
    file is then a line of a CityJSON Text Sequence (CityJSONL) too."""
    write_atomic(path, cityjson_bytes(document) + b"\n")


class CityJSONWriter:
    """The document written a feature (:func:`building_object`) at a time, in flat memory:
    CityObjects and vertices go to temporary files beside ``path`` as they come, and the
    document is assembled into ``path`` (atomically) when the block ends without an error.
    Its bytes are those of :func:`cityjson_document` for the same buildings in the same
    order, so add the features in a fixed order (the manifest's)::

        with CityJSONWriter(path, crs, origin, name) as writer:
            for feature in features:
                writer.add(feature)
    """

    def __init__(self, path: str | Path, crs: str, origin: tuple[float, float], name: str):
        self.path = Path(path)
        self.header = cityjson_header(crs, origin, name)
        self._objects_written = 0
        self._count = 0
        self._extent = _Extent()
        self._stack = contextlib.ExitStack()
        try:
            self._objects = self._spool(".objects")
            self._vertices = self._spool(".vertices")
            self._ids = Ids(self._spool(".ids"))
        except BaseException:
            self._stack.close()
            raise

    def _spool(self, suffix: str) -> BinaryIO:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(
            prefix=f".{self.path.name}.", suffix=suffix, dir=self.path.parent
        )
        self._stack.callback(_unlink, name)
        return self._stack.enter_context(os.fdopen(fd, "w+b"))

    def add(self, feature: dict[str, Any]) -> None:
        """Append one building's feature (two CityObjects with one id are refused when
        the document is assembled: :meth:`close`)."""
        for key, value in feature["CityObjects"].items():
            self._ids.add(key)
            self._objects.write(b"," if self._objects_written else b"")
            self._objects_written += 1
            self._objects.write(cityjson_bytes({key: _shifted(value, self._count)})[1:-1])
        for point in feature["vertices"]:
            self._vertices.write(b"," if self._count else b"")
            self._vertices.write(cityjson_bytes(point))
            self._count += 1
        self._extent.add(feature["vertices"])

    def close(self) -> None:
        """Assemble the document into ``path`` and remove the temporary files; ValueError
        (and no document) for two CityObjects with one id, the first such id named."""
        try:
            twice = self._ids.repeated()
            if twice is not None:
                raise ValueError(f"two CityObjects with the id '{twice}'")
            header = dict(self.header)
            header["metadata"] = self._extent.metadata(header)
            head = cityjson_bytes(header)[:-1]
            with atomic_output(self.path) as out:
                out.write(head + b',"CityObjects":{')
                self._copy(self._objects, out)
                out.write(b'},"vertices":[')
                self._copy(self._vertices, out)
                out.write(b"]}\n")
        finally:
            self._stack.close()

    @staticmethod
    def _copy(spool: BinaryIO, out: BinaryIO) -> None:
        spool.flush()
        spool.seek(0)
        shutil.copyfileobj(spool, out, 1 << 16)

    def __enter__(self) -> CityJSONWriter:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if kind is None:
            self.close()
        else:
            self._stack.close()


class Ids:
    """The CityObject ids of a streamed document, to find one written twice in flat
    memory: each id is kept as an 8-byte digest (where a set of the ids takes a hundred
    bytes an id) and as a line of ``spool`` (a temporary file), read again only for the
    few digests that repeat, to tell a repeated id from two ids sharing a digest."""

    def __init__(self, spool: BinaryIO):
        self._spool = spool
        self._digests = array("Q")

    def add(self, key: str) -> None:
        self._digests.append(_digest(key))
        self._spool.write(json.dumps(key).encode("ascii") + b"\n")

    def repeated(self) -> str | None:
        """The first id (in the order added) added before, None when each came once."""
        ordered = np.frombuffer(self._digests, dtype=np.uint64)
        ordered.sort()  # in place: the digests are not needed in their order
        shared = set(ordered[1:][ordered[1:] == ordered[:-1]].tolist())
        if not shared:
            return None
        self._spool.flush()
        self._spool.seek(0)
        seen: set[str] = set()
        for line in self._spool:
            key: str = json.loads(line)
            if _digest(key) in shared:
                if key in seen:
                    return key
                seen.add(key)
        return None


def _digest(key: str) -> int:
    return int.from_bytes(
        hashlib.blake2b(key.encode("utf-8", "surrogatepass"), digest_size=8).digest(), "big"
    )


def _unlink(name: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(name)


class _Extent:
    """The bounding box of integer vertices, as the metadata's geographicalExtent."""

    def __init__(self) -> None:
        self.low: np.ndarray | None = None
        self.high: np.ndarray | None = None

    def add(self, points: list[list[int]]) -> None:
        if not points:
            return
        array = np.asarray(points, dtype=np.int64)
        low, high = array.min(axis=0), array.max(axis=0)
        self.low = low if self.low is None else np.minimum(self.low, low)
        self.high = high if self.high is None else np.maximum(self.high, high)

    def metadata(self, header: dict[str, Any]) -> dict[str, Any]:
        """The header's metadata with the extent first (in real coordinates)."""
        if self.low is None or self.high is None:
            return dict(header["metadata"])
        translate = header["transform"]["translate"]
        real = [
            round(translate[i % 3] + value * SCALE, 3)
            for i, value in enumerate([*self.low.tolist(), *self.high.tolist()])
        ]
        return {"geographicalExtent": real, **header["metadata"]}


def _json_safe(value: Any) -> Any:
    """An attribute value as JSON can hold it: NaN and infinities become null, tuples
    lists, keys strings, and anything else not JSON its text."""
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(key): _json_safe(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(item) for item in value]
    return str(value)


def _shifted(value: dict[str, Any], offset: int) -> dict[str, Any]:
    """A CityObject with its geometries' vertex indices moved by ``offset``."""
    if "geometry" not in value or offset == 0:
        return value
    shifted = dict(value)
    shifted["geometry"] = [
        {**g, "boundaries": _add(g["boundaries"], offset)} for g in value["geometry"]
    ]
    return shifted


def _add(boundaries: Any, offset: int) -> Any:
    if isinstance(boundaries, list):
        return [_add(item, offset) for item in boundaries]
    return boundaries + offset


def _object(kind: str, attributes: dict[str, Any], **members: Any) -> dict[str, Any]:
    result: dict[str, Any] = {"type": kind}
    if attributes:
        result["attributes"] = attributes
    for key in ("children", "geometry", "parents"):
        if key in members:
            result[key] = [members[key]] if key == "geometry" else members[key]
    return result


def _children(ids: list[str]) -> dict[str, list[str]]:
    return {"children": ids} if ids else {}


def _posts(places: Sequence[Post], vertices: _Vertices) -> dict[str, Any]:
    """A roof's posts as a MultiSolid: each a closed box facing outwards, its sides
    WallSurfaces, its foot a GroundSurface (an OuterCeilingSurface off the ground), its
    top, under the roof, a ClosureSurface."""
    half = round(POST / 2 * UNITS)
    solids, values = [], []
    for x, y, base, top in places:
        cx, cy = round(x * UNITS), round(y * UNITS)
        z0, z1 = round(base * UNITS), round(top * UNITS)
        ring = [(cx - half, cy - half), (cx + half, cy - half), (cx + half, cy + half)]
        ring.append((cx - half, cy + half))  # counter-clockwise seen from above
        low = [vertices.add((px, py, z0)) for px, py in ring]
        high = [vertices.add((px, py, z1)) for px, py in ring]
        sides = [[[low[k], low[(k + 1) % 4], high[(k + 1) % 4], high[k]]] for k in range(4)]
        solids.append([[[low[::-1]], *sides, [high]]])
        values.append([[0 if z0 <= 0 else 1, 2, 2, 2, 2, 3]])
    kinds = ["GroundSurface", "OuterCeilingSurface", "WallSurface", "ClosureSurface"]
    used = sorted({v for solid in values for shell in solid for v in shell})
    renumber = {old: new for new, old in enumerate(used)}
    values = [[[renumber[v] for v in shell] for shell in solid] for solid in values]
    semantics = {"surfaces": [{"type": kinds[k]} for k in used], "values": values}
    return {"type": "MultiSolid", "lod": LOD, "boundaries": solids, "semantics": semantics}


def _part_attributes(
    volume: Volume, geometry: dict[str, Any], points: list[Point]
) -> dict[str, Any]:
    used = {i for surface in _surfaces_of(geometry) for ring in surface for i in ring}
    top = max(points[i][2] for i in used) * SCALE
    return {
        "eavesHeight": round(volume.eaves, 3),
        "measuredHeight": round(top, 3),
        "minHeight": round(volume.base, 3),
        "roofType": volume.roof.type,
    }


def _surfaces_of(geometry: dict[str, Any]) -> list[Surface]:
    boundaries = geometry["boundaries"]
    return [s for shell in boundaries for s in shell] if geometry["type"] == "Solid" else boundaries


class _Vertices:
    """A building's vertices, one index per integer point. A roof's points within SNAP
    units of a point already used by the volume being written are that point
    (:meth:`add_all`): a skeleton's nodes a millimetre or two apart would otherwise be
    distinct vertices joined by edges too short for :func:`_split_edges` to mend, and the
    shell would not close."""

    def __init__(self) -> None:
        self.index: dict[Point, int] = {}
        self.points: list[Point] = []
        self.cells: dict[Point, list[int]] = {}  # the volume's points, by snap-sized cell
        self.snap = SNAP[0]

    def volume(self, snap: int = SNAP[0]) -> None:
        """A new volume: snap to its own points only, within ``snap`` units."""
        self.cells = {}
        self.snap = snap

    def add(self, point: Point) -> int:
        found = self.index.get(point)
        if found is None:
            found = self.index[point] = len(self.points)
            self.points.append(point)
        cell = self.cells.setdefault(self.cell(point), [])
        if found not in cell:
            cell.append(found)
        return found

    def near(self, point: Point) -> list[tuple[int, int]]:
        """The volume's points within the snap: (squared distance, index) each."""
        x, y, z = self.cell(point)
        found = []
        for dx, dy, dz in itertools.product((-1, 0, 1), repeat=3):
            for i in self.cells.get((x + dx, y + dy, z + dz), ()):
                gap = _gap(self.points[i], point)
                if gap <= self.snap * self.snap:
                    found.append((gap, i))
        return found

    def add_all(self, array: np.ndarray) -> tuple[list[int], np.ndarray]:
        """Indices of (n, 3) points in metres, and the points in units as used. Points
        within the snap of each other, in chains, are one (a cluster of a skeleton's
        nodes), and that is the volume's nearest point within the snap of one of them
        if there is one, else the cluster's least point."""
        units = np.rint(np.asarray(array, dtype=float) * UNITS).astype(np.int64)
        points = [(int(x), int(y), int(z)) for x, y, z in units.tolist()]
        unique = sorted(set(points))
        parent = {p: p for p in unique}

        def root(p: Point) -> Point:
            while parent[p] != p:
                parent[p] = parent[parent[p]]
                p = parent[p]
            return p

        cells: dict[Point, list[Point]] = {}
        for p in unique:
            x, y, z = self.cell(p)
            for dx, dy, dz in itertools.product((-1, 0, 1), repeat=3):
                for q in cells.get((x + dx, y + dy, z + dz), ()):
                    if _gap(p, q) <= self.snap * self.snap:
                        parent[root(q)] = root(p)
            cells.setdefault((x, y, z), []).append(p)
        clusters: dict[Point, list[Point]] = {}
        for p in unique:
            clusters.setdefault(root(p), []).append(p)
        chosen: dict[Point, int] = {}
        for members in clusters.values():
            near = [(gap, i) for p in members for gap, i in self.near(p)]
            found = min(near)[1] if near else self.add(min(members))
            for p in members:
                chosen[p] = found
        ids = [chosen[p] for p in points]
        snapped = np.asarray([self.points[i] for i in ids], dtype=np.int64).reshape(-1, 3)
        return ids, snapped

    def cell(self, point: Point) -> Point:
        return (point[0] // self.snap, point[1] // self.snap, point[2] // self.snap)


def _gap(p: Point, q: Point) -> int:
    """The squared distance of two points."""
    return (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2


def _geometry(volume: Volume, vertices: _Vertices) -> dict[str, Any]:
    """The volume's Solid (or MultiSurface when its surfaces do not close, with the
    roof's slivers or without them)."""
    if not volume.eaves > volume.base:
        raise ValueError(f"eaves at {volume.eaves} m are not above the base at {volume.base} m")
    before = len(vertices.points)
    tries = [(True, SNAP[0]), *((False, snap) for snap in SNAP)]
    for number, (slivers, snap) in enumerate(tries):  # slivers may fold the shell at a ridge
        vertices.volume(snap)
        if number:  # the try before's points are not written
            for point in vertices.points[before:]:
                del vertices.index[point]
            del vertices.points[before:]
        kinds, surfaces = zip(*_surfaces(volume, vertices, slivers), strict=True)
        split = _cancelled(_despiked(_split_edges(list(surfaces), vertices.points)))
        kinds = tuple(kind for kind, surface in zip(kinds, split, strict=True) if surface)
        split = [surface for surface in split if surface]
        oriented = _orient(split, vertices.points)
        if oriented is not None:
            break
    types = [t for t in SURFACE_TYPES if t in kinds]
    values = [types.index(kind) for kind in kinds]
    semantics = {"surfaces": [{"type": t} for t in types], "values": values}
    if oriented is None:
        return {"type": "MultiSurface", "lod": LOD, "boundaries": split, "semantics": semantics}
    semantics["values"] = [values]
    return {"type": "Solid", "lod": LOD, "boundaries": [oriented], "semantics": semantics}


def _surfaces(
    volume: Volume, vertices: _Vertices, slivers: bool = True
) -> Iterator[tuple[str, Surface]]:
    """Ground, walls and roof: rings of vertex indices, facing outwards as built (the
    roof's slivers left out without ``slivers``: see :func:`_polygons`)."""
    base, eaves = round(volume.base * UNITS), round(volume.eaves * UNITS)
    exterior = _plan_ring(volume.part.exterior)
    if not exterior:
        raise ValueError("a footprint part with no area at millimetre precision")
    rings = [exterior, *(r for r in map(_plan_ring, volume.part.interiors) if r)]

    def at(ring: list[tuple[int, int]], z: int) -> Ring:
        return [vertices.add((x, y, z)) for x, y in ring]

    # the outer ring is counter-clockwise seen from above, holes clockwise: the bottom
    # faces down, so its rings turn the other way; off the ground it is a ceiling outside
    bottom = "GroundSurface" if base <= 0 else "OuterCeilingSurface"
    yield bottom, [at(ring[::-1], base) for ring in rings]
    for ring in rings:
        for (ax, ay), (bx, by) in itertools.pairwise([*ring, ring[0]]):
            a0, b0 = vertices.add((ax, ay, base)), vertices.add((bx, by, base))
            a1, b1 = vertices.add((ax, ay, eaves)), vertices.add((bx, by, eaves))
            yield "WallSurface", [[a0, b0, b1, a1]]  # outwards is right of a -> b
    roofed = roof_outlines(volume)  # the glb's rule: the roof leaves out a tower on it
    for shape, still in roofed:
        flat = volume.roof.type == "flat"
        if not flat:
            cover, infill = roof_meshes(shape, volume.eaves, volume.roof, still)
            # a roof that rises nowhere (roofs may fall back to a flat slab) is flat here
            top = float(np.max(cover.vertices[:, 2])) * UNITS if len(cover.vertices) else 0.0
            flat = top < eaves + 1
        if flat:
            yield "RoofSurface", [at(ring, eaves) for ring in _plan_rings(shape, rings, volume)]
            continue
        for surface in _polygons(cover, vertices, slivers):
            yield "RoofSurface", surface
        for piece in infill:
            for surface in _polygons(piece, vertices, slivers):
                yield "WallSurface", surface
    if roofed[0][0] is volume.part:
        return
    # under the parts standing on it, the volume is closed at its eaves: their base
    rest = volume.part.difference(shapely.union_all([shape for shape, _ in roofed]))
    for piece in getattr(rest, "geoms", [rest]):
        if isinstance(piece, shapely.Polygon) and not piece.is_empty:
            closing = [at(ring, eaves) for ring in _plan_rings(orient(piece, 1.0), [], volume)]
            if closing:
                yield "ClosureSurface", closing


def _plan_rings(shape: Any, rings: list[list[tuple[int, int]]], volume: Volume) -> list[Any]:
    """A polygon's rings in integer units (:func:`_plan_ring`), the exterior first: the
    volume's own ``rings`` when it is the volume's part; none when the exterior
    vanishes at millimetre precision."""
    if shape is volume.part:
        return rings
    exterior = _plan_ring(shape.exterior)
    if not exterior:
        return []
    return [exterior, *(r for r in map(_plan_ring, shape.interiors) if r)]


def _plan_ring(ring: Any) -> list[tuple[int, int]]:
    """A ring's points in integer units, without repeats (nor the closing point); empty
    when fewer than 3 are left."""
    units = np.rint(np.asarray(ring.coords, dtype=float)[:, :2] * UNITS).astype(np.int64)
    points = [(int(x), int(y)) for x, y in units.tolist()]
    kept = [p for p, q in itertools.pairwise(points) if p != q]  # also drops the closing point
    while len(kept) > 1 and kept[-1] == kept[0]:
        kept.pop()
    return kept if len(kept) >= 3 else []


def _polygons(mesh: trimesh.Trimesh, vertices: _Vertices, slivers: bool = True) -> list[Surface]:
    """A mesh's triangles as polygons: each set of edge-adjacent triangles with the same
    normal becomes one polygon when its outline is one simple ring, else stays triangles.
    Triangles degenerate at millimetre precision are left out, and without ``slivers``
    those less than a unit high too."""
    if len(mesh.faces) == 0:
        return []
    points = np.asarray(mesh.vertices, dtype=float)
    ids, rounded = vertices.add_all(points)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    corners = np.asarray(ids, dtype=np.int64)[faces]  # (n, 3) vertex indices
    units = rounded[faces].astype(float)  # (n, 3, 3) integer points
    twice = np.linalg.norm(np.cross(units[:, 1] - units[:, 0], units[:, 2] - units[:, 0]), axis=1)
    spans = points[faces]
    normal = np.cross(spans[:, 1] - spans[:, 0], spans[:, 2] - spans[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    keep = twice >= 1.0  # at least half a square unit (three distinct points, not in line)
    if not slivers:  # nor a corner within NEAR of the opposite edge (_split_edges puts it in)
        longest = np.max(np.linalg.norm(units - np.roll(units, 1, axis=1), axis=2), axis=1)
        keep &= twice > math.sqrt(NEAR) * longest
    triangles = [(a, b, c) for a, b, c in corners[keep].tolist()]
    normals = normal[keep]
    parent = list(range(len(triangles)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    by_edge: dict[tuple[int, int], list[int]] = {}
    for index, triangle in enumerate(triangles):
        for u, v in _ring_edges(list(triangle)):
            by_edge.setdefault((min(u, v), max(u, v)), []).append(index)
    for sharing in by_edge.values():
        for i, j in itertools.combinations(sharing, 2):
            if float(normals[i] @ normals[j]) > 1 - COPLANAR:
                parent[root(j)] = root(i)
    groups: dict[int, list[int]] = {}
    for index in range(len(triangles)):
        groups.setdefault(root(index), []).append(index)
    surfaces: list[Surface] = []
    for members in groups.values():
        group = [triangles[i] for i in members]
        outline = _outline(group)
        surfaces.extend([[outline]] if outline else [[list(t)] for t in group])
    return surfaces


def _ring_edges(ring: Ring) -> Iterator[tuple[int, int]]:
    return zip(ring, ring[1:] + ring[:1], strict=True)


def _outline(triangles: list[tuple[int, int, int]]) -> Ring | None:
    """The one simple ring around consistently oriented triangles, or None."""
    if len(triangles) == 1:
        return list(triangles[0])
    edges = [e for t in triangles for e in _ring_edges(list(t))]
    present = set(edges)
    if len(present) < len(edges):
        return None  # a repeated edge: not one consistent sheet
    following: dict[int, int] = {}
    first: int | None = None
    for u, v in edges:
        if (v, u) in present:
            continue
        if u in following:
            return None  # the outline touches itself
        following[u] = v
        first = u if first is None else first
    if first is None:
        return None
    ring = [first]
    while (nxt := following.get(ring[-1])) != first:
        if nxt is None or len(ring) >= len(following):
            return None
        ring.append(nxt)
    return ring if len(ring) == len(following) else None  # else holes: keep the triangles


def _split_edges(surfaces: list[Surface], points: list[Point]) -> list[Surface]:
    """Surfaces whose ring edges pass through other vertices of the shell (closer than
    NEAR, and not within APART of the edge's ends) get those vertices inserted, so that
    every edge is shared whole. Only vertices within an edge's span of x are tried."""
    used = np.asarray(sorted({i for s in surfaces for ring in s for i in ring}), dtype=np.int64)
    where = np.asarray([points[i] for i in used.tolist()], dtype=float)
    edges = np.asarray([e for s in surfaces for ring in s for e in _ring_edges(ring)])
    position = {int(vertex): row for row, vertex in enumerate(used.tolist())}
    starts = where[[position[i] for i in edges[:, 0].tolist()]]
    steps = where[[position[i] for i in edges[:, 1].tolist()]] - starts
    by_x = np.argsort(where[:, 0], kind="stable")
    xs = where[by_x, 0]
    low = np.searchsorted(xs, np.minimum(starts[:, 0], starts[:, 0] + steps[:, 0]) - 1, "left")
    high = np.searchsorted(xs, np.maximum(starts[:, 0], starts[:, 0] + steps[:, 0]) + 1, "right")
    counts = high - low
    edge = np.repeat(np.arange(len(edges)), counts)  # (edge, candidate vertex) pairs
    within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    candidate = by_x[np.repeat(low, counts) + within]
    relative = where[candidate] - starts[edge]
    length2 = (steps[edge] ** 2).sum(axis=1)
    t = (relative * steps[edge]).sum(axis=1) / length2  # along the edge, 0 to 1
    off = relative - t[:, None] * steps[edge]  # across it
    on = ((off**2).sum(axis=1) <= NEAR) & (t > 0) & (t < 1)
    on &= (t * t * length2 > APART) & ((1 - t) ** 2 * length2 > APART)
    inserted: dict[int, list[int]] = {}
    for row in np.lexsort((t[on], edge[on])).tolist():  # by edge, then along it
        inserted.setdefault(int(edge[on][row]), []).append(int(used[candidate[on][row]]))
    result: list[Surface] = []
    index = 0
    for surface in surfaces:
        rings = []
        for ring in surface:
            out: Ring = []
            for u in ring:
                out.append(u)
                out.extend(inserted.get(index, ()))
                index += 1
            rings.append(out)
        result.append(rings)
    return result


def _despiked(surfaces: list[Surface]) -> list[Surface]:
    """Rings without spikes (an edge that runs back along itself, ``u -> v -> u``: a
    sliver snapped flat, or a point :func:`_split_edges` put on the edge next to it) and
    without a point twice in a row; a surface whose exterior is left with fewer than 3
    points is empty (left out), a hole so left is dropped."""
    result: list[Surface] = []
    for surface in surfaces:
        rings = []
        for ring in surface:
            out: Ring = []
            for u in ring:
                if out and out[-1] == u:
                    continue
                while len(out) >= 2 and out[-2] == u:  # out[-1] is a spike's tip
                    out.pop()
                    out.pop()
                out.append(u)
            while len(out) >= 3 and (out[0] == out[-1] or out[1] == out[-1] or out[0] == out[-2]):
                if out[0] == out[-1]:
                    out.pop()
                elif out[1] == out[-1]:  # the tip is out[0]
                    out = out[1:-1]
                else:  # the tip is out[-1]
                    out = out[:-2]
            rings.append(out)
        if len(rings[0]) < 3:
            result.append([])
            continue
        result.append([rings[0], *(ring for ring in rings[1:] if len(ring) >= 3)])
    return result


def _cancelled(surfaces: list[Surface]) -> list[Surface]:
    """The surfaces less pairs of one ring run both ways (a fin of no volume: two slivers
    of a roof's apex snapped onto each other), each left empty."""

    def key(ring: Ring) -> tuple[int, ...]:
        at = ring.index(min(ring))
        return tuple(ring[at:] + ring[:at])

    waiting: dict[tuple[int, ...], list[int]] = {}
    gone: set[int] = set()
    for index, surface in enumerate(surfaces):
        if len(surface) != 1 or not surface[0]:
            continue
        mine, back = key(surface[0]), key(surface[0][::-1])
        if waiting.get(back):
            gone.update((waiting[back].pop(), index))
        else:
            waiting.setdefault(mine, []).append(index)
    return [[] if index in gone else surface for index, surface in enumerate(surfaces)]


def _orient(surfaces: list[Surface], points: list[Point]) -> list[Surface] | None:
    """The surfaces turned to face outwards, each edge used by exactly two of them in
    opposite directions; None when they do not close into one such shell. The first
    surface (the bottom) sets the orientation, the enclosed volume checks it."""
    edges = [[e for ring in surface for e in _ring_edges(ring)] for surface in surfaces]
    runs = [set(surface_edges) for surface_edges in edges]
    sharing: dict[tuple[int, int], list[int]] = {}
    for index, surface_edges in enumerate(edges):
        for u, v in surface_edges:
            sharing.setdefault((min(u, v), max(u, v)), []).append(index)
    if any(len(set(owners)) != 2 or len(owners) != 2 for owners in sharing.values()):
        return None
    flip: list[bool | None] = [None] * len(surfaces)
    flip[0] = False
    queue = deque([0])
    while queue:
        index = queue.popleft()
        for u, v in edges[index]:
            for other in sharing[(min(u, v), max(u, v))]:
                if other == index:
                    continue
                # the neighbour must run this edge the other way: flipped if it runs along
                same = (u, v) in runs[other]
                want = same != bool(flip[index])
                if flip[other] is None:
                    flip[other] = want
                    queue.append(other)
                elif flip[other] != want:
                    return None
    if any(f is None for f in flip):
        return None
    oriented = [
        [ring[::-1] for ring in surface] if flipped else surface
        for surface, flipped in zip(surfaces, flip, strict=True)
    ]
    directed = Counter(e for surface in oriented for ring in surface for e in _ring_edges(ring))
    if any(n != 1 or directed[(v, u)] != 1 for (u, v), n in directed.items()):
        return None
    return oriented if _volume(oriented, points) > 0 else None


def _volume(surfaces: list[Surface], points: list[Point]) -> float:
    """The signed volume a closed shell of planar polygons encloses (divergence theorem:
    a third of the sum of each polygon's vector area dotted with one of its points)."""
    where = np.asarray(points, dtype=float)
    heads, tails, owners = [], [], []
    for index, surface in enumerate(surfaces):
        for ring in surface:
            heads.extend(ring)
            tails.extend(ring[1:] + ring[:1])
            owners.extend([index] * len(ring))
    areas = np.zeros((len(surfaces), 3))
    np.add.at(areas, np.asarray(owners), np.cross(where[heads], where[tails]) / 2)
    anchors = where[[surface[0][0] for surface in surfaces]]
    return float(np.einsum("ij,ij->", anchors, areas)) / 3
