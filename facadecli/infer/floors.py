"""The façade's floors along y: one sequence every layer standing on them follows (issue 34).

The openings' floors are the rows of the opening grid with the most rows (``floors_top``);
where they repeat (a run of floors alike at one pitch, written with a counter), a taller
façade gains floors there, and a shorter one drops them. What stands on those floors (a
window's sill, its blind, the cornice over it) must be gained and dropped with them, at
their pitch, or a gained floor has none and the rows drawn over the run stay where they
were while the windows move over them.

So the run is cut into *floors* in the middle of the walls between them (``Floors``): the
cut ``cut`` over the run's last floor, and the ones a pitch apart under it, one per floor
of the run. A layer standing on the floors whose elements cross no cut and show alike on
every floor of the run (the same rows, each edge within ``ALIKE`` of the element's size
of the last floor's, measured from each floor's cut: ``follows``; sills drawn a millimetre
or two off the windows' pitch) is written as the sequence of floors (``floor_letters``): what
it shows under the run as drawn, one floor of the run repeated with the openings'
counter (a floor it shows nothing on is one hidden spacer), what it shows over the run
as drawn; the repeated floor is read from where the layer's first element on it starts
(two letters, an element and a gap, as the openings' run: a unit of a gap, an element and
a gap leaves the solver's search no layout within its budget). Its margin to the ground,
its elements and every gap keep their size; the margin to the roof takes the slack. Its
elements then stand where drawn at the input's size (each floor of the run as the last
is, within ``ALIKE``), and on every floor gained, where the openings' floors are, at any
height; a shorter façade drops them with their floors. A label's grids, cut by column
(``layers``), are re-cut by floor first (``by_floors``): what stands alike on every
floor of the run is one grid, so that a floor lacking one column's sill does not keep
the others' from following.

A layer with nothing on the run's floors (a top floor's sills alone) moves with the top
floor, over the floors gained. Where the openings have a run, it is the one place a
taller façade gains floors: no layer's top floor repeats upwards
(``spec_text._floors_above``) but one standing on the run's floors; the two ways mixed
would gain floors twice, the copies of a floor's sills over the windows the run moved up
(the family with defects' seed 1 at 1.5x height: four windows over others).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

from facadecli.infer.bays import HELD
from facadecli.infer.layers import OPENINGS, Grid, Span, cut

EPS = 1e-6  # m: an element this close to a cut does not cross it
ALIKE = HELD  # of an element's size: the most its edges on one floor of the run may be
# off where they are on the last (measured from each floor's cut): as far as a bay kind's
# shape may move an element, so the floors' one sequence puts it within that of as drawn
SLIVER = 0.5e-4  # m: a gap this thin or thinner is none (written, it would be 0)

Letter = tuple[str, float]  # ("margin" | "gap" | "element", size)


@dataclass(frozen=True)
class Floors:
    """The openings' run of floors: ``copies`` floors (the counter's value at the input's
    size) at ``pitch``, the cut over the last ``cut`` (mid-wall), each floor from the cut
    under it to the one over it; ``alike``: the share of an element's size its edges on
    one floor of the run may be off where they are on the last (``ALIKE``; 0: to
    ``EPS``)."""

    cut: float
    pitch: float
    copies: int
    alike: float = ALIKE

    def cuts(self) -> list[float]:
        """The cuts bottom up: under the run's first floor, ..., over its last."""
        return [self.cut - (self.copies - k) * self.pitch for k in range(self.copies + 1)]


def floors_top(found: list[Grid]) -> float:
    """Where the floors end: the top of the opening grid with the most rows (windows on a
    tie); a grid starting there or higher stands above them (an attic, a top cornice)."""
    grid = floors_grid(found)
    return float("inf") if grid is None else found[grid].rows[-1][1]


def floors_grid(found: list[Grid]) -> int | None:
    """The index of the opening grid with the most rows (windows on a tie): the floors'."""
    openings = [k for k, g in enumerate(found) if g.label in OPENINGS]
    if not openings:
        return None
    return max(
        openings,
        key=lambda k: (len(found[k].rows), found[k].label == "window", found[k].elements),
    )


