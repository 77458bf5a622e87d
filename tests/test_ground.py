"""The viewer's ground rules (facadecli.viewer.ground's GROUND, JavaScript) run in node over
plans drawn from generated footprints with known answers: what each place is, where the
centre-line dashes and the street lamps stand. The browser tests (test_viewer.py) check
the page draws them."""

from __future__ import annotations

import json
import random
import shutil
import subprocess
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from facadecli.viewer.ground import GROUND
from facadecli.viewer.landcover import COVER

pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")

CELL = 0.5  # metres a cell of the plans below
MARGIN = 14  # metres of town round a plan, as the viewer's GROUND_MARGIN

# the kinds groundKinds gives a cell
BUILDING, PAVEMENT, KERB, ASPHALT, GRASS = range(5)

DRIVER = """
const plan = JSON.parse(require('fs').readFileSync(0, 'utf8'));
const built = Uint8Array.from(plan.built);
const ground = groundKinds(built, plan.columns, plan.rows, plan.cell);
const dashes = dashCells(ground, plan.columns, plan.rows, plan.cell);
const trees = treeCells(ground, plan.columns, plan.cell);
const lamps = lampCells(ground, plan.columns, plan.rows, plan.cell, trees);
const benches = benchCells(ground, plan.columns, plan.rows, plan.cell,
                           [...trees, ...lamps.map(([at]) => at)]);
const kindsAt = places => places.map(at => ground.kinds[at]);
console.log(JSON.stringify({kinds: Array.from(ground.kinds), dashes, lamps, trees, benches,
                            treeKinds: kindsAt(trees),
                            benchKinds: kindsAt(benches.map(([at]) => at))}));
"""

Box = tuple[float, float, float, float]  # x0, y0, x1, y1 in metres


@dataclass(frozen=True)
class Ground:
    """A plan's ground as GROUND makes it: the kind of each cell (rows from the top), the
    dashes, the lamps and the benches (x, y in metres, then the way they face: x, y), the
    trees, and the kind of ground each tree and each bench stands on."""

    kinds: np.ndarray
    dashes: list[tuple[float, float, float, float]]
    lamps: list[tuple[float, float, float, float]]
    trees: list[tuple[float, float]]
    benches: list[tuple[float, float, float, float]]
    tree_kinds: list[int]
    bench_kinds: list[int]

    def inner(self) -> np.ndarray:
        """The plan's cells, not the town's margin round it."""
        return self.kinds[_cells(MARGIN) : -_cells(MARGIN), _cells(MARGIN) : -_cells(MARGIN)]

    def share(self, kind: int) -> float:
        """Of the plan's open ground."""
        return float((self.inner() == kind).sum() / (self.inner() != BUILDING).sum())

    def area(self, kind: int) -> float:
        """m² of the plan."""
        return float((self.inner() == kind).sum() * CELL * CELL)


def _cells(metres: float) -> int:
    return round(metres / CELL)


