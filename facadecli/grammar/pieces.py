"""Measures of a derived layout's terminals (:class:`~facadecli.grammar.model.Piece`, made
by the derivations of :mod:`facadecli.grammar.derive` and the copied bays of
:mod:`facadecli.grammar.slabs`): their elements, how far their sizes are from the source's,
how far two layouts are apart, and a key that tells two layouts apart."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import numpy as np

from facadecli.grammar.inputs import BACKGROUND
from facadecli.grammar.model import Piece
from facadecli.grammar.style import Box, Facade, facade_of


def boxes_of(pieces: Sequence[Piece]) -> list[Box]:
    """The pieces as the style's boxes (their source sizes left out)."""
    return [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]


def elements_of(
    pieces: Sequence[Piece], width: float, height: float, background: str = BACKGROUND
) -> Facade:
    """A derivation's elements (its pieces of one element joined, the wall left out), to
    check the style on."""
    return facade_of(boxes_of(pieces), width, height, background)


def _misfit(p: Piece) -> float:
    """How far a piece's size is from its source's: the squares of the log-ratios."""
    return math.log((p.x1 - p.x0) / p.source_w) ** 2 + math.log((p.y1 - p.y0) / p.source_h) ** 2


def score(pieces: list[Piece], background: str = BACKGROUND) -> float:
    """How far the elements' sizes are from the source's (0: the same)."""
    terms = [_misfit(p) for p in pieces if p.label != background and p.x1 > p.x0 and p.y1 > p.y0]
    return sum(terms) / len(terms) if terms else 0.0


def likeness(pieces: list[Piece]) -> float:
    """How far the pieces' sizes are from the source's, the wall included, each weighted by
    its area (0: the same): a derivation that widens its wall into blank margins is as far
    from the source as one that widens its windows."""
    weighted = [((p.x1 - p.x0) * (p.y1 - p.y0), p) for p in pieces if p.x1 > p.x0 and p.y1 > p.y0]
    area = sum(a for a, _ in weighted)
    return sum(a * _misfit(p) for a, p in weighted) / area if area else 0.0


def apart(a: Sequence[Piece], b: Sequence[Piece], least: float) -> bool:
    """Whether two derivations differ visibly: a label has more elements in one than in
    the other (a bay or a floor gained), or their ``displacement`` is ``least`` or more."""
    counts = [Counter(p.label for p in pieces if p.label != BACKGROUND) for pieces in (a, b)]
    return counts[0] != counts[1] or displacement(a, b) >= least


def displacement(a: Sequence[Piece], b: Sequence[Piece], background: str = BACKGROUND) -> float:
    """How far two derivations' elements are apart: over the elements of each, the mean
    distance (the largest of the four edges') to the nearest element of its label in the
    other, the larger of the two ways round (0: the same elements; an element one has and
    the other not counts its distance to the nearest of its label, or, with none, its
    own size)."""
    return max(_one_way(a, b, background), _one_way(b, a, background))


def _one_way(a: Sequence[Piece], b: Sequence[Piece], background: str) -> float:
    theirs: dict[str, list[tuple[float, float, float, float]]] = {}
    for p in b:
        if p.label != background:
            theirs.setdefault(p.label, []).append((p.x0, p.y0, p.x1, p.y1))
    mine = [p for p in a if p.label != background]
    if not mine:
        return 0.0
    total = 0.0
    for label in {p.label for p in mine}:
        edges = np.array([(p.x0, p.y0, p.x1, p.y1) for p in mine if p.label == label])
        if label not in theirs:
            total += float(np.maximum(edges[:, 2] - edges[:, 0], edges[:, 3] - edges[:, 1]).sum())
            continue
        other = np.array(theirs[label])
        far = np.abs(edges[:, None, :] - other[None, :, :]).max(axis=2)
        total += float(far.min(axis=1).sum())
    return total / len(mine)


PiecesKey = tuple[tuple[str, float, float, float, float], ...]


def pieces_key(pieces: Sequence[Piece]) -> PiecesKey:
    """The pieces as they would be written (to tell two derivations apart)."""
    return tuple(
        sorted(
            (p.label, round(p.x0, 9), round(p.y0, 9), round(p.x1, 9), round(p.y1, 9))
            for p in pieces
        )
    )
