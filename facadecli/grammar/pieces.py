"""A derived layout's terminals: each a labelled rectangle with its size in the source
layout (the derivations of :mod:`facadecli.grammar.variation` and the copied bays of
:mod:`facadecli.grammar.slabs` make them)."""

from __future__ import annotations

from dataclasses import dataclass


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
