"""The most columns an alignment can have at its sizes (SPEC 2.7's tie-break).

Once a layout is sized, a column can be cut wherever every visible entry in it has a
letter boundary: transparent entries may be cut anywhere (their letters split into
pieces). The cut alignment has the same sizes and the same objective, and every rule of
SPEC 2.4 still holds (each part of an opaque entry is opaque, nothing new is empty), so
among equally good layouts it is the one the contract asks for. Searches then need not
find the finest alignment themselves: any alignment with the right sizes will do.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

from facadecli.solver import sizing
from facadecli.solver.alignment import Alignment, Move, _entry, _NoEntry, _Row
from facadecli.spec.model import Spec

NEAR = 1e-7  # metres: boundaries this close are one
# m^2: the cut layout has the same sizes, but its program more lengths with the tiny weight
# (sizing.TINY) that makes the optimum unique: its objective may move by about this much
REGULARIZATION = 1e-7


def finest(
    spec: Spec,
    canvas: float,
    groups: Mapping[str, Alignment],
    program: sizing.Program,
    solved: sizing.Sizing,
    known: sizing.Sized | None = None,
) -> tuple[dict[str, Alignment], sizing.Program, sizing.Sizing]:
    """The alignments cut into as many columns as their sizes allow, with their program
    and sizing; the originals when nothing can be cut. ``known``: alignments sized
    before (:func:`sizing.sized_alignments`)."""
    refined = {name: _refine(name, a, program, solved) for name, a in groups.items()}
    if all(refined[name] is groups[name] for name in groups):
        return dict(groups), program, solved
    finer, resized = sizing.sized_alignments(spec, refined, canvas, known)
    if resized is None or resized.objective > solved.objective + REGULARIZATION:
        return dict(groups), program, solved
    return refined, finer, resized


def _refine(
    group: str, alignment: Alignment, program: sizing.Program, solved: sizing.Sizing
) -> Alignment:
    rows = [_Row(row) for row in alignment.rows]
    starts = sizing.column_starts(solved, program, group, alignment.columns)
    columns: list[tuple[Move | None, ...]] = []
    for j, column in enumerate(alignment.entries):
        if any(_uncut(move) for move in column):
            columns.append(column)  # a visible letter spans it whole: no cut inside
            continue
        points = {
            r: _points(group, r, j, move, alignment, program, solved, starts[j])
            for r, move in enumerate(column)
            if move is not None
        }
        cuts = _common_cuts(column, points, starts[j], starts[j + 1])
        if not cuts:
            columns.append(column)
            continue
        try:
            columns.extend(_cut(column, points, rows, [starts[j], *cuts, starts[j + 1]]))
        except _NoEntry:
            columns.append(column)
    if len(columns) == alignment.columns:
        return alignment
    return Alignment(
        alignment.rows,
        tuple(columns),
        alignment.error,
        tuple(0.0 for _ in columns),
        tuple(False for _ in columns),
    )


def _uncut(move: Move | None) -> bool:
    """A visible entry of one whole letter: no boundary inside it, so its column has none
    that every visible entry shares."""
    return (
        move is not None
        and not move.transparent
        and move.start % 2 == 0
        and move.end == move.start + 2
    )


Points = list[tuple[float, int]]  # (coordinate, position in half-steps) along an entry


def _points(
    group: str,
    r: int,
    j: int,
    move: Move,
    alignment: Alignment,
    program: sizing.Program,
    solved: sizing.Sizing,
    start: float,
) -> Points:
    """Where the letters and pieces of an entry begin and end."""
    word = alignment.rows[r].word
    whole, parts = sizing.entry_parts(move)
    items = sorted([(k, False) for k in whole] + [(k, True) for k in parts])
    points = [(start, move.start)]
    x = start
    for index, (k, is_piece) in enumerate(items):
        if is_piece:
            x += solved.of(program.pieces[sizing.Piece(group, r, k, j)])
        else:
            x += solved.of(program.symbols[word[k].symbol])
        last = index == len(items) - 1
        points.append((x, move.end if last else 2 * (k + 1)))
    return points


def _common_cuts(
    column: Sequence[Move | None], points: Mapping[int, Points], low: float, high: float
) -> list[float]:
    """Inner boundaries shared by every visible entry of a column."""
    visible = [r for r, move in enumerate(column) if move is not None and not move.transparent]
    if not visible:
        return []
    candidates = [x for x, _ in points[visible[0]][1:-1] if low + NEAR < x < high - NEAR]
    return [
        x
        for x in candidates
        if all(any(abs(x - y) <= NEAR for y, _ in points[r][1:-1]) for r in visible[1:])
    ]


def _position(points: Points, x: float) -> int:
    """The half-step position of coordinate ``x`` in an entry: a boundary, or inside the
    (transparent) letter that spans it."""
    for y, position in points:
        if abs(x - y) <= NEAR:
            return position
    for (a, before), (b, _) in itertools.pairwise(points):
        if a < x < b:
            return before + 1 if before % 2 == 0 else before
    raise _NoEntry(f"no position at {x}")


def _cut(
    column: Sequence[Move | None],
    points: Mapping[int, Points],
    rows: Sequence[_Row],
    edges: Sequence[float],
) -> list[tuple[Move | None, ...]]:
    parts = []
    last = len(edges) - 2
    for j, (a, b) in enumerate(itertools.pairwise(edges)):
        entries: list[Move | None] = []
        for r, move in enumerate(column):
            if move is None:
                entries.append(None)
                continue
            # the column's own ends where the entry has them: letters of no length at an
            # end stay in it (a coordinate alone would name the first of them)
            start = move.start if j == 0 else _position(points[r], a)
            end = move.end if j == last else _position(points[r], b)
            entries.append(_entry(rows[r], start, end))
        parts.append(tuple(entries))
    return parts
