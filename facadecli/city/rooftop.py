"""What stands on a flat roof: the coping that caps its walls, and its plant.

- **Coping**: a capping on the top of the walls around a flat roof (on the parapet,
  or at the eaves where there is none), COPING_HEIGHT thick, from COPING_OVER outside
  the outline (a drip over the façade) to COPING_IN inside it (over the wall's top).
  Along a party wall it stops at the wall's face (no drip into the neighbour's roof),
  and it leaves out the taller parts standing on the roof.
- **Plant**, seeded from the building's number: air-conditioning units, mushroom vents,
  on roofs of HOUSING_AREA or more a stair or lift housing, on some rooflights; how
  many from the roof's area. Each lies, with CLEAR around it, inside the roof's outline
  less EDGE_CLEAR (the walkway inside the parapet) and PARTY_CLEAR from its party walls
  and the taller parts on it, square to the roof's main direction. What does not fit
  is left out.

Each kind has a few shapes (sizes in metres, fixed: three condensers, one with two
fans; three vents; three housings, the largest on roofs of twice HOUSING_AREA; three
rooflights), one picked by the seed for each unit, so roofs differ while a city's
units are still one mesh a shape, placed again and again (instanced across the
buildings with ``--instance``).
Units and placements are in the glTF frame (x east, y up, z south), the coping and
the outlines in the map frame (x east, y north, z up).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from shapely.geometry import LineString, MultiPolygon, Point, Polygon
from shapely.ops import unary_union
from shapely.prepared import prep

from facadecli.city.roofs import Segment, roof_axes  # the roofs' main direction, shared

COPING_HEIGHT = 0.08  # metres: the capping's thickness
COPING_OVER = 0.05  # metres: how far it overhangs the outer face of a wall
COPING_IN = 0.35  # metres: how far in it reaches, over the wall's top
EDGE_CLEAR = COPING_IN + 0.6  # metres: plant stays this far inside the outline
PARTY_CLEAR = 1.5  # metres: plant stays this far from a party wall
CLEAR = 0.5  # metres: between two units
HOUSING_AREA = 180.0  # square metres of roof: a stair or lift housing from this size
GRID = 1e-4  # metres: the coping's outline is snapped to this grid
TRIES = 40  # places tried for each unit before it is left out

METAL_NAME = "roof_metal"  # the coping, units, vents and rooflights' kerbs
ROOFLIGHT_NAME = "rooflight"  # the rooflights' glazing
# the housing is in the building's plain wall material, the rooflight's well the interior's


@dataclass(frozen=True)
class Unit:
    """One shape of a kind of plant (``name``: the shape, ``kind``: what it is): its
    meshes by material (``wall``: the building's plain wall material; ``interior``: the
    dark of a window's recess), in its own frame (glTF's; its base's centre at the
    origin, its length along x). ``from_area``: the least roof (square metres) it goes
    on."""

    name: str
    kind: str
    meshes: tuple[tuple[str, trimesh.Trimesh], ...]
    from_area: float = 0.0

    @property
    def size(self) -> tuple[float, float]:
        """Its plan, (along x, along z), centred on its origin: all of its meshes."""
        points = np.vstack([mesh.vertices for _, mesh in self.meshes])
        reach = np.abs(points).max(axis=0)
        return 2 * float(reach[0]), 2 * float(reach[2])


def _box(size: tuple[float, float, float], centre: tuple[float, float, float]) -> trimesh.Trimesh:
    found = trimesh.creation.box(extents=size)
    found.apply_translation(centre)
    return found


def _cylinder(
    radius: float, height: float, base: float, sections: int, x: float = 0.0
) -> trimesh.Trimesh:
    found = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    found.apply_transform(trimesh.transformations.rotation_matrix(-math.pi / 2, (1, 0, 0)))
    found.apply_translation((x, base + height / 2, 0.0))
    return found


def _joined(*meshes: trimesh.Trimesh) -> trimesh.Trimesh:
    found = trimesh.util.concatenate(list(meshes))
    found.vertices = np.round(found.vertices, 6) + 0.0  # no -0.0: the same bytes each time
    return found


def _condenser(name: str, size: tuple[float, float, float], fans: int, radius: float) -> Unit:
    """An air-conditioning unit: a casing ``size`` (length, height, width) with ``fans``
    fans' shrouds of ``radius`` in a row on top."""
    length, height, _ = size
    pitch = length / fans
    shrouds = [
        _cylinder(radius, 0.12, height, 12, x=-length / 2 + pitch * (k + 0.5)) for k in range(fans)
    ]
    casing = _joined(_box(size, (0.0, height / 2, 0.0)), *shrouds)
    return Unit(name, "condenser", ((METAL_NAME, casing),))


