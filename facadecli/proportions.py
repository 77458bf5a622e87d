"""New proportions drawn near a design's own (Bao et al. 2013 draw each region's size from
a truncated Gaussian centred on its size in the input): one place for the draw, shared by
``facade vary`` (a spec's symbols) and ``facade grammar --variations`` (a grammar's parts).

A factor's log is drawn from N(0, ``SPREAD``) and cut at ``MOST``, so sizes stay within
0.9 to 1.1 times their own. Sizes close to each other (``size_classes``; the caller says
how close) form one *class* and get one factor: what was as long as something else still
is (columns over columns, mirrored halves, floors of one kind), and hand-drawn sizes a
little apart do not drift further apart.
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable

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