def mid_wall(run_end: float, unit: list[Letter], pitch: float) -> float:
    """The cut over a run of the openings' floors ending at ``run_end`` whose repeated unit
    is ``unit`` (an element and a gap, in either order): the middle of the wall between
    the run's last floor and the one over it."""
    gap = next(size for kind, size in unit if kind == "gap")
    return run_end - gap / 2 if unit[0][0] == "element" else run_end + gap / 2


def follows(rows: tuple[Span, ...], floors: Floors) -> bool:
    """Whether a layer on ``rows`` can follow the floors: something on the run or over it,
    no element across a cut, the same rows on every floor of the run, and nothing on the
    floor over the run under where its elements start on the run's floors."""
    cuts = floors.cuts()
    if cuts[0] <= EPS or rows[-1][1] <= cuts[0] + EPS:
        return False
    if any(a < c - EPS and b > c + EPS for a, b in rows for c in cuts):
        return False
    shown = [_on(rows, cuts[k], cuts[k + 1]) for k in range(floors.copies)]
    if any(not _alike(s, shown[-1], floors.alike) for s in shown):
        return False
    starts = _starts(rows, floors)
    return not any(
        a < _over(starts[-1], (a, b), floors.alike) and b > cuts[-1] + EPS for a, b in rows
    )


def on_run(rows: tuple[Span, ...], floors: Floors) -> bool:
    """Whether a layer on ``rows`` shows something on the run's floors (on the first)."""
    cuts = floors.cuts()
    return bool(_on(rows, cuts[0], cuts[1]))


def _on(rows: tuple[Span, ...], low: float, high: float) -> tuple[Span, ...]:
    """The rows from ``low`` to ``high``, measured from ``low``."""
    return tuple((a - low, b - low) for a, b in rows if a >= low - EPS and b <= high + EPS)


def _alike(rows: tuple[Span, ...], reference: tuple[Span, ...], alike: float) -> bool:
    """As many rows as ``reference``, each within ``alike`` of its size of its own."""
    return len(rows) == len(reference) and all(
        _near(row, own, alike) for row, own in zip(rows, reference, strict=True)
    )


def _near(row: Span, own: Span, alike: float) -> bool:
    """``row`` within ``alike`` of the size of ``own`` of it, at both ends."""
    reach = alike * (own[1] - own[0]) + EPS
    return abs(row[0] - own[0]) <= reach and abs(row[1] - own[1]) <= reach


def _over(start: float, row: Span, alike: float) -> float:
    """Where ``row`` counts as over the run whose floor over it starts at ``start``: from
    ``alike`` of its size under that (a top floor's sill drawn a millimetre under the
    floors' pitch stands on it, written from ``start``)."""
    return start - alike * (row[1] - row[0]) - EPS


def by_floors(found: list[Grid], floors: Floors) -> list[Grid]:
    """The grids, each label's but the openings' (whose floors these are) re-cut by floor:
    its elements that stand alike on every floor of the run (in one column, on rows
    within ``ALIKE`` of the last floor's, measured from each floor's cut) are one grid
    per row of the last floor, their columns those every floor shows, with the rows of
    the label under and over the run that show all those columns (as drawn there); the
    rest stay in the grids they were in (a grid left a part of itself is cut again,
    ``layers.cut``). Cut by column alone, a floor whose sills lack one column's (a door's
    bay) put them in another grid than the floors' over it, so no grid was alike on
    every floor and none followed the floors. The elements apart from the bays
    (``Grid.apart``) are re-cut among themselves."""
    cuts = floors.cuts()
    out: list[Grid] = []
    seen: set[tuple[str, bool]] = set()
    for grid in found:
        key = (grid.label, grid.apart)
        if grid.label in OPENINGS:
            out.append(grid)
            continue
        if key in seen:
            continue
        seen.add(key)
        mine = [g for g in found if (g.label, g.apart) == key]
        out.extend(_recut(mine, cuts, floors.alike) or mine)
    return out