def _vent(name: str, stem: float, height: float, cap: float) -> Unit:
    """A mushroom vent: a stem of radius ``stem``, ``height`` high, and its cap."""
    found = _joined(_cylinder(stem, height, 0.0, 8), _cylinder(cap, 0.1, height, 8))
    return Unit(name, "vent", ((METAL_NAME, found),))


def _housing(name: str, size: tuple[float, float, float], from_area: float) -> Unit:
    """A stair or lift housing ``size`` (length, height, width): a box of the wall's
    material, a capping and a metal door near one end of its long side."""
    length, height, width = size
    housing = _box(size, (0.0, height / 2, 0.0))
    capping = _box(
        (length + 0.1, COPING_HEIGHT, width + 0.1), (0.0, height + COPING_HEIGHT / 2, 0.0)
    )
    door = _box((0.9, 2.05, 0.04), (length / 2 - 0.9, 1.025, width / 2 + 0.02))
    meshes = (("wall", housing), (METAL_NAME, _joined(capping, door)))
    return Unit(name, "housing", meshes, from_area)


def _rooflight(name: str, length: float, width: float) -> Unit:
    """A rooflight ``length`` by ``width`` (the longer along z): a kerb, the dark well
    under it, a low glazed pyramid over it, hipped along a ridge."""
    kerb = _box((length, 0.3, width), (0.0, 0.15, 0.0))
    well = _box((length - 0.2, 0.005, width - 0.2), (0.0, 0.3025, 0.0))
    ridge = (width - length) / 2
    apex = ((0.0, 0.45, -ridge), (0.0, 0.45, ridge))
    x, z = length / 2, width / 2
    corners = ((-x, 0.3, -z), (x, 0.3, -z), (x, 0.3, z), (-x, 0.3, z))
    glazing = trimesh.Trimesh(
        [*corners, *apex],
        [[0, 4, 1], [1, 4, 5], [1, 5, 2], [2, 5, 3], [3, 5, 4], [3, 4, 0]],
        process=False,
    )
    meshes = ((METAL_NAME, kerb), ("interior", well), (ROOFLIGHT_NAME, glazing))
    return Unit(name, "rooflight", meshes)


def _units() -> dict[str, Unit]:
    found = [
        _housing("housing", (3.0, 2.6, 2.4), HOUSING_AREA),  # a stair
        _housing("housing-lift", (2.4, 3.2, 2.2), HOUSING_AREA),  # a lift's overrun
        _housing("housing-stair-lift", (4.4, 3.0, 2.6), 2 * HOUSING_AREA),  # both
        _condenser("condenser", (1.6, 1.0, 1.0), 1, 0.38),
        _condenser("condenser-small", (1.0, 0.7, 0.8), 1, 0.3),
        _condenser("condenser-twin", (2.4, 1.1, 1.1), 2, 0.4),  # two fans
        _rooflight("rooflight", 1.2, 1.8),
        _rooflight("rooflight-small", 0.9, 1.2),
        _rooflight("rooflight-long", 1.5, 2.7),
        _vent("vent", 0.11, 0.55, 0.24),
        _vent("vent-tall", 0.08, 0.9, 0.18),
        _vent("vent-wide", 0.16, 0.4, 0.32),
    ]
    return {unit.name: unit for unit in found}


UNITS = _units()  # every shape, by its name
KINDS = tuple(dict.fromkeys(unit.kind for unit in UNITS.values()))  # housing, condenser, ...


def shapes(kind: str, area: float) -> tuple[Unit, ...]:
    """The shapes of ``kind`` that go on a roof of ``area`` square metres."""
    return tuple(u for u in UNITS.values() if u.kind == kind and u.from_area <= area)


@dataclass(frozen=True)
class Placed:
    """A unit on a roof: its kind, its shape (a name in UNITS), its plan (a rectangle,
    map frame), and its placement (the glTF frame: a turn about the vertical, then a
    translation)."""

    kind: str
    shape: str
    outline: Polygon
    matrix: np.ndarray


def coping(
    part: Polygon, top: float, party: Sequence[Segment], above: object = None
) -> trimesh.Trimesh:
    """The capping on the walls around a flat roof whose walls' top is ``top``: from
    COPING_OVER outside to COPING_IN inside the outline, no overhang along a ``party``
    wall, none over the taller parts ``above`` the roof. In the map frame."""
    outer = part.buffer(COPING_OVER, join_style="mitre")
    for a, b in party:  # no drip into the neighbour: cut back to the wall's face
        outer = outer.difference(_beyond(part, a, b))
    inner = part.buffer(-COPING_IN, join_style="mitre")
    ring = outer.difference(inner)
    if above is not None and not getattr(above, "is_empty", True):
        ring = ring.difference(above)
    ring = shapely.set_precision(ring, GRID)  # no points a hair apart: a closed solid
    pieces = [ring] if isinstance(ring, Polygon) else list(getattr(ring, "geoms", []))
    meshes = []
    for piece in pieces:
        if not isinstance(piece, Polygon) or piece.area < 1e-4:
            continue
        slab = trimesh.creation.extrude_polygon(piece, COPING_HEIGHT)
        slab.apply_translation((0.0, 0.0, top))
        meshes.append(slab)
    if not meshes:
        return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), process=False)
    return trimesh.util.concatenate(meshes)


