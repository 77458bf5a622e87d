"""New proportions drawn near a design's own (Bao et al. 2013 draw each region's size from
a truncated Gaussian centred on its size in the input): one place for the draw, shared by
``facade vary`` (a spec's symbols) and ``facade grammar --variations`` (a grammar's parts).

A factor's log is drawn from N(0, ``SPREAD``) and cut at ``MOST``, so sizes stay within
0.9 to 1.1 times their own. Sizes close to each other (``size_classes``; the caller says
how close) form one *class* and get one factor: what was as long as something else still
is (columns over columns, mirrored halves, floors of one kind), and hand-drawn sizes a
little apart do not drift further apart. ``warp`` draws the same factors for a layout
already laid out (the stretches between its edges), so that its bays can then be copied
with new proportions (``facade grammar --variations``).
"""

from __future__ import annotations

import bisect
import itertools
import math
import random
from collections.abc import Iterable, Sequence

SPREAD = 0.05  # sd of a factor's log
MOST = 0.1  # ... cut here
DRAWS = 3  # proportions drawn per variation asked for (the caller keeps the best of them)
CLASS_SHARE = 0.02  # sizes this share of the largest apart or less are one class (a spec)


def factor(rng: random.Random) -> float:
    """One drawn factor, rounded to 6 decimals (the same on every machine)."""
    return round(math.exp(max(-MOST, min(MOST, rng.gauss(0.0, SPREAD)))), 6)


def size_classes(sizes: Iterable[float], width: float) -> dict[float, int]:
    """Each size's class: sorted, a class starts at a size more than ``width`` above the
    least of the class before (classes of bounded width: no chains)."""
    classes: dict[float, int] = {}
    least: float | None = None
    number = -1
    for size in sorted(set(sizes)):
        if least is None or size - least > width:
            least, number = size, number + 1
        classes[size] = number
    return classes


def warp(
    spans: Sequence[tuple[float, float, str]],
    extent: float,
    near: float,
    rng: random.Random,
    mirrored: bool = False,
) -> tuple[dict[float, float], tuple[tuple[str, float], ...]]:
    """New proportions for a laid-out axis: where each edge of ``spans`` (lo, hi, label;
    they tile ``0``-``extent``, a label's spans may overlap others) goes, and the factors
    drawn. The axis is cut at every edge; each stretch between two edges is scaled by a
    factor drawn per *kind* of stretch (its length's class, within ``near``, and the
    labels of the spans covering it), then all alike so that they fill ``extent``
    again. Stretches of one kind stay alike, so what was on one column or evenly spaced
    mostly still is. ``mirrored``: the warp is made its own mirror image (the mean of it
    and its reflection about the centre), so a mirrored layout stays mirrored and
    whatever was on the centre line stays there."""
    edges = sorted({v for lo, hi, _ in spans for v in (lo, hi)})
    if len(edges) < 2:
        return {v: v for v in edges}, ()
    stretches = list(itertools.pairwise(edges))
    classes = size_classes([b - a for a, b in stretches], near)
    kinds = [
        (classes[b - a], tuple(sorted({label for lo, hi, label in spans if lo <= a and hi >= b})))
        for a, b in stretches
    ]
    drawn = {kind: factor(rng) for kind in sorted(set(kinds))}
    lengths = [(b - a) * drawn[kind] for (a, b), kind in zip(stretches, kinds, strict=True)]
    scale = (edges[-1] - edges[0]) / sum(lengths)
    moved = [edges[0], *(edges[0] + scale * s for s in itertools.accumulate(lengths))]
    if mirrored:
        reflected = [extent - v for v in reversed(edges)]
        image = [extent - v for v in reversed(moved)]
        moved = [(m + _at(v, reflected, image)) / 2 for v, m in zip(edges, moved, strict=True)]
    moved[0], moved[-1] = edges[0], edges[-1]  # exactly, whatever the rounding
    named = tuple((f"{size} {'+'.join(labels)}", f) for (size, labels), f in drawn.items())
    return dict(zip(edges, moved, strict=True)), named


def _at(x: float, xs: Sequence[float], ys: Sequence[float]) -> float:
    """The piecewise-linear function through (xs, ys) (xs increasing) at ``x``."""
    i = min(max(bisect.bisect_right(xs, x), 1), len(xs) - 1)
    x0, x1, y0, y1 = xs[i - 1], xs[i], ys[i - 1], ys[i]
    return y0 if x1 == x0 else y0 + (y1 - y0) * (x - x0) / (x1 - x0)
