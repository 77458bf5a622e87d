"""Doors where OpenStreetMap maps a building's entrances (nodes tagged ``entrance=*`` on
its outline): the wall that holds such a node gets a door at that point of its façade.

The door takes the place of the ground floor's opening nearest the entrance (a window
of the façade's ground floor, starting below :data:`GROUND_FLOOR`), from the ground up
to that opening's head, at least :data:`DOOR_HEIGHT`; a façade whose ground floor has no
opening near it gets a door :data:`DOOR_WIDTH` wide centred on the entrance. A wall, a
pane or a ledge (a box or a ledge) the door crosses is cut round it, so the wall below
the window and a window above a low ground floor keep what the door leaves of them;
whatever else it covers goes (the window's frame, its sill and shutters), and what it
uncovers shows. The door is the façade's own (the look and material of a shape the spec
draws with the ``door`` mesh), else a frame's look in :data:`DOOR_MATERIAL`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

from facadecli.geometry.facade import see_through
from facadecli.geometry.primitives import PANES
from facadecli.layout import Appearance, Layout, Shape, cull

GROUND_FLOOR = 1.5  # metres: an opening starting lower is on the ground floor
DOOR_HEIGHT = 2.1  # metres: a door is at least this tall
DOOR_WIDTH = 1.0  # metres: a door where no ground-floor opening is near
NEAR = 1.5  # metres: how far from an entrance a ground-floor opening may be
ON_WALL = 0.5  # metres: how far from a wall an entrance may be and still be on it
DOOR_MATERIAL = "door"  # the spec's, else a dark timber (city/building.py)
CUT = ("box", "ledge")  # meshes a door is cut out of; any other it covers goes


def along_wall(
    entrances: Sequence[tuple[float, float]], a: tuple[float, float], b: tuple[float, float]
) -> tuple[float, ...]:
    """Where each entrance within :data:`ON_WALL` of the wall from ``a`` to ``b`` lies
    along it (metres from ``a``), in order."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = math.hypot(dx, dy)
    if length == 0:
        return ()
    found = []
    for x, y in entrances:
        t = ((x - a[0]) * dx + (y - a[1]) * dy) / length
        off = abs((x - a[0]) * dy - (y - a[1]) * dx) / length
        if 0 <= t <= length and off <= ON_WALL:
            found.append(round(t, 6))
    return tuple(sorted(found))


Wall = tuple[tuple[float, float], tuple[float, float], bool]  # its ends; a party wall?


def door_owners(
    point: tuple[float, float], holders: Sequence[tuple[str, Sequence[Wall]]]
) -> list[str]:
    """Which of the buildings holding one entrance (``holders``: id and walls, as on a
    node two outlines share) may have its door, best first: those with the entrance on
    one of their walls that is not a party wall (a party wall has no façade, so no
    door); among several, the one where the entrance lies farthest from its wall's ends
    (a door fits whole there, not round a corner), then the first in ``holders``."""
    ranked = []
    for order, (key, walls) in enumerate(holders):
        rooms = [
            min(t, math.dist(a, b) - t)
            for a, b, party in walls
            if not party
            for t in along_wall([point], a, b)
        ]
        if rooms:
            ranked.append((-round(max(rooms), 6), order, key))
    return [key for *_, key in sorted(ranked)]


def with_doors(layout: Layout, positions: Sequence[float]) -> Layout:
    """The layout with a door at each position (metres from its left end, in the
    layout's own width)."""
    shapes = [dataclasses.replace(s, visible=True) for s in layout.shapes]
    for position in positions:
        shapes = _door(layout, shapes, position)
    order = {layer.name: k for k, layer in enumerate(layout.spec.layers)}
    shapes.sort(key=lambda s: order.get(s.layer, len(order)))  # back to front, stable
    return dataclasses.replace(layout, shapes=cull(shapes))  # what the door uncovers shows


def _door(layout: Layout, shapes: list[Shape], position: float) -> list[Shape]:
    spec = layout.spec
    openings = [
        s
        for s in shapes
        if s.y0 < GROUND_FLOOR
        and (s.mesh in PANES or see_through(spec, s.material))
        and s.x0 - NEAR <= position <= s.x1 + NEAR
    ]
    opening = min(  # the nearest; of a window's frame and pane, the frontmost
        openings,
        key=lambda s: (round(abs((s.x0 + s.x1) / 2 - position), 6), -s.z1, s.x0),
        default=None,
    )
    if opening is not None and opening.mesh == "door":
        return shapes  # the façade has its door there already
    top = layout.height - 0.1
    if opening is not None:
        x0, x1 = opening.x0, opening.x1
        head = min(max(opening.y1, DOOR_HEIGHT), top)
    else:
        half = min(DOOR_WIDTH, layout.width) / 2
        middle = min(max(position, half), layout.width - half)
        x0, x1, head = middle - half, middle + half, min(DOOR_HEIGHT, top)
    front = _front(shapes, x0, x1, head)
    kept: list[Shape] = []
    for shape in shapes:
        if shape.x1 <= x0 + 1e-6 or shape.x0 >= x1 - 1e-6 or shape.y0 >= head - 1e-6:
            kept.append(shape)
        elif shape.mesh in CUT:
            kept.extend(_around(shape, x0, x1, head))
    return [*kept, _door_shape(shapes, opening or front, x0, x1, head)]


def _front(shapes: list[Shape], x0: float, x1: float, head: float) -> Shape:
    """The frontmost shape the door covers: where its door stands."""
    covered = [s for s in shapes if s.x0 < x1 and s.x1 > x0 and s.y0 < head]
    return max(covered or shapes, key=lambda s: (s.z1, -s.z0))


def _around(shape: Shape, x0: float, x1: float, head: float) -> list[Shape]:
    """What is left of a wall or a ledge round a door from ``x0`` to ``x1``, up to
    ``head``: its pieces left, right and above."""
    pieces = []
    if shape.x0 < x0 - 1e-6:
        pieces.append(dataclasses.replace(shape, x1=x0))
    if shape.x1 > x1 + 1e-6:
        pieces.append(dataclasses.replace(shape, x0=x1))
    if shape.y1 > head + 1e-6:
        pieces.append(
            dataclasses.replace(shape, x0=max(shape.x0, x0), x1=min(shape.x1, x1), y0=head)
        )
    return pieces


def _door_shape(shapes: list[Shape], where: Shape, x0: float, x1: float, head: float) -> Shape:
    """A door over ``x0``-``x1`` from the ground to ``head``, in the layer and depth of
    ``where``: the spec's own door's look when it draws one, else a frame's."""
    own = next((s for s in shapes if s.mesh == "door" and s.look is not None), None)
    if own is not None and own.look is not None:
        look = own.look
    elif where.look is not None and where.mesh in PANES:
        look = dataclasses.replace(where.look, material=DOOR_MATERIAL, mesh="door")
    else:
        thickness = max(where.z1 - where.z0, 0.1)
        look = Appearance(DOOR_MATERIAL, "door", where.z1, thickness)
    z1 = where.z1
    z0 = z1 - max(where.z1 - where.z0, look.thickness, 0.05)
    return Shape(
        where.layer,
        where.x,
        where.y,
        x0,
        x1,
        0.0,
        head,
        z0,
        z1,
        look.material,
        "door",
        False,
        False,
        False,
        True,
        look,
    )