def _beyond(part: Polygon, a: tuple[float, float], b: tuple[float, float]) -> Polygon:
    """The strip outside the wall from ``a`` to ``b``: twice the drip deep, as long as the
    wall and a drip more at each end (where the next wall's drip would run on past it)."""
    start, end = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    length = float(np.hypot(*(end - start)))
    if length <= 0:
        return Polygon()
    along = (end - start) / length
    normal = np.array([along[1], -along[0]])  # right of a -> b
    middle = (start + end) / 2
    if part.contains(Point(*(middle + normal * COPING_OVER))):
        normal = -normal  # outwards is the other side
    first, last = start - along * COPING_OVER, end + along * COPING_OVER
    deep = normal * 2 * COPING_OVER
    return Polygon([tuple(first), tuple(last), tuple(last + deep), tuple(first + deep)])


def room(roof: Polygon, party: Sequence[Segment]) -> Polygon | MultiPolygon:
    """Where plant may stand on a flat roof: inside its outline less EDGE_CLEAR, and
    PARTY_CLEAR from its party walls (and the walls of taller parts on it)."""
    inside = roof.buffer(-EDGE_CLEAR, join_style="mitre")
    if party:
        walls = unary_union([LineString([a, b]) for a, b in party])
        inside = inside.difference(walls.buffer(PARTY_CLEAR))
    return inside


def plant(
    roof: Polygon, eaves: float, party: Sequence[Segment], seed: Sequence[int]
) -> list[Placed]:
    """The plant on a flat roof (its outline, the roof's level ``eaves``, its party
    walls), chosen and placed from ``seed``: a housing on a roof of HOUSING_AREA or more,
    condensers and vents by the roof's area, rooflights on about half the roofs. Larger
    units are placed first; each tries TRIES places, square to the roof's main
    direction, and is left out when none is free."""
    space = room(roof, party)
    if space.is_empty or space.area < 1.0:
        return []
    rng = np.random.default_rng(list(seed))
    area = float(space.area)
    wanted: list[str] = []
    if roof.area >= HOUSING_AREA:
        wanted.append("housing")
    wanted += ["condenser"] * min(6, int(area // 80) + int(rng.integers(0, 2)))
    if rng.random() < 0.5:
        wanted += ["rooflight"] * min(4, 1 + int(area // 120))
    wanted += ["vent"] * min(8, 1 + int(area // 50) + int(rng.integers(0, 2)))
    _, main, _ = roof_axes(roof)
    angle = math.atan2(float(main[1]), float(main[0]))
    free = prep(space)
    low_x, low_y, high_x, high_y = space.bounds
    placed: list[Placed] = []
    taken: list[Polygon] = []
    for kind in wanted:
        choice = shapes(kind, float(roof.area))
        unit = choice[int(rng.integers(0, len(choice)))]  # one of its shapes, by the seed
        length, width = unit.size
        for _ in range(TRIES):
            turn = angle + (math.pi / 2 if rng.random() < 0.5 else 0.0)
            x = float(rng.uniform(low_x, high_x))
            y = float(rng.uniform(low_y, high_y))
            outline = _rectangle(x, y, length, width, turn)
            if not free.contains(outline):
                continue
            if any(outline.distance(other) < CLEAR for other in taken):
                continue
            taken.append(outline)
            placed.append(Placed(kind, unit.name, outline, _placement(x, y, eaves, turn)))
            break
    return placed


def _rectangle(x: float, y: float, length: float, width: float, turn: float) -> Polygon:
    c, s = math.cos(turn), math.sin(turn)
    corners = [
        (-length / 2, -width / 2),
        (length / 2, -width / 2),
        (length / 2, width / 2),
        (-length / 2, width / 2),
    ]
    return Polygon([(x + u * c - v * s, y + u * s + v * c) for u, v in corners])


def _placement(x: float, y: float, z: float, turn: float) -> np.ndarray:
    """A unit's frame in the glTF frame: turned ``turn`` about the vertical (counter-
    clockwise seen from above, as on the map), its base's centre at map (x, y, z)."""
    matrix = np.asarray(trimesh.transformations.rotation_matrix(turn, (0, 1, 0)), dtype=float)
    matrix[:3, 3] = (x, z, -y)
    return np.asarray(np.round(matrix, 9) + 0.0)
