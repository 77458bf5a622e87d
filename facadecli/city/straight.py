"""Near-collinear footprint nodes merged, so that one straight wall is one façade.

Mappers often draw a straight wall with extra nodes on it (where a neighbour's wall
meets it, where an address point or an entrance was, or from tracing). Left as they are,
each node starts a new façade and its bay rhythm restarts there. Before the façades are
laid, a run of edges becomes one edge (its first node to its last) when no two of its
edges differ in direction by ``angle`` degrees or more: measuring every pair, not each
edge against the next, keeps a gentle curve (a round tower's many short edges) a curve.

A node is kept, whatever its angle, where another footprint has a vertex within
``near`` metres: the end of a party wall, a neighbour's corner, a part's corner on its
outline. So a wall that is blind along a neighbour and free past it keeps the node
between. A ring is kept as it was if merging would leave it invalid or under three
nodes. Pure functions of the footprints.
"""

from __future__ import annotations

import math
from array import array
from bisect import bisect_left, bisect_right
from collections.abc import Callable, Container, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from facadecli.city.footprints import Footprint

ANGLE = 3.0  # degrees: edges this close to their run's chord are one wall (the default)
CELL = 1.0  # metres: the side of the grid's cells that finds the vertices near a node

Point = tuple[float, float]
Kept = Callable[[Point], bool]


@dataclass(frozen=True)
class Straightened:
    """What merging did: the footprints, and how many nodes it took out of how many."""

    footprints: tuple[Footprint, ...]
    nodes: int  # nodes taken out
    footprints_changed: int  # footprints with at least one node taken out


def straighten(
    footprints: Sequence[Footprint],
    angle: float,
    near: float,
    counted: Container[str] | None = None,
) -> Straightened:
    """Every footprint with its near-collinear nodes merged (see the module); ``angle``
    0 leaves them all as they are. With ``counted`` (ids), the nodes and footprints
    counted are those footprints' alone (a region of a town, the others its neighbours)."""
    if angle <= 0 or not footprints:
        return Straightened(tuple(footprints), 0, 0)
    corners = Corners(footprints, max(CELL, near))
    done: list[Footprint] = []
    taken = changed = 0
    for footprint in footprints:

        def shared(point: Point, me: str = footprint.id) -> bool:
            """Another footprint has a vertex within ``near`` of the point."""
            return corners.near(point, near, me)

        parts = []
        before = taken
        for part in footprint.parts:
            merged, count = _part(part, angle, shared)
            parts.append(merged)
            taken += count
        if taken > before:
            done.append(replace(footprint, parts=tuple(parts)))
            if counted is not None and footprint.id not in counted:
                taken = before
            else:
                changed += 1
        else:
            done.append(footprint)
    return Straightened(tuple(done), taken, changed)


BATCH = 1024  # rings whose vertices are joined into one array each (Corners)


