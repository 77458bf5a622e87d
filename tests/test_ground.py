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
console.log(JSON.stringify({kinds: Array.from(ground.kinds), dashes, lamps, trees}));
"""

Box = tuple[float, float, float, float]  # x0, y0, x1, y1 in metres


@dataclass(frozen=True)
class Ground:
    """A plan's ground as GROUND makes it: the kind of each cell (rows from the top), the
    dashes and the lamps (x, y in metres, then the way they face: x, y), the trees."""

    kinds: np.ndarray
    dashes: list[tuple[float, float, float, float]]
    lamps: list[tuple[float, float, float, float]]
    trees: list[tuple[float, float]]

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


def _houses(seed: int) -> list[Box]:
    """A sparse town: 100 detached houses, 8-14 m a side, on a grid 45 m apart, each moved
    up to 8 m (seeded): lawns round them, as Kotka has."""
    chance = random.Random(seed)
    houses = []
    for i in range(10):
        for j in range(10):
            x, y = i * 45 + chance.uniform(-8, 8), j * 45 + chance.uniform(-8, 8)
            houses.append((x, y, x + chance.uniform(8, 14), y + chance.uniform(8, 14)))
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
