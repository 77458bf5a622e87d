"""The rooms behind a façade's windows (a ``rooms`` interior, issue 35), decided in one
place: :func:`rooms` takes the openings of a façade (each window's glass seen head-on),
the façade's size and the space behind it, and gives each window one room box, as a
room is: wider than its window (out to about its bay), its floor the storey's floor
(:data:`BELOW_SILL` under the sill, or a door's threshold), its ceiling the storey's
ceiling (:data:`ABOVE_HEAD` over the head), as deep as the façade's ends and the
building behind the wall leave room. No two rooms meet: where two would, they are cut
apart between their windows. Coordinates are the façade's (x along, y up, z out of the
wall, metres).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from facadecli.geometry.primitives import RECESS_DEPTH, ROOM_DEPTH

#: metres from a window's sill down to its room's floor (a sill stands 0.9 m up)
BELOW_SILL = 0.9
#: metres from a window's head up to its room's ceiling
ABOVE_HEAD = 0.3
#: metres a room reaches out beyond each side of its window, at the most (a window
#: 1.2 m wide looks into a room 3.2 m wide, about a bay)
BEYOND_JAMB = 1.0
#: metres at the least between the rooms of two windows (two rooms never touch)
ROOM_GAP = 0.1


@dataclass(frozen=True)
class Opening:
    """A window's glass seen head-on: across (x0, x1) and up (y0, y1), and ``back``, the
    z of the back of its glass (where its room begins); ``floor``, the storey's floor
    where the façade says it (a door's threshold), else None (:data:`BELOW_SILL`)."""

    x0: float
    x1: float
    y0: float
    y1: float
    back: float
    floor: float | None = None


@dataclass(frozen=True)
class Room:
    """A room box: its side walls (x0, x1), floor and ceiling (y0, y1), its open front at
    ``front`` (the back of its window's glass) and its back wall ``depth`` behind it."""

    x0: float
    x1: float
    y0: float
    y1: float
    front: float
    depth: float


def rooms(
    openings: Sequence[Opening], width: float, height: float, behind: float = math.inf
) -> list[Room | None]:
    """The room behind each of ``openings`` of a façade ``width`` x ``height``, or None
    for one whose window shares its room with an earlier opening (a frame's pane in
    front of the glazing of its opening: the openings that overlap or stand closer than
    :data:`ROOM_GAP` are one window, whose room begins behind the deepest glass).

    Each room is first as large as a room is round its window (:data:`BEYOND_JAMB` each
    side, :data:`BELOW_SILL` and :data:`ABOVE_HEAD`), within the façade; where two
    rooms would meet, both are cut back to :data:`ROOM_GAP` apart (:func:`_apart`) on the
    axis where their windows stand furthest apart. Its depth is :func:`room_depth`: no
    further than ``behind`` the façade's plane (the space behind the wall; a façade alone
    has nothing behind it)."""
    windows = _windows(openings)
    spans = [_round(window, width, height) for window, _ in windows]
    pairs = [(i, j) for i in range(len(windows)) for j in range(i + 1, len(windows))]
    diagonal = [not _level(windows[i][0], windows[j][0]) for i, j in pairs]
    for _, (i, j) in sorted(zip(diagonal, pairs, strict=True)):  # a row's, a column's first
        if _meet(spans[i], spans[j]):
            spans[i], spans[j] = _apart(windows[i][0], windows[j][0], spans[i], spans[j])
    found: list[Room | None] = [None] * len(openings)
    for (window, first), (x0, x1, y0, y1) in zip(windows, spans, strict=True):
        deep = room_depth(window, width, behind)
        x0 = max(x0, min(window.x0, deep - window.back))  # the corner rule (room_depth)
        x1 = min(x1, max(window.x1, width - deep + window.back))
        found[first] = Room(x0, x1, y0, y1, window.back, deep)
    return found


def room_depth(window: Opening, width: float, behind: float = math.inf) -> float:
    """How deep a window's room is behind its glass: :data:`ROOM_DEPTH`, reaching no
    further than ``behind`` the façade's plane (the space behind the wall: in a city, half
    the building behind it, :func:`.room_reach`) nor further behind the façade's plane
    than the window stands from the façade's nearer end
    (so that at a building's corner it meets no room of the other façade, whose windows
    stand as far from the corner as its rooms reach in); whole decimetres, so that the
    windows of a façade share a few depths, and :data:`RECESS_DEPTH` at the least."""
    free = min(window.x0, width - window.x1, behind) + window.back  # back: under 0
    deep = math.floor(min(ROOM_DEPTH, free) * 10 + 1e-9) / 10
    return max(RECESS_DEPTH, deep)


Span = tuple[float, float, float, float]  # x0, x1, y0, y1


def _windows(openings: Sequence[Opening]) -> list[tuple[Opening, int]]:
    """The windows the openings make (those that overlap or stand closer than
    :data:`ROOM_GAP`, grouped until no two groups do): each as the bounds of its openings
    with the deepest back, and the index of its first opening, in order of it."""
    groups = [([k], opening) for k, opening in enumerate(openings)]
    merged = True
    while merged:
        merged = False
        for i in range(len(groups)):
            for j in range(i + 1, len(groups)):
                a, b = groups[i][1], groups[j][1]
                if _gap(a, b) < ROOM_GAP:
                    floors = [f for f in (a.floor, b.floor) if f is not None]
                    joined = Opening(
                        min(a.x0, b.x0),
                        max(a.x1, b.x1),
                        min(a.y0, b.y0),
                        max(a.y1, b.y1),
                        min(a.back, b.back),
                        min(floors) if floors else None,
                    )
                    groups[i] = (groups[i][0] + groups[j][0], joined)
                    del groups[j]
                    merged = True
                    break
            if merged:
                break
    return [(window, min(members)) for members, window in groups]


def _gap(a: Opening, b: Opening) -> float:
    """How far apart two openings stand: on the axis where they stand furthest apart."""
    return max(b.x0 - a.x1, a.x0 - b.x1, b.y0 - a.y1, a.y0 - b.y1)


def _round(window: Opening, width: float, height: float) -> Span:
    """The room a window would have alone, within the façade."""
    floor = window.y0 - BELOW_SILL if window.floor is None else window.floor
    return (
        min(window.x0, max(0.0, window.x0 - BEYOND_JAMB)),
        max(window.x1, min(width, window.x1 + BEYOND_JAMB)),
        min(window.y0, max(0.0, floor)),
        max(window.y1, min(height, window.y1 + ABOVE_HEAD)),
    )


def _level(a: Opening, b: Opening) -> bool:
    """Whether two windows stand side by side or one above the other (their spans overlap
    across or up), rather than diagonally apart."""
    return min(a.x1, b.x1) > max(a.x0, b.x0) or min(a.y1, b.y1) > max(a.y0, b.y0)


def _meet(a: Span, b: Span) -> bool:
    """Whether two rooms come closer than :data:`ROOM_GAP`."""
    return max(b[0] - a[1], a[0] - b[1], b[2] - a[3], a[2] - b[3]) < ROOM_GAP - 1e-9


def _apart(a: Opening, b: Opening, room_a: Span, room_b: Span) -> tuple[Span, Span]:
    """Two rooms cut back to :data:`ROOM_GAP` apart, on the axis where their windows stand
    apart and the cut takes least room, half way across where the two rooms meet (so a
    room whose ceiling meets the next room's floor keeps both near the storeys' floor),
    never into a window (the windows stand :data:`ROOM_GAP` apart at the least,
    :func:`_windows`)."""
    gaps = [(b.x0 - a.x1, 0, True), (a.x0 - b.x1, 0, False)]
    gaps += [(b.y0 - a.y1, 2, True), (a.y0 - b.y1, 2, False)]
    apart = [(axis, a_first) for gap, axis, a_first in gaps if gap >= ROOM_GAP - 1e-9]
    apart = apart or [max(gaps)[1:]]

    def overlap(choice: tuple[int, bool]) -> float:  # how much room the cut takes
        axis, a_first = choice
        low, high = (room_a, room_b) if a_first else (room_b, room_a)
        return low[axis + 1] - high[axis]

    axis, a_first = min(apart, key=overlap)
    low, high = (a, b) if a_first else (b, a)
    cut_low, cut_high = list(room_a if a_first else room_b), list(room_b if a_first else room_a)
    end, start = (low.x1, high.x0) if axis == 0 else (low.y1, high.y0)
    met = (cut_low[axis + 1] + cut_high[axis]) / 2  # the middle of where they meet
    middle = min(max(met, end + ROOM_GAP / 2), start - ROOM_GAP / 2)
    cut_low[axis + 1] = min(cut_low[axis + 1], middle - ROOM_GAP / 2)
    cut_high[axis] = max(cut_high[axis], middle + ROOM_GAP / 2)
    first, second = tuple(cut_low), tuple(cut_high)
    return (first, second) if a_first else (second, first)  # type: ignore[return-value]