class Corners:
    """Every footprint's vertices, by the footprint they are of, found by a grid: flat
    arrays (28 bytes a vertex), not a shapely point (and a tuple) each, which for a
    city's vertices was most of what planning held at its peak."""

    def __init__(self, footprints: Sequence[Footprint], cell: float = CELL):
        self.ids = [footprint.id for footprint in footprints]
        xs, ys, owners = [], [], []  # a batch's arrays, joined at its end
        batch: list[tuple[Any, Any, Any]] = []  # a ring's arrays (three objects a ring)
        for number, footprint in enumerate(footprints):
            for part in footprint.parts:
                for ring in (part.exterior, *part.interiors):
                    coords = shapely.get_coordinates(ring)[:-1]
                    owner = np.full(len(coords), number, dtype=np.int32)
                    batch.append((coords[:, 0], coords[:, 1], owner))
            if batch and (len(batch) >= BATCH or number == len(footprints) - 1):
                xs.append(np.concatenate([ring[0] for ring in batch]))
                ys.append(np.concatenate([ring[1] for ring in batch]))
                owners.append(np.concatenate([ring[2] for ring in batch]))
                batch = []
        x = np.concatenate(xs) if xs else np.zeros(0)
        y = np.concatenate(ys) if ys else np.zeros(0)
        del xs, ys
        extent = float(np.ptp(x) + np.ptp(y)) if len(x) else 0.0
        self.cell = max(cell, extent / 2**30)  # keys (column x rows + row) fit 63 bits
        columns, rows = self._cells(x, y)
        self.left = int(columns.min(initial=0)) - 1
        self.bottom = int(rows.min(initial=0)) - 1
        self.height = int(rows.max(initial=0)) - self.bottom + 2  # rows a column
        keys = (columns - self.left) * self.height + (rows - self.bottom)
        order = np.argsort(keys, kind="stable")
        self.keys = array("q", keys[order].tobytes())
        self.xs = array("d", x[order].tobytes())
        self.ys = array("d", y[order].tobytes())
        owner = np.concatenate(owners) if owners else np.zeros(0, dtype=np.int32)
        self.owners = array("i", owner[order].astype(np.int32).tobytes())

    def _cells(self, x: Any, y: Any) -> tuple[Any, Any]:
        return np.floor(x / self.cell).astype(np.int64), np.floor(y / self.cell).astype(np.int64)

    def near(self, point: Point, distance: float, me: str) -> bool:
        """Has a footprint other than ``me`` (an id) a vertex within ``distance`` of
        ``point``? Every vertex of the cells the square around it covers is measured."""
        x0, y0 = point[0] - distance, point[1] - distance
        x1, y1 = point[0] + distance, point[1] + distance
        first, last = math.floor(x0 / self.cell), math.floor(x1 / self.cell)
        low = math.floor(y0 / self.cell) - self.bottom
        high = math.floor(y1 / self.cell) - self.bottom
        for column in range(first - self.left, last - self.left + 1):
            start = bisect_left(self.keys, column * self.height + low)
            end = bisect_right(self.keys, column * self.height + high)
            for i in range(start, end):
                x, y = self.xs[i], self.ys[i]
                if self.ids[self.owners[i]] == me or not (x0 <= x <= x1 and y0 <= y <= y1):
                    continue
                if math.dist((x, y), point) <= distance:
                    return True
        return False


def _part(part: Polygon, angle: float, shared: Kept) -> tuple[Polygon, int]:
    rings = [list(ring.coords)[:-1] for ring in (part.exterior, *part.interiors)]
    kept = [merged_ring([(p[0], p[1]) for p in ring], angle, shared) for ring in rings]
    count = sum(len(a) - len(b) for a, b in zip(rings, kept, strict=True))
    if count == 0:
        return part, 0
    merged = Polygon(kept[0], kept[1:])
    if not merged.is_valid or merged.is_empty:
        return part, 0
    return orient(merged, sign=1.0), count


def merged_ring(ring: list[Point], angle: float, shared: Kept | None = None) -> list[Point]:
    """A closed ring's nodes (without the closing repeat) less those inside runs of edges
    within ``angle`` degrees of their chord; ``shared(point)`` says a node must stay."""
    size = len(ring)
    if size <= 3:
        return ring
    must = [shared is not None and shared(p) for p in ring]
    limit = math.radians(angle)
    # start at a node that surely stays: a kept one, else the sharpest corner
    starts = [i for i in range(size) if must[i]]
    start = starts[0] if starts else max(range(size), key=lambda i: (_turn(ring, i), -i))
    order = [ring[(start + k) % size] for k in range(size)] + [ring[start]]
    keep = [must[(start + k) % size] for k in range(size)] + [True]
    result = [order[0]]
    i = 0
    while i < size:
        j = i + 1  # the run i..j is one wall while every edge lies along its chord
        while j < size and not keep[j] and _straight(order, i, j + 1, limit):
            j += 1
        result.append(order[j])
        i = j
    result.pop()  # the closing repeat of the start
    return result if len(result) >= 3 else ring


def _turn(ring: list[Point], i: int) -> float:
    a, b, c = ring[i - 1], ring[i], ring[(i + 1) % len(ring)]
    return abs(_apart(_bearing(a, b), _bearing(b, c)))


def _bearing(a: Point, b: Point) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])


def _apart(one: float, other: float) -> float:
    return (one - other + math.pi) % (2 * math.pi) - math.pi


def _straight(points: list[Point], i: int, j: int, limit: float) -> bool:
    """Do the edges from node i to node j all run within ``limit`` of each other?"""
    turns = [
        _apart(_bearing(points[k], points[k + 1]), _bearing(points[i], points[i + 1]))
        for k in range(i, j)
        if math.dist(points[k], points[k + 1]) > 1e-9
    ]
    return bool(turns) and max(turns) - min(turns) < limit
