"""OGC 3D Tiles 1.1 of a city (``facade city --3dtiles``): ``3dtiles/tileset.json`` and
glb content, in levels of detail, streamed as the buildings finish.

**Hierarchy.** A quadtree over the buildings' centroids in the run's local frame (metres
from its origin), split until a square holds at most CAPACITY[k] buildings of the finest
level of detail k chosen (``--lod``: LOD1 blocks, LOD2 walls and roofs, LOD3 the
façades; lods.py). Each coarser LOD goes to the largest squares that hold at most its
own CAPACITY, so a square may hold a chain of tiles, coarse to fine, each the only child
of the one before; the square's children hang under the last. Every tile replaces its
parent (``refine: REPLACE``); squares above the coarsest tiles have no content.

**Geometric error** is what a tile's content gets wrong, in metres: a leaf's none (0); a
LOD2 tile the façades' relief it leaves out (how far the LOD3 model stands out of its
box) and at least MIN_ERROR[2] (a storey: the rhythm of windows and floors it leaves
out); a LOD1 tile as much, at least MIN_ERROR[1], and its roofs' depth; a square
without content under one with content the largest of its children's; above, the
diagonal of its box (all of it missing), and at least twice its children's. Each tile's
error is at least its children's: errors fall from the root to the leaves.

**Place on the globe.** Tiles are z-up; their glTF content is y-up, as 3D Tiles wants:
the runtime turns glTF's y-up to z-up (x, y, z) -> (x, -z, y), which makes our glTF
frame (x east, y up, z south) x east, y north, z up. The root's ``transform`` maps that
local frame to Earth-centred, Earth-fixed coordinates (EPSG:4978): its translation is
the run's origin on the ellipsoid (height 0: buildings stand on it), its columns the
ECEF directions of a metre east, north (the CRS's grid, so grid north and the scale
factor are in them) and up, measured with PROJ at the origin.

**Files.** ``3dtiles/<level>/<column>/<row>.lod<k>.glb``: a square's tiles are written,
each atomically, as soon as its last building is done (or failed), and
``tileset.json`` last, atomically; files of an earlier run the tileset no longer names
are removed. The same buildings give the same bytes. While the run goes, what each
square's tiles leave for ``tileset.json`` is kept in an unnamed temporary file in
``3dtiles/`` (:class:`SquareRecords`): nothing of it is left beside the outputs, even
when the run is killed.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import struct
import tempfile
from array import array
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
import trimesh

from facadecli.city.georef import Georef, georeference
from facadecli.city.lods import dressed, feature_of, lod_meshes, roof_depth
from facadecli.errors import SpecError
from facadecli.export.atomic import atomic_output, write_atomic
from facadecli.export.glb_merge import merge_glb, read_glb
from facadecli.export.gltf import glb_bytes
from facadecli.export.instancing import EXTENSION, node_matrix, placements

FOLDER = "3dtiles"
LODS = (1, 2, 3)
CAPACITY = {1: 256, 2: 32, 3: 8}  # buildings a tile of each level of detail holds at most
MAX_LEVEL = 20  # quadtree levels at most (buildings sharing a centroid stay together)
MIN_ERROR = {1: 4.0, 2: 3.0}  # metres: what a block or a façade-less model gets wrong at least
TILE_FILE = re.compile(r"\d+\.lod[123]\.glb")
NUMBER = re.compile(r"0|[1-9]\d*")  # a level, column or row as a tile's name writes it
Box = tuple[float, float, float, float, float, float]  # min x, y, z, max x, y, z (z up)


def parse_lods(text: str) -> tuple[int, ...]:
    """``--lod 1,2,3`` as the levels of detail, coarse to fine; SpecError (exit 2) else."""
    try:
        found = sorted({int(item) for item in text.split(",") if item.strip()})
    except ValueError:
        found = []
    if not found or any(lod not in LODS for lod in found):
        raise SpecError.at(
            "--lod",
            None,
            None,
            f"'{text}' is not a list of levels of detail",
            "give some of 1 (blocks), 2 (roofs), 3 (façades), separated by commas: --lod 1,2,3",
        )
    return tuple(found)


def chosen_lods(text: str | None, tiles: bool) -> tuple[tuple[int, ...], int]:
    """``--lod``: the levels of detail of the 3D Tiles (none without ``tiles``) and the
    merged glb's level (the finest asked; 3, façades, by default). Without 3D Tiles only
    one level may be asked; SpecError (exit 2) else."""
    lods = parse_lods(text or "1,2,3")
    if not tiles and text is not None and len(lods) > 1:
        raise SpecError.at(
            "--lod",
            None,
            None,
            f"'{text}' names several levels of detail; the merged glb takes one",
            "give one of 1 (blocks), 2 (roofs), 3 (façades), or add --3dtiles to make "
            "3D Tiles at several",
        )
    return (lods if tiles else ()), (lods[-1] if text is not None else 3)


def ecef_transform(georef: Georef) -> list[float]:
    """The root tile's transform (column-major 4 × 4): local metres (x east, y north on
    the CRS's grid, z up) to ECEF metres, exact at the origin (see the module)."""
    to_ecef = _to_ecef()
    step = 10.0

    def at(x: float, y: float, z: float) -> np.ndarray:
        lon, lat = georef.lonlat(x, y)
        return np.array(to_ecef.transform(lon, lat, z), dtype=float)

    origin = at(0.0, 0.0, 0.0)
    columns = [
        (at(step, 0.0, 0.0) - at(-step, 0.0, 0.0)) / (2 * step),
        (at(0.0, step, 0.0) - at(0.0, -step, 0.0)) / (2 * step),
        (at(0.0, 0.0, step) - at(0.0, 0.0, -step)) / (2 * step),
    ]
    matrix = [*(float(v) for c in columns for v in (*c, 0.0)), *(float(v) for v in origin), 1.0]
    return [round(v, 12) if abs(v) < 2 else round(v, 4) for v in matrix]