def _ground(buildings: list[Box]) -> Ground:
    """GROUND over the plan of ``buildings`` (a cell's centre inside a box is built), with
    MARGIN metres of town round them; places in metres from the plan's lower left."""
    xs = [x for b in buildings for x in (b[0], b[2])]
    ys = [y for b in buildings for y in (b[1], b[3])]
    left, bottom = min(xs) - MARGIN, min(ys) - MARGIN
    columns = _cells(max(xs) + MARGIN - left)
    rows = _cells(max(ys) + MARGIN - bottom)
    x = left + (np.arange(columns) + 0.5) * CELL
    y = bottom + (rows - np.arange(rows) - 0.5) * CELL  # row 0 at the top
    built = np.zeros((rows, columns), dtype=np.uint8)
    for x0, y0, x1, y1 in buildings:
        built[np.ix_((y > y0) & (y < y1), (x > x0) & (x < x1))] = 1
    plan = {"columns": columns, "rows": rows, "cell": CELL, "built": built.ravel().tolist()}
    done = subprocess.run(
        ["node", "-e", GROUND + DRIVER],
        input=json.dumps(plan),
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    found: dict[str, Any] = json.loads(done.stdout)

    def place(at: int) -> tuple[float, float]:
        return float(x[at % columns]), float(y[at // columns])

    return Ground(
        np.array(found["kinds"], dtype=np.uint8).reshape(rows, columns),
        [(*place(at), across, -down) for at, across, down in found["dashes"]],
        [(*place(at), across, -down) for at, across, down in found["lamps"]],
        [place(at) for at in found["trees"]],
        [(*place(at), across, -down) for at, across, down in found["benches"]],
        found["treeKinds"],
        found["benchKinds"],
    )


def _blocks(seed: int, street: float) -> tuple[list[Box], list[Box], float]:
    """A town of 3 x 3 blocks, each a row of terraced houses round its edge (depth 10 m)
    round a courtyard, seeded sizes, ``street`` metres between blocks. Returns the
    buildings, the junctions (the squares where two streets cross) and the courtyards'
    lawn inside their 1 m paths (m²)."""
    chance = random.Random(seed)
    wide = [chance.uniform(40, 60) for _ in range(3)]
    deep = [chance.uniform(36, 50) for _ in range(3)]
    lefts = [sum(wide[:i]) + i * street for i in range(3)]
    bottoms = [sum(deep[:j]) + j * street for j in range(3)]
    buildings = []
    for i in range(3):
        for j in range(3):
            x0, y0, x1, y1 = lefts[i], bottoms[j], lefts[i] + wide[i], bottoms[j] + deep[j]
            buildings += [(x0, y0, x1, y0 + 10), (x0, y1 - 10, x1, y1)]
            buildings += [(x0, y0 + 10, x0 + 10, y1 - 10), (x1 - 10, y0 + 10, x1, y1 - 10)]
    junctions = [
        (lefts[i] + wide[i], bottoms[j] + deep[j], lefts[i + 1], bottoms[j + 1])
        for i in range(2)
        for j in range(2)
    ]
    lawn = sum((w - 22) * (d - 22) for w in wide for d in deep)
    return buildings, junctions, lawn


def _houses(seed: int, sides: tuple[float, float] = (8, 14)) -> list[Box]:
    """A sparse town: 100 detached houses, ``sides`` metres a side, on a grid 45 m apart,
    each moved up to 8 m (seeded): lawns round them, as Kotka has."""
    chance = random.Random(seed)
    houses = []
    for i in range(10):
        for j in range(10):
            x, y = i * 45 + chance.uniform(-8, 8), j * 45 + chance.uniform(-8, 8)
            houses.append((x, y, x + chance.uniform(*sides), y + chance.uniform(*sides)))
    return houses


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_sparse_towns_open_land_is_lawn_and_a_dense_towns_is_street(seed: int) -> None:
    """Open land no walls close in is grass (detached houses 45 m apart stood in paving:
    every place over 12 m from a wall was a paved square, Kotka's 97% of its open ground);
    a town of closed blocks keeps its streets asphalt and its courtyards alone green."""
    sparse = _ground(_houses(seed))
    assert sparse.share(GRASS) > 0.6, sparse.share(GRASS)
    buildings, _, courtyards = _blocks(seed, 16)
    dense = _ground(buildings)
    assert dense.area(GRASS) == pytest.approx(courtyards, rel=0.1)  # within their paths
    assert dense.share(ASPHALT) > 0.25


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_street_lamps_stand_on_the_pavements_30_m_apart_their_arms_over_the_road(
    seed: int,
) -> None:
    """Lamps along every street of a town of blocks: on the pavement short of the kerb
    (1.9 m from the walls on a 2.5 m pavement, 3.9 m on a wide one), at least 30 m apart,
    clear of the trees, none in a courtyard, each facing the road (away from its wall)."""
    from shapely.geometry import Point, box

    buildings, _, _ = _blocks(seed, 16)
    ground = _ground(buildings)
    walls = [box(*b) for b in buildings]
    courtyards = [
        box(b[2], b[1], c[0], c[3]) for b, c in zip(buildings[2::4], buildings[3::4], strict=True)
    ]
    assert len(ground.lamps) >= 12
    for x, y, towards_x, towards_y in ground.lamps:
        at = Point(x, y)
        distance = min(wall.distance(at) for wall in walls)
        assert 1.9 - CELL <= distance <= 3.9 + CELL
        assert not any(courtyard.contains(at) for courtyard in courtyards)
        assert all(Point(tree).distance(at) >= 3 - CELL for tree in ground.trees)
        ahead = Point(x + 2 * towards_x, y + 2 * towards_y)
        assert min(wall.distance(ahead) for wall in walls) > distance + 1
    for index, (x, y, *_) in enumerate(ground.lamps):
        for other in ground.lamps[index + 1 :]:
            assert np.hypot(other[0] - x, other[1] - y) >= 30 - CELL


@pytest.mark.parametrize("seed", [7, 8, 9])
def test_centre_line_dashes_stop_before_each_junction(seed: int) -> None:
    """Dashes run down the middle of every street between junctions and stop before each
    junction (the square where two streets cross): none reaches into it (they crossed
    it where the crossing's middle ran straight for a dash's length)."""
    from shapely.geometry import LineString, box

    buildings, junctions, _ = _blocks(seed, 16)
    ground = _ground(buildings)
    crossings = [box(*junction) for junction in junctions]
    assert len(ground.dashes) >= 12
    for x, y, along_x, along_y in ground.dashes:
        half = 1.5  # a dash is 3 m long
        dash = LineString([(x - half * along_x, y - half * along_y),
                           (x + half * along_x, y + half * along_y)])  # fmt: skip
        assert not any(dash.intersects(crossing) for crossing in crossings), (x, y)


def _wall_distance(buildings: list[Box], x: float, y: float) -> float:
    from shapely.geometry import Point, box

    return min(box(*b).distance(Point(x, y)) for b in buildings)


@pytest.mark.parametrize("seed", [10, 11, 12])
def test_trees_stand_on_lawn_or_in_pits_along_roads_never_on_the_paving_round_a_house(
    seed: int,
) -> None:
    """A tree stands on a lawn, 6 m or more from the walls, or in a pit on a street's wide
    pavement with the road past its kerb, where the pavement runs straight for 14 m;
    never in a road or on a kerb. Small detached houses (7-10 m a side) in their lawns
    keep no tree on the ring of paving round them (each had four or five there, 3.4 m
    from its walls); a town of closed blocks keeps its street trees in pits."""
    from shapely.geometry import Point, box

    houses = _houses(seed, (7, 10))
    sparse = _ground(houses)
    assert len(sparse.trees) >= 100
    for (x, y), kind in zip(sparse.trees, sparse.tree_kinds, strict=True):
        assert kind == GRASS and _wall_distance(houses, x, y) >= 6 - CELL, (x, y, kind)
    buildings, _, _ = _blocks(seed, 16)
    dense = _ground(buildings)
    roads = [
        (x, y)
        for (x, y), kind in zip(dense.trees, dense.tree_kinds, strict=True)
        if kind == PAVEMENT
    ]
    assert len(roads) >= 20
    asphalt = np.argwhere(dense.kinds == ASPHALT)
    for (x, y), kind in zip(dense.trees, dense.tree_kinds, strict=True):
        assert kind in (PAVEMENT, GRASS)
        assert _wall_distance(buildings, x, y) >= (3 if kind == PAVEMENT else 6) - CELL
    # each pit's road: asphalt within 1.3 m (the pavement's 1.1 m left and the kerb)
    left = min(b[0] for b in buildings) - MARGIN
    top = max(b[3] for b in buildings) + MARGIN
    for x, y in roads:
        row, column = (top - y) / CELL - 0.5, (x - left) / CELL - 0.5
        nearest = np.hypot(asphalt[:, 0] - row, asphalt[:, 1] - column).min() * CELL
        assert nearest <= 1.3 + CELL, (x, y, nearest)
    courtyards = [
        box(b[2], b[1], c[0], c[3]) for b, c in zip(buildings[2::4], buildings[3::4], strict=True)
    ]
    assert not any(c.contains(Point(tree)) for c in courtyards for tree in dense.trees)


@pytest.mark.parametrize("seed", [13, 14, 15])
def test_a_road_meets_a_lawn_at_a_kerb(seed: int) -> None:
    """Where the enclosure turns a road into lawn, a kerb lies between them: no asphalt
    cell has a grass cell beside it (the asphalt ran into the grass with no edge)."""
    ground = _ground(_houses(seed))
    kinds = ground.kinds
    asphalt = kinds == ASPHALT
    assert asphalt.sum() > 1000 and (kinds == GRASS).sum() > 1000
    beside = np.zeros_like(asphalt)
    beside[1:] |= kinds[:-1] == GRASS
    beside[:-1] |= kinds[1:] == GRASS
    beside[:, 1:] |= kinds[:, :-1] == GRASS
    beside[:, :-1] |= kinds[:, 1:] == GRASS
    assert not (asphalt & beside).any(), int((asphalt & beside).sum())


@pytest.mark.parametrize("seed", [16, 17, 18])
def test_benches_stand_on_paving_at_a_lawns_edge_facing_it(seed: int) -> None:
    """Benches along the paving where a lawn opens before it: on paving, 2.5 m or more
    from the walls, no road within 4 m, facing the lawn (3 m ahead is grass), 40 m apart
    and 2.5 m clear of the trees and lamps. The lawns are the public ones between blocks
    50 m apart (a detached house's are its garden's, where no bench stands:
    test_detached_houses_stand_in_gardens_with_a_drive_each)."""
    houses, _, _ = _blocks(seed, 50)
    ground = _ground(houses)
    assert len(ground.benches) >= 12
    left = min(b[0] for b in houses) - MARGIN
    top = max(b[3] for b in houses) + MARGIN
    asphalt = np.argwhere(ground.kinds == ASPHALT)

    def kind(x: float, y: float) -> int:
        return int(ground.kinds[int((top - y) / CELL), int((x - left) / CELL)])

    for (x, y, ahead_x, ahead_y), under in zip(ground.benches, ground.bench_kinds, strict=True):
        assert under == PAVEMENT
        wall = _wall_distance(houses, x, y)
        assert wall >= 2.5 - CELL
        row, column = (top - y) / CELL - 0.5, (x - left) / CELL - 0.5
        assert np.hypot(asphalt[:, 0] - row, asphalt[:, 1] - column).min() * CELL > 4 - CELL
        assert kind(x + 3 * ahead_x, y + 3 * ahead_y) == GRASS
        others = [*ground.trees, *((lx, ly) for lx, ly, *_ in ground.lamps)]
        assert all(np.hypot(ox - x, oy - y) >= 2.5 - CELL for ox, oy in others)
    for index, (x, y, *_) in enumerate(ground.benches):
        for other in ground.benches[index + 1 :]:
            assert np.hypot(other[0] - x, other[1] - y) >= 40 - CELL


# The land cover on the plan (facadecli.viewer.landcover's COVER, after GROUND's besideKind)
COVER_DRIVER = """
const plan = JSON.parse(require('fs').readFileSync(0, 'utf8'));
const cover = coverCells(plan.polygons, plan.columns, plan.rows);
const trees = coverTreeCells(cover, Float32Array.from(plan.near), plan.columns, plan.rows,
                             plan.cell);
console.log(JSON.stringify({cover: Array.from(cover), trees}));
"""
WOOD, PARK, WATER = 1, 3, 7  # COVER_KINDS' codes


def _cover(
    polygons: list[dict[str, Any]], columns: int, rows: int, near: np.ndarray | None = None
) -> tuple[np.ndarray, list[int]]:
    """COVER over a plan of ``columns`` x ``rows`` cells of CELL metres: each cell's kind
    (rows from the top), and the trees' cells; ``near``: the distance to the buildings in
    cells (none: far from any)."""
    far = np.full(columns * rows, 1e9) if near is None else near.ravel()
    plan = {"polygons": polygons, "columns": columns, "rows": rows, "cell": CELL}
    done = subprocess.run(
        ["node", "-e", GROUND + COVER + COVER_DRIVER],
        input=json.dumps({**plan, "near": far.tolist()}),
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    found: dict[str, Any] = json.loads(done.stdout)
    return np.array(found["cover"], dtype=np.uint8).reshape(rows, columns), found["trees"]


def _square(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_ponds_island_is_the_park_round_it_and_water_lies_over_the_park(seed: int) -> None:
    """Scanlines fill what each polygon holds (a ring's hole not), a later kind over an
    earlier one whatever the order given: the pond's cells are its area less its island,
    the island is the park's, nothing outside the park is covered."""
    chance = random.Random(seed)
    x0, y0 = chance.uniform(5, 15), chance.uniform(5, 15)
    w, d = chance.uniform(100, 160), chance.uniform(100, 160)  # cells
    px, py, pw = x0 + chance.uniform(10, 30), y0 + chance.uniform(10, 30), chance.uniform(30, 50)
    island = _square(px + pw / 2 - 5, py + pw / 2 - 5, px + pw / 2 + 5, py + pw / 2 + 5)
    polygons = [
        {"kind": "water", "rings": [_square(px, py, px + pw, py + pw), island]},
        {"kind": "park", "rings": [_square(x0, y0, x0 + w, y0 + d)]},
        {"kind": "moor", "rings": [_square(0, 0, 200, 200)]},  # no kind drawn: left out
    ]
    cover, _ = _cover(polygons, 200, 200)
    water = int((cover == WATER).sum())
    assert water == pytest.approx(pw * pw - 100, abs=4 * pw)  # within a cell of the edges
    assert cover[int(py + pw / 2), int(px + pw / 2)] == PARK  # the island
    assert int((cover > 0).sum()) == pytest.approx(w * d, abs=2 * (w + d) + 4)
    assert cover[int(y0 + d) + 2, int(x0 + w) + 2] == 0


@pytest.mark.parametrize("seed", [1, 2])
def test_trees_stand_in_woods_and_parks_never_on_water_nor_by_a_building(seed: int) -> None:
    """A wood (west half) has a tree about every WOOD_EVERY (4.5 m), the park (east half)
    fewer; none on the pond or within TREE_CLEAR (2.5 m) of it, none within 2.5 m of the
    house standing in the wood; seeded lattice: the same trees each time."""
    chance = random.Random(seed)
    columns = rows = 240  # 120 m
    middle = chance.uniform(100, 140)
    pond = [chance.uniform(150, 170), chance.uniform(60, 120)]
    house = (chance.uniform(20, 60), chance.uniform(20, 60))  # 16 x 16 cells
    polygons = [
        {"kind": "wood", "rings": [_square(0, 0, middle, rows)]},
        {"kind": "park", "rings": [_square(middle, 0, columns, rows)]},
        {"kind": "water", "rings": [_square(pond[0], pond[1], pond[0] + 40, pond[1] + 40)]},
    ]
    ys, xs = np.mgrid[0:rows, 0:columns] + 0.5
    dx = np.maximum(np.maximum(house[0] - xs, xs - house[0] - 16), 0)
    dy = np.maximum(np.maximum(house[1] - ys, ys - house[1] - 16), 0)
    near = np.hypot(dx, dy)
    cover, trees = _cover(polygons, columns, rows, near)
    assert trees == _cover(polygons, columns, rows, near)[1]
    kinds = [int(cover.ravel()[at]) for at in trees]
    assert set(kinds) <= {WOOD, PARK}
    in_wood = kinds.count(WOOD) / ((middle * rows - 256) * CELL * CELL)
    in_park = kinds.count(PARK) / (((columns - middle) * rows - 1600) * CELL * CELL)
    assert in_wood == pytest.approx(1 / 4.5**2, rel=0.35)
    assert in_park < in_wood / 4
    water_rows, water_columns = np.nonzero(cover == WATER)
    for at in trees:
        row, column = divmod(at, columns)
        nearest = np.hypot(water_rows - row, water_columns - column).min() * CELL
        assert nearest >= 2.5
        assert near[row, column] * CELL >= 2.5


def _band(houses: list[Box], kinds: np.ndarray, near: float, far: float) -> list[np.ndarray]:
    """The kinds of the cells from ``near`` to ``far`` metres round each house (of a plan
    drawn by _ground; the nearest house's, others' cells left out)."""
    rows, columns = kinds.shape
    left = min(b[0] for b in houses) - MARGIN
    top = max(b[3] for b in houses) + MARGIN
    x = left + (np.arange(columns) + 0.5) * CELL
    y = top - (np.arange(rows) + 0.5) * CELL
    bands = []
    for x0, y0, x1, y1 in houses:
        dx = np.maximum(np.maximum(x0 - x, x - x1), 0)[None, :]
        dy = np.maximum(np.maximum(y0 - y, y - y1), 0)[:, None]
        distance = np.hypot(dx, dy)
        bands.append(kinds[(distance >= near) & (distance < far)])
    return bands


@pytest.mark.parametrize("seed", [19, 20, 21])
def test_detached_houses_stand_in_gardens_with_a_drive_each(seed: int) -> None:
    """A town of detached houses has streets between blocks of houses, each house in its
    garden with a drive to the street (on main a ring of paving, then a ring road, round
    every house: 4 m round each was paving and asphalt): from 1.5 to 4 m round a house
    mostly lawn, its drive across it; each house's drive reaches a road's asphalt over
    paving alone; the street lamps along the roads, no bench in a garden."""
    from scipy.ndimage import label

    houses = _houses(seed)
    ground = _ground(houses)
    bands = _band(houses, ground.kinds, 1.5, 4)
    lawn = [float((band == GRASS).mean()) for band in bands]
    assert min(lawn) > 0.5 and float(np.mean(lawn)) > 0.75, (min(lawn), np.mean(lawn))
    assert float(np.mean([(band == ASPHALT).mean() for band in bands])) < 0.02
    paved, _ = label(np.isin(ground.kinds, (PAVEMENT, KERB, ASPHALT)))
    for house, band in zip(houses, _band(houses, paved, 0, 1), strict=True):
        ways = set(band[band > 0].tolist())
        assert (ground.kinds[np.isin(paved, list(ways))] == ASPHALT).any(), house
    assert (ground.kinds == ASPHALT).mean() > 0.08  # streets, not lanes
    assert len(ground.lamps) >= 40 and not ground.benches


def _clusters(seed: int, count: int = 4) -> list[Box]:
    """Clusters of six detached houses (three by two, 22-24 m apart, 8-12 m a side), each
    cluster 110 m or more from every other (seeded places): blocks of houses more than
    30 m from any other block, as Kotka's outlying ones."""
    chance = random.Random(seed)
    centres: list[tuple[float, float]] = []
    while len(centres) < count:
        x, y = chance.uniform(0, 260), chance.uniform(0, 260)
        if all(np.hypot(x - ox, y - oy) >= 110 for ox, oy in centres):
            centres.append((x, y))
    houses = []
    for cx, cy in centres:
        for i in range(3):
            for j in range(2):
                x, y = cx + i * 22 + chance.uniform(-3, 3), cy + j * 24 + chance.uniform(-3, 3)
                houses.append((x, y, x + chance.uniform(8, 12), y + chance.uniform(8, 12)))
    return houses


def _reaches_asphalt(houses: list[Box], ground: Ground) -> list[bool]:
    """Whether each house reaches a road's asphalt over paving alone (its drive)."""
    from scipy.ndimage import label

    paved, _ = label(np.isin(ground.kinds, (PAVEMENT, KERB, ASPHALT)))
    reached = []
    for band in _band(houses, paved, 0, 1):
        ways = set(band[band > 0].tolist())
        reached.append(bool((ground.kinds[np.isin(paved, list(ways))] == ASPHALT).any()))
    return reached


@pytest.mark.parametrize("seed", [22, 23, 24])
def test_clusters_of_houses_far_apart_are_joined_by_one_network_of_streets(seed: int) -> None:
    """Clusters of houses more than 30 m from any other block each get an access road,
    joined into one network (on main a cluster that was one block had no road at all,
    and the roads there were were pieces): the asphalt is one piece (eight neighbours),
    some house of every cluster reaches it over its drive, and nine in ten houses do
    (a drive from the access road's end runs 100 m at most, down the distance to the
    walls, which can lead it to a neighbour)."""
    from scipy.ndimage import label

    houses = _clusters(seed)
    ground = _ground(houses)
    _, pieces = label(ground.kinds == ASPHALT, structure=np.ones((3, 3)))
    assert pieces == 1, pieces
    reached = _reaches_asphalt(houses, ground)
    assert all(any(reached[k : k + 6]) for k in range(0, len(houses), 6)), reached
    assert sum(reached) >= 0.9 * len(houses), reached


ROUND = 7.0  # metres: the circle round a road's cell that tells an end (_road_ends)


def _road_ends(ground: Ground) -> list[tuple[int, int, float]]:
    """The ends of the roads: cells of a road's core (asphalt 2 m or more from its edge)
    round which a circle of ROUND metres meets the core in one arc alone (along a road
    two, at a junction three or more), and the widest asphalt within ROUND of each
    (metres from its edge: a road's middle about 3, a turning head's 6); those within
    ROUND + 2 of the plan's edge left out (a road going on into the town)."""
    from scipy.ndimage import distance_transform_edt

    asphalt = ground.kinds == ASPHALT
    width = distance_transform_edt(asphalt) * CELL
    core = width >= 2
    angles = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    reach = _cells(ROUND)
    ends = []
    edge = _cells(ROUND + 2)
    for row, column in np.argwhere(core[edge:-edge, edge:-edge]) + edge:
        ring = core[
            np.round(row + reach * np.sin(angles)).astype(int),
            np.round(column + reach * np.cos(angles)).astype(int),
        ]
        if int((ring & ~np.roll(ring, 1)).sum()) == 1:
            near = width[row - reach : row + reach + 1, column - reach : column + reach + 1]
            ends.append((int(row), int(column), float(near.max())))
    return ends


@pytest.mark.parametrize("seed", [25, 26, 27])
def test_every_street_ends_in_a_turning_head_or_goes_on_past_the_plan(seed: int) -> None:
    """A street between blocks of detached houses that stops (30 m from the walls, where
    open land begins) ends in a turning head, asphalt 6 m round (on main in a stub, as
    wide as the road, 3 m from its middle): every end of a road's core within the plan
    has asphalt 5 m or more from its edge within 7 m."""
    ground = _ground(_houses(seed))
    ends = _road_ends(ground)
    assert ends
    stubs = [(row, column) for row, column, widest in ends if widest < 5]
    assert not stubs, stubs[:5]