def _recut(mine: list[Grid], cuts: list[float], alike: float) -> list[Grid] | None:
    """A label's grids (all apart or none) re-cut by the floors between ``cuts`` (see
    ``by_floors``): the grids of what stands alike on every floor, and the grids as they
    were less those elements (a grid left a part of itself is cut again); None where
    nothing stands alike on every floor of the run."""
    label, apart = mine[0].label, mine[0].apart
    spans = sorted({(r, c) for g in mine for r in g.rows for c in g.columns})
    on = [
        [(r, c) for r, c in spans if r[0] >= low - EPS and r[1] <= high + EPS]
        for low, high in itertools.pairwise(cuts)
    ]
    same: dict[tuple[Span, ...], list[Span]] = {}  # its row on each floor -> columns
    for row, column in on[-1]:
        rows = []
        for k, elements in enumerate(on):
            shift = cuts[k] - cuts[-2]
            own = (row[0] + shift, row[1] + shift)
            hit = next((r for r, c in elements if c == column and _near(r, own, alike)), None)
            if hit is None:
                break
            rows.append(hit)
        else:
            same.setdefault(tuple(rows), []).append(column)
    taken: set[tuple[Span, Span]] = set()
    found: list[Grid] = []
    for floor_rows, columns in same.items():
        if any(b[0] < a[1] - EPS for a, b in itertools.pairwise(sorted(columns))):
            continue  # overlapping columns: not one grid
        kept = list(floor_rows)
        off = sorted({r for r, _ in spans if r[1] <= cuts[0] + EPS or r[0] >= cuts[-1] - EPS})
        for row in off:  # under and over the run, as drawn, where it shows every column
            if all((row, c) in spans and (row, c) not in taken for c in columns) and not any(
                min(row[1], r[1]) - max(row[0], r[0]) > EPS for r in kept
            ):
                kept.append(row)
        taken |= {(r, c) for r in kept for c in columns}
        found.append(Grid(label, tuple(sorted(columns)), tuple(sorted(kept)), apart))
    if not found:
        return None
    for grid in mine:
        rest = [(r, c) for r in grid.rows for c in grid.columns if (r, c) not in taken]
        found.extend([grid] if len(rest) == grid.elements else cut(label, sorted(rest), apart))
    return sorted(found, key=lambda g: (g.rows[0], g.columns[0]))


def _starts(rows: tuple[Span, ...], floors: Floors) -> list[float]:
    """Where the layer's floors start: each floor's cut moved up to where its first
    element starts (so that the repeated floor starts with an element and ends with one
    gap: a run of two letters, as the openings' own), the floor over the run's as much as
    the last of the run's; the cuts where it shows nothing on the run."""
    cuts = floors.cuts()
    firsts = [
        min((a for a, b in rows if a >= low - EPS and b <= high + EPS), default=None)
        for low, high in itertools.pairwise(cuts)
    ]
    if firsts[-1] is None:
        return cuts
    starts = [low if a is None else a for a, low in zip(firsts, cuts, strict=False)]
    return [*starts, cuts[-1] + firsts[-1] - cuts[-2]]


def floor_letters(
    rows: tuple[Span, ...], floors: Floors, height: float
) -> tuple[list[Letter], list[Letter], list[Letter]]:
    """The y word of a layer that ``follows`` the floors, as letters: under the run (from
    the margin to the ground up to where its first floor starts), one floor of the run
    (the last), over the run (from where the floor over it starts to the margin to the
    roof)."""
    starts = _starts(rows, floors)
    under = _letters([r for r in rows if r[1] <= starts[0] + EPS], 0.0, starts[0], "margin", "gap")
    floor = _letters(
        [r for r in rows if starts[-2] - EPS <= r[0] and r[1] <= starts[-1] + EPS],
        starts[-2],
        starts[-1],
        "gap",
        "gap",
    )
    over = _letters(
        [r for r in rows if r[0] >= _over(starts[-1], r, floors.alike)],
        starts[-1],
        height,
        "gap",
        "margin",
    )
    return under, floor, over


def _letters(rows: list[Span], low: float, high: float, first: str, last: str) -> list[Letter]:
    """The rows between ``low`` and ``high`` with the gaps between them: the gap before
    the first is a ``first``, the one after the last a ``last``; none of a ``SLIVER``."""
    letters: list[Letter] = []
    cursor = low
    for a, b in sorted(rows):
        if a - cursor > SLIVER:
            letters.append((first if not letters else "gap", a - cursor))
        letters.append(("element", b - a))
        cursor = b
    if high - cursor > SLIVER:
        letters.append((last if letters or last == "margin" else first, high - cursor))
    return letters
