"""Which side of its building a wall is, CityEngine's ``comp(f){front | side | back}``
for footprints with no street network: the front is the longest wall that is not a party
wall, and, when the building has party walls, does not run parallel to them (a terrace
house faces the street with its short wall, its long end wall is a side); every free wall
facing the front's way (within ANGLE) is front too, those facing the other way are the
back, the rest are sides. Pure functions of the walls' ends."""

from __future__ import annotations

import math
from collections.abc import Sequence

ANGLE = 30.0  # degrees: walls whose outward normals are this close face the same way
Point = tuple[float, float]


def facing(a: Point, b: Point) -> float:
    """Compass degrees (0 north, 90 east) the outside of the wall from a to b faces: the
    footprint's outer ring runs counter-clockwise, so outwards is to the right."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    return math.degrees(math.atan2(dy, -dx)) % 360.0  # the normal (dy, -dx) as a bearing


def _apart(first: float, second: float) -> float:
    """Degrees between two bearings, 0 to 180."""
    return abs((first - second + 180.0) % 360.0 - 180.0)


def sides(walls: Sequence[tuple[Point, Point, bool]]) -> list[str]:
    """Each wall's side ("front", "back", "side", or "party" for a party wall), from its
    ends and whether it is a party wall."""
    free = [i for i, (_, _, party) in enumerate(walls) if not party]
    if not free:
        return ["party"] * len(walls)
    shared = [facing(a, b) for a, b, party in walls if party]
    across = [  # free walls that do not run parallel to a party wall
        i
        for i in free
        if all(ANGLE < _apart(facing(*walls[i][:2]), s) < 180 - ANGLE for s in shared)
    ]
    longest = max(across or free, key=lambda i: (math.dist(walls[i][0], walls[i][1]), -i))
    front = facing(walls[longest][0], walls[longest][1])
    found = []
    for a, b, party in walls:
        if party:
            found.append("party")
            continue
        apart = _apart(facing(a, b), front)
        found.append("front" if apart <= ANGLE else "back" if apart >= 180 - ANGLE else "side")
    return found
