"""A derived layout's terminals: each a labelled rectangle with its size in the source
layout (the derivations of :mod:`facadecli.grammar.variation` and the copied bays of
:mod:`facadecli.grammar.slabs` make them), and how far their sizes are from the source's."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from facadecli.grammar.inputs import BACKGROUND
from facadecli.grammar.style import Box, Facade, facade_of


@dataclass(frozen=True)
class Piece:
    """A derived terminal rectangle and its size in the source layout."""

    label: str
    x0: float
    y0: float
    x1: float
    y1: float
    source_w: float
    source_h: float


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