def _to_ecef() -> pyproj.Transformer:
    return pyproj.Transformer.from_crs(
        pyproj.CRS.from_epsg(4979), pyproj.CRS.from_epsg(4978), always_xy=True
    )


@dataclass(frozen=True, slots=True)
class Square:
    """A square of the quadtree as read from its arrays (:meth:`Quadtree.square`), made
    when asked for, not held: its place in the tree's depth-first order (``index``), its
    level, column and row, and where its buildings are in the tree's order (from
    ``start`` to ``end``)."""

    index: int
    level: int
    column: int
    row: int
    start: int
    end: int

    @property
    def count(self) -> int:
        """How many buildings lie in it."""
        return self.end - self.start


Centroids = Sequence[tuple[float, float]]  # each building's centroid, in the run's order


@dataclass(frozen=True)
class Quadtree:
    """The quadtree of a run's buildings (:func:`quadtree`): its frame (the root's
    south-west corner and side, metres), its squares and ``order``, the buildings'
    positions in the run leaf by leaf, depth first, each leaf's in the run's order: a
    square's buildings are ``order[start:end]``, 8 bytes a building in one array, not a
    list of ids in every square on the way to its leaf.

    The squares are numpy arrays in the tree's depth-first order (the root first, each
    square before its children, a square's children in column and row order): their
    ``level``, ``column``, ``row``, ``start``, ``end`` and ``after`` (the first square
    past its own and its children's: a leaf's is the next one). 33 bytes a square, where
    a Python object a square took over 100 and a tuple of its children."""

    west: float
    south: float
    side: float
    order: np.ndarray
    level: np.ndarray
    column: np.ndarray
    row: np.ndarray
    start: np.ndarray
    end: np.ndarray
    after: np.ndarray

    def __len__(self) -> int:
        """How many squares the tree has."""
        return len(self.level)

    def square(self, index: int) -> Square:
        """The square at ``index`` in the tree's depth-first order."""
        return Square(
            index,
            int(self.level[index]),
            int(self.column[index]),
            int(self.row[index]),
            int(self.start[index]),
            int(self.end[index]),
        )

    @property
    def root(self) -> Square:
        return self.square(0)

    def children(self, square: Square) -> Iterator[Square]:
        """The square's children, in column and row order (none for a leaf)."""
        index = square.index + 1
        while index < self.after[square.index]:
            yield self.square(index)
            index = int(self.after[index])

    def members(self, square: Square) -> list[int]:
        """The positions of the square's buildings, in the run's order."""
        return [int(k) for k in np.sort(self.order[square.start : square.end])]

    def path(self, point: tuple[float, float]) -> Iterator[Square]:
        """The squares from the root to the leaf a centroid lies in."""
        square = self.root
        yield square
        while self.after[square.index] > square.index + 1:
            column, row = _quarter(square, point, self.west, self.south, self.side)
            square = next(c for c in self.children(square) if (c.column, c.row) == (column, row))
            yield square

    def find(self, level: int, column: int, row: int) -> Square | None:
        """The square at ``level``, ``column``, ``row``; None when the tree has none."""
        square = self.root
        while square.level < level:
            shift = level - square.level - 1
            inner = [
                c
                for c in self.children(square)
                if (c.column, c.row) == (column >> shift, row >> shift)
            ]
            if not inner:
                return None
            square = inner[0]
        return square if (square.level, square.column, square.row) == (level, column, row) else None


