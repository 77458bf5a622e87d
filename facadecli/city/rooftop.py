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

Every unit of a kind is one shape (sizes in metres, fixed), so a city's units are one
mesh each, placed again and again (instanced across the buildings with ``--instance``).
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
    """A kind of plant: its meshes by material (``wall``: the building's plain wall
    material; ``interior``: the dark of a window's recess), in its own frame (glTF's;
    its base's centre at the origin, its length along x)."""

    kind: str
    meshes: tuple[tuple[str, trimesh.Trimesh], ...]

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


def _cylinder(radius: float, height: float, base: float, sections: int) -> trimesh.Trimesh:
    found = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    found.apply_transform(trimesh.transformations.rotation_matrix(-math.pi / 2, (1, 0, 0)))
    found.apply_translation((0.0, base + height / 2, 0.0))
    return found


def _joined(*meshes: trimesh.Trimesh) -> trimesh.Trimesh:
    found = trimesh.util.concatenate(list(meshes))
    found.vertices = np.round(found.vertices, 6) + 0.0  # no -0.0: the same bytes each time
    return found


def _units() -> dict[str, Unit]:
    # an air-conditioning unit: a casing with its fan's shroud on top
    condenser = _joined(_box((1.6, 1.0, 1.0), (0.0, 0.5, 0.0)), _cylinder(0.38, 0.12, 1.0, 12))
    # a mushroom vent: a stem and its cap
    vent = _joined(_cylinder(0.11, 0.55, 0.0, 8), _cylinder(0.24, 0.1, 0.55, 8))
    # a stair or lift housing: a box of the wall's material, a capping and a metal door
    housing = _box((3.0, 2.6, 2.4), (0.0, 1.3, 0.0))
    capping = _box((3.1, COPING_HEIGHT, 2.5), (0.0, 2.6 + COPING_HEIGHT / 2, 0.0))
    door = _box((0.9, 2.05, 0.04), (0.6, 1.025, 1.22))
    # a rooflight: a kerb, the dark well under it, a low glazed pyramid over it
    kerb = _box((1.2, 0.3, 1.8), (0.0, 0.15, 0.0))
    well = _box((1.0, 0.005, 1.6), (0.0, 0.3025, 0.0))
    apex = ((0.0, 0.45, -0.3), (0.0, 0.45, 0.3))  # a hipped ridge along it
    corners = ((-0.6, 0.3, -0.9), (0.6, 0.3, -0.9), (0.6, 0.3, 0.9), (-0.6, 0.3, 0.9))
    glazing = trimesh.Trimesh(
        [*corners, *apex],
        [[0, 4, 1], [1, 4, 5], [1, 5, 2], [2, 5, 3], [3, 5, 4], [3, 4, 0]],
        process=False,
    )
    return {
        "housing": Unit("housing", (("wall", housing), (METAL_NAME, _joined(capping, door)))),
        "condenser": Unit("condenser", ((METAL_NAME, condenser),)),
        "rooflight": Unit(
            "rooflight",
            ((METAL_NAME, kerb), ("interior", well), (ROOFLIGHT_NAME, glazing)),
        ),
        "vent": Unit("vent", ((METAL_NAME, vent),)),
    }


UNITS = _units()


@dataclass(frozen=True)
class Placed:
    """A unit on a roof: its kind, its plan (a rectangle, map frame), and its placement
    (the glTF frame: a turn about the vertical, then a translation)."""

    kind: str
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
        length, width = UNITS[kind].size
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
            placed.append(Placed(kind, outline, _placement(x, y, eaves, turn)))
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