def _quarter(
    square: Square, point: tuple[float, float], west: float, south: float, side: float
) -> tuple[int, int]:
    """The column and row of the square's quarter a point lies in (one rule for splitting
    the tree and for finding a building's leaf in it)."""
    size = side / 2 ** (square.level + 1)
    x, y = point
    column = min(square.column * 2 + 1, max(square.column * 2, int((x - west) // size)))
    row = min(square.row * 2 + 1, max(square.row * 2, int((y - south) // size)))
    return column, row


def quadtree(centroids: Centroids, capacity: int) -> Quadtree:
    """The quadtree of the buildings (centroids in local metres, in the run's order), split
    until a square holds at most ``capacity`` buildings. The root square is the smallest
    power-of-two side (from 1 m) holding them all, its south-west corner at the lowest
    centroid."""
    if not centroids:
        west = south = 0.0
        side = 1.0
    else:
        west = math.floor(min(x for x, _ in centroids))
        south = math.floor(min(y for _, y in centroids))
        east, north = max(x for x, _ in centroids), max(y for _, y in centroids)
        side = 1.0
        while west + side <= east or south + side <= north:
            side *= 2
    rows: dict[str, array[int]] = {key: array("q") for key in FIELDS}
    leaves: list[array[int]] = []  # each leaf's positions, depth first
    placed = [0]  # positions put in the order so far

    def split(square: Square, items: array[int]) -> None:
        index = square.index
        values = (square.level, square.column, square.row, placed[0], 0, 0)  # end, after: below
        for field, value in zip(FIELDS, values, strict=True):
            rows[field].append(value)
        if len(items) <= capacity or square.level >= MAX_LEVEL:
            leaves.append(items)
            placed[0] += len(items)
        else:
            quarters: dict[tuple[int, int], array[int]] = {}
            for position in items:
                key = _quarter(square, centroids[position], west, south, side)
                quarters.setdefault(key, array("q")).append(position)
            del items
            for column, row in sorted(quarters):
                child = Square(len(rows["level"]), square.level + 1, column, row, 0, 0)
                split(child, quarters.pop((column, row)))
        rows["end"][index] = placed[0]
        rows["after"][index] = len(rows["level"])

    split(Square(0, 0, 0, 0, 0, 0), array("q", range(len(centroids))))
    order = np.concatenate([np.frombuffer(leaf, dtype=np.int64) for leaf in leaves])
    found = {key: np.frombuffer(rows[key], dtype=np.int64).astype(KINDS[key]) for key in FIELDS}
    return Quadtree(west, south, side, order, **found)


FIELDS = ("level", "column", "row", "start", "end", "after")  # a square's, in its arrays
KINDS = {"level": np.uint8, "column": np.int32, "row": np.int32}
KINDS |= {"start": np.int64, "end": np.int64, "after": np.int64}


class SquareRecords:
    """What the squares' tiles leave for ``tileset.json``, spilled to an unnamed temporary
    file in ``folder`` (made on the first record; gone with the object or the process,
    nothing beside the outputs) at each square's place in the tree's depth-first order:
    a sorted run, read back in that order as ``tileset.json`` is written. Two fixed-size
    records a square: its tiles' (:meth:`put_tiles`: its content's box and each tile's
    error, once written) and its span's (:meth:`put_span`: the box of its content and
    its children's, and their largest error). Nothing a square is held in memory."""

    TILES = struct.Struct(f"<?6d{len(LODS)}d")  # written, box, each tile's error (its chain's)
    SPAN = struct.Struct("<?6dd")  # spanned (any building built), box, largest error below

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self._file: Any = None
        self._size = self.TILES.size + self.SPAN.size

    def _at(self, index: int, offset: int) -> Any:
        if self._file is None:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._file = tempfile.TemporaryFile(dir=self.folder)  # noqa: SIM115 (with self)
        self._file.seek(index * self._size + offset)
        return self._file

    def _read(self, index: int, offset: int, record: struct.Struct) -> tuple[Any, ...] | None:
        if self._file is None:
            return None
        data = self._at(index, offset).read(record.size)
        if len(data) < record.size or not data[0]:  # past the end, or a hole: not put
            return None
        return record.unpack(data)

    def put_tiles(self, index: int, box: Box, errors: Sequence[float]) -> None:
        padded = [*errors, *[0.0] * (len(LODS) - len(errors))]
        self._at(index, 0).write(self.TILES.pack(True, *box, *padded))

    def tiles(self, index: int, count: int) -> tuple[Box, list[float]] | None:
        """The square's content box and its ``count`` tiles' errors; None when not written."""
        found = self._read(index, 0, self.TILES)
        if found is None:
            return None
        return _six(found[1:7]), list(found[7 : 7 + count])

    def put_span(self, index: int, box: Box, below: float) -> None:
        self._at(index, self.TILES.size).write(self.SPAN.pack(True, *box, below))

    def span(self, index: int) -> tuple[Box, float] | None:
        """The square's spanned box and largest error below; None when none of its
        buildings was built."""
        found = self._read(index, self.TILES.size, self.SPAN)
        if found is None:
            return None
        return _six(found[1:7]), found[7]


def _six(values: Sequence[float]) -> Box:
    return (values[0], values[1], values[2], values[3], values[4], values[5])


class TilesetWriter:
    """Writes the 3D Tiles of a run as its buildings finish: :meth:`done` for every
    building (its position in the run, its id and glb, or None when it failed), in any
    order; :meth:`close` writes ``tileset.json``. The quadtree is planned from every
    building's centroid before the first is built: it is split until a square holds
    CAPACITY of the finest LOD chosen; each coarser LOD goes to the largest squares
    holding at most its CAPACITY (the leaves for what is left), so far views load few,
    larger tiles. What it keeps of a building while the run goes is its place in the
    tree's order (8 bytes, :class:`Quadtree`) and, from its end to its square's, its
    glb: a building's squares are found again from its centroid (``centroids``, the
    run's, read not copied). Of a square, its place in the tree's arrays, its chain of
    LODs and its buildings not done yet (42 bytes); what its tiles leave for
    ``tileset.json`` (their box and errors) is spilled to disk as they are written
    (:class:`SquareRecords`) and read back in the tree's order by :meth:`close`."""

    def __init__(
        self,
        outdir: Path,
        georef: Georef,
        lods: Sequence[int],
        centroids: Centroids,
    ) -> None:
        self.folder = outdir / FOLDER
        self.georef = georef
        self.lods = tuple(sorted(lods))
        self.centroids = centroids
        self.tree = quadtree(centroids, CAPACITY[self.lods[-1]])
        self.chains: list[tuple[int, ...]] = [()]  # the few chains of LODs, each held once
        self.chain = np.zeros(len(self.tree), dtype=np.uint8)  # each square's, in chains
        self.left = np.zeros(len(self.tree), dtype=np.int64)  # its buildings not done yet
        self._assign(self.tree.root, ())
        self.records = SquareRecords(self.folder)  # the squares' tiles once written
        self.ready: dict[int, tuple[str, Path]] = {}  # built buildings' ids and glbs, by
        # position, until their tiles are written
        self.boxes: dict[int, Box] = {}  # their LOD3 boxes, likewise
        self.written = 0  # tile files
        self.triangles = dict.fromkeys(self.lods, 0)
        self.bytes = dict.fromkeys(self.lods, 0)

    def _assign(self, square: Square, done: tuple[int, ...]) -> None:
        """The LODs of the square's tiles: each not yet above it, once it holds at most
        that LOD's CAPACITY of buildings (or it is a leaf)."""
        children = list(self.tree.children(square))
        lods = tuple(
            k for k in self.lods if k not in done and (square.count <= CAPACITY[k] or not children)
        )
        if lods not in self.chains:
            self.chains.append(lods)
        self.chain[square.index] = self.chains.index(lods)
        if lods:
            self.left[square.index] = square.count
        for child in children:
            self._assign(child, done + lods)

    def lods_of(self, square: Square) -> tuple[int, ...]:
        """The levels of detail of the square's tiles, coarse first (none: no content)."""
        return self.chains[int(self.chain[square.index])]

    def _holders(self, position: int) -> list[Square]:
        """The squares with tiles of the building at ``position``, root first."""
        return [s for s in self.tree.path(self.centroids[position]) if self.chain[s.index]]

    def done(self, position: int, building_id: str, glb: Path | None) -> None:
        """The building at ``position`` in the run (``building_id``) has ended: built
        into ``glb``, or failed (None); the squares it completes are written."""
        if glb is not None:
            self.ready[position] = (building_id, glb)
        for square in self._holders(position):
            self.left[square.index] -= 1
            if self.left[square.index] == 0:
                self._write_square(square)

    def _lod3_box(self, position: int) -> Box:
        if position not in self.boxes:
            (self.boxes[position],) = _glb_boxes([self.ready[position][1]])
        return self.boxes[position]

    def _write_square(self, square: Square) -> None:
        members = [k for k in self.tree.members(square) if k in self.ready]
        built = [self.ready[k] for k in members]
        if not built:
            return
        lods = self.lods_of(square)
        features = [feature_of(glb) for _, glb in built] if lods[0] < 3 else []
        boxes: dict[int, Box] = {}
        relief = {1: 0.0, 2: 0.0}  # how far each building's LOD3 stands out of the LOD's box
        finest = [self._lod3_box(k) for k in members]
        name = _name(square)
        for lod in lods:
            path = self.folder / f"{name}.lod{lod}.glb"
            if lod == 3:
                merge_glb(built, path)
                boxes[3] = _union(finest)
                self.triangles[3] += sum(_glb_triangles(glb) for _, glb in built)
            else:
                scene, found = _lod_scene([lod_meshes(f, lod) for f in features])
                own = [b or whole for b, whole in zip(found, finest, strict=True)]
                data = glb_bytes(scene)
                path.parent.mkdir(parents=True, exist_ok=True)
                write_atomic(path, data)
                boxes[lod] = _union(own)
                relief[lod] = max(_outside(a, b) for a, b in zip(finest, own, strict=True))
                self.triangles[lod] += sum(len(g.faces) for g in scene.geometry.values())
            self.bytes[lod] += path.stat().st_size
            self.written += 1
        roofs = max((roof_depth(f) for f in features), default=0.0)
        errors = []
        for lod in lods:  # what each gets wrong; finer tiles below may raise it
            missed = 0.0
            if lod != 3:
                missed = max(relief[lod], MIN_ERROR[lod]) + (roofs if lod == 1 else 0.0)
            errors.append(round(missed, 3))
        self.records.put_tiles(square.index, _union(boxes.values()), errors)
        for k in members:  # a building's glb is let go with the last of its tiles
            if all(self.left[holder.index] == 0 for holder in self._holders(k)):
                self.ready.pop(k)
                self.boxes.pop(k, None)

    def close(self, name: str) -> dict[str, Any]:
        """Write ``tileset.json`` (and remove tiles an earlier run left that it does not
        name); returns what the report says of the tiles. The file is written as its
        text is made, a tile at a time from the squares' records read back in the tree's
        order (:class:`SquareRecords`, :meth:`_span`): no tile's JSON is held but those on
        the way from the root to the one written."""
        top = self._span(self.tree.root, covered=False)
        self.folder.mkdir(parents=True, exist_ok=True)
        self._remove_stale()
        transform = {"transform": ecef_transform(self.georef)}
        if top is None:  # no building built: an empty tileset, placed all the same
            empty: dict[str, Any] = {
                **transform,
                "boundingVolume": {"box": _box((0.0, 0.0, 0.0, 1.0, 1.0, 1.0))},
                "geometricError": 0.0,
                "refine": "REPLACE",
            }
            root = empty
            error = 0.0
        else:
            root = self._tile(self.tree.root, False, None, transform)
            error = top[1]
        tileset = {
            "asset": {"version": "1.1", "generator": "facadecli"},
            "extras": {"name": name, "georeference": georeference(self.georef)},
            "geometricError": error,
            "root": root,
        }
        with atomic_output(self.folder / "tileset.json") as out:
            for chunk in _batched(_text(tileset, 0)):
                out.write(chunk)
            out.write(b"\n")
        return {
            "tileset": f"{FOLDER}/tileset.json",
            "lods": list(self.lods),
            "tiles": self.written,
            "triangles": {f"lod{k}": v for k, v in self.triangles.items()},
            "bytes": {f"lod{k}": v for k, v in self.bytes.items()},
        }

    def _tiles(self, square: Square) -> tuple[Box, list[float]] | None:
        """The square's content box and its tiles' errors, coarse first, once written."""
        return self.records.tiles(square.index, len(self.lods_of(square)))

    def _span(self, square: Square, covered: bool) -> tuple[Box, float] | None:
        """The square's tile as its parent sees it: its box (as written, widened) and
        its geometric error, before :meth:`_tile` raises an error under content; None
        when none of its buildings was built. What :meth:`_tile` needs again is put in
        the square's span record (:class:`SquareRecords`: the box of its content and its
        children's, and their largest error). ``covered``: a square above has content."""
        tiles = self._tiles(square)
        below = covered or tiles is not None
        found = [span for child in self.tree.children(square) if (span := self._span(child, below))]
        if not found and tiles is None:
            return None
        own = [tiles[0]] if tiles is not None else []
        box = _union([*(box for box, _ in found), *own])
        largest = max((error for _, error in found), default=0.0)
        self.records.put_span(square.index, box, largest)
        errors = _errors(box, largest, tiles[1] if tiles is not None else [], covered)
        return _unbox(_box(box)), errors[0]

    def _tile(
        self, square: Square, covered: bool, ceiling: float | None, first: dict[str, Any]
    ) -> dict[str, Any]:
        """The square's tile: its chain of content, coarse first, each the only child of
        the one before, its children's tiles under the last; or, without content, a tile
        holding its children's. The children are made as they are written (an iterator,
        :meth:`_children`), not here. A tile without content under one with content
        (``ceiling``, its error) takes that one's error: a viewer that refined it goes on
        through it to the content below (with a smaller error it would stop there, and
        draw nothing). ``first``: keys the tile starts with (the root's transform)."""
        span = self.records.span(square.index)
        assert span is not None
        tiles = self._tiles(square)
        box = _box(span[0])
        below = covered or tiles is not None
        shown = [c for c in self.tree.children(square) if self.records.span(c.index) is not None]
        errors = _errors(span[0], span[1], tiles[1] if tiles is not None else [], covered)
        if tiles is None:
            error = errors[0] if ceiling is None else ceiling
            return {
                **first,
                "boundingVolume": {"box": box},
                "geometricError": error,
                "refine": "REPLACE",
                "children": self._children(shown, below, ceiling),
            }
        name = _name(square)
        chain = [
            {
                **(first if number == 0 else {}),
                "boundingVolume": {"box": box},
                "geometricError": error,
                "refine": "REPLACE",
                "content": {"uri": f"{name}.lod{lod}.glb"},
            }
            for number, (lod, error) in enumerate(zip(self.lods_of(square), errors, strict=True))
        ]
        if shown:
            chain[-1]["children"] = self._children(shown, below, errors[-1])
        for parent, child in zip(chain[-2::-1], chain[:0:-1], strict=True):
            parent["children"] = iter([child])
        return chain[0]

    def _children(
        self, squares: list[Square], covered: bool, ceiling: float | None
    ) -> Iterator[dict[str, Any]]:
        """The squares' tiles, each made when the one before is written."""
        return (self._tile(child, covered, ceiling, {}) for child in squares)

    def _remove_stale(self) -> None:
        """The tile files in the folder this run did not write (an earlier run's): each
        file's square looked up in the tree by its name, no list of the files kept."""
        for folder, _, files in os.walk(self.folder):  # a folder at a time, none held
            for file in files:
                path = Path(folder) / file
                if TILE_FILE.fullmatch(file) and not self._wrote(path):
                    with contextlib.suppress(FileNotFoundError):
                        path.unlink()

    def _wrote(self, path: Path) -> bool:
        """Whether ``path`` is a tile this run wrote: ``<level>/<column>/<row>.lod<k>.glb``
        of a square holding that tile."""
        parts = path.relative_to(self.folder).parts
        numbers = [*parts[:-1], *parts[-1].split(".")[:1]]
        if len(parts) != 3 or not all(NUMBER.fullmatch(n) for n in numbers):
            return False
        square = self.tree.find(*(int(n) for n in numbers))
        if square is None or self._tiles(square) is None:
            return False
        return int(parts[-1].split(".")[1][3:]) in self.lods_of(square)


def _name(square: Square) -> str:
    """The square's tiles' name: ``<level>/<column>/<row>``."""
    return f"{square.level}/{square.column}/{square.row}"


def _errors(box: Box, below: float, own: Sequence[float], covered: bool) -> list[float]:
    """The geometric errors of a square's tiles (its chain, coarse first, whose own
    errors are ``own``; or its one tile without content, ``own`` empty) before a tile
    above with content raises the latter's: each at least its children's (``below``,
    the largest; ``box``, theirs and its content's); without content, all of it missing
    (the diagonal of its box, at least twice its children's) unless ``covered``."""
    error = below
    if not own:
        if not covered:
            lo, hi = np.array(box[:3]), np.array(box[3:])
            error = max(float(np.linalg.norm(hi - lo)), 2 * error)
        return [round(error, 3)]
    errors = []
    for missed in reversed(own):
        error = max(error, missed)  # at least what the finer tiles get wrong
        errors.append(round(error, 3))
    return errors[::-1]


def _text(value: Any, depth: int) -> Iterator[str]:
    """``value``'s JSON text as ``json.dumps(value, indent=1)`` writes it at ``depth``,
    a piece at a time: a dict key by key, a list given as an iterator (a tile's children)
    an item at a time, each made as it is written; anything else by ``json.dumps``."""
    inside = "\n" + " " * (depth + 1)
    if isinstance(value, dict) and value:
        for number, (key, item) in enumerate(value.items()):
            yield ("{" if number == 0 else ",") + inside + json.dumps(key) + ": "
            yield from _text(item, depth + 1)
        yield "\n" + " " * depth + "}"
    elif isinstance(value, Iterator):
        opened = False
        for item in value:
            yield ("," if opened else "[") + inside
            yield from _text(item, depth + 1)
            opened = True
        yield "\n" + " " * depth + "]" if opened else "[]"
    else:
        yield json.dumps(value, indent=1).replace("\n", "\n" + " " * depth)


def _batched(chunks: Iterable[str], size: int = 1 << 16) -> Iterator[bytes]:
    """The text's pieces as UTF-8 bytes, gathered into writes of about ``size``."""
    held: list[str] = []
    length = 0
    for chunk in chunks:
        held.append(chunk)
        length += len(chunk)
        if length >= size:
            yield "".join(held).encode("utf-8")
            held, length = [], 0
    if held:
        yield "".join(held).encode("utf-8")


def _lod_scene(
    buildings: list[dict[str, trimesh.Trimesh]],
) -> tuple[trimesh.Scene, list[Box | None]]:
    """A tile's buildings at one LOD as one mesh a material (two draw calls at most), and
    each building's box (None when it has no surface at this LOD)."""
    scene = trimesh.Scene()
    boxes: list[Box | None] = []
    for meshes in buildings:
        points = np.vstack([np.zeros((0, 3)), *(m.vertices for m in meshes.values())])
        found = _z_up(points.min(axis=0), points.max(axis=0)) if len(points) else None
        boxes.append(found)
    for name in sorted({name for meshes in buildings for name in meshes}):
        parts = [m[name] for m in buildings if name in m and len(m[name].faces)]
        if not parts:
            continue
        merged = dressed({name: trimesh.util.concatenate(parts)})[name]
        scene.add_geometry(merged, geom_name=name, node_name=name)
    return scene, boxes


def _glb_boxes(paths: Iterable[Path]) -> list[Box]:
    """Each glb's box (z up) from its positions' bounds (nodes carry no transforms but
    the instances of ``EXT_mesh_gpu_instancing``: their meshes' boxes placed at each)."""
    boxes = []
    for path in paths:
        document, chunk = read_glb(path.read_bytes())
        accessors = document.get("accessors", [])
        instanced = _instances(document, chunk)
        lows, highs = [], []
        for index, mesh in enumerate(document.get("meshes", [])):
            for primitive in mesh["primitives"]:
                accessor = accessors[primitive["attributes"]["POSITION"]]
                low, high = np.asarray(accessor["min"]), np.asarray(accessor["max"])
                for matrix in instanced.get(index, [np.eye(4)]):
                    corners = np.array(
                        [
                            (x, y, z, 1.0)
                            for x in (low[0], high[0])
                            for y in (low[1], high[1])
                            for z in (low[2], high[2])
                        ]
                    )
                    placed = (corners @ matrix.T)[:, :3]
                    lows.append(placed.min(axis=0))
                    highs.append(placed.max(axis=0))
        boxes.append(_z_up(np.min(lows, axis=0), np.max(highs, axis=0)))
    return boxes


def _instances(document: dict[str, Any], chunk: bytes) -> dict[int, list[np.ndarray]]:
    """The placements of each mesh an ``EXT_mesh_gpu_instancing`` node draws."""
    found: dict[int, list[np.ndarray]] = {}
    for node in document.get("nodes", []):
        if "mesh" in node and EXTENSION in node.get("extensions", {}):
            for row in placements(document, chunk, node):
                t, r, scale = row[:3], row[3:7], row[7:10]
                matrix = node_matrix({"translation": t, "rotation": r, "scale": scale})
                found.setdefault(node["mesh"], []).append(matrix)
    return found


def _glb_triangles(path: Path) -> int:
    """A glb's triangles as drawn (an instanced mesh's once per instance)."""
    document, chunk = read_glb(path.read_bytes())
    accessors = document.get("accessors", [])
    instanced = _instances(document, chunk)
    return sum(
        accessors[p["indices"]]["count"] // 3 * len(instanced.get(index, [None]))
        for index, mesh in enumerate(document.get("meshes", []))
        for p in mesh["primitives"]
    )


def _z_up(low: np.ndarray, high: np.ndarray) -> Box:
    """A glTF box (x east, y up, z south) in the tiles' frame (x east, y north, z up)."""
    return (
        float(low[0]),
        -float(high[2]),
        float(low[1]),
        float(high[0]),
        -float(low[2]),
        float(high[1]),
    )


def _union(boxes: Iterable[Box]) -> Box:
    found = np.array(list(boxes))
    (x0, y0, z0), (x1, y1, z1) = found[:, :3].min(axis=0), found[:, 3:].max(axis=0)
    return (float(x0), float(y0), float(z0), float(x1), float(y1), float(z1))


def _outside(outer: Box, inner: Box) -> float:
    """How far ``outer`` reaches beyond ``inner`` on any side (metres)."""
    return max(
        0.0, *(inner[i] - outer[i] for i in range(3)), *(outer[i] - inner[i] for i in range(3, 6))
    )


def _box(box: Box) -> list[float]:
    """A 3D Tiles box: centre and half-axes, widened to the millimetre outwards."""
    low = [math.floor(v * 1000) / 1000 for v in box[:3]]
    high = [math.ceil(v * 1000) / 1000 for v in box[3:]]
    centre = [round((a + b) / 2, 4) for a, b in zip(low, high, strict=True)]
    half = [round(max((b - a) / 2, 0.001) + 0.0005, 4) for a, b in zip(low, high, strict=True)]
    return [*centre, half[0], 0.0, 0.0, 0.0, half[1], 0.0, 0.0, 0.0, half[2]]


def _unbox(box: list[float]) -> Box:
    (x, y, z), (a, b, c) = box[:3], (box[3], box[7], box[11])
    return (x - a, y - b, z - c, x + a, y + b, z + c)
