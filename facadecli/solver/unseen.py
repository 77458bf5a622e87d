"""A lower bound on the candidates an axis never makes: those with a word longer than the
candidate space's reach (twice the canvas), which the passes of the exact search never see.

Two facts make it strong where the space's own bound (the smallest symbol's size, squared,
over 4) is not:

- **The core.** A pattern with a single word gives every candidate the same rows. The
  relaxation of those rows alone (:func:`.construct.relax`, each row filling the canvas
  unless some layer in front could make room in it) bounds what their symbols deviate in
  every layout of every candidate.
- **The band.** Taking a repeat away from a word takes its letters away, and a word with
  fewer letters fits more easily: shrinking a word's letters into the canvas (each at
  least its ``min``) costs no more than shrinking a longer word's. A word longer than the
  reach, less one repeat at a time, comes down to a word no longer than the reach but
  longer than it less the most one repeat takes away (the *band*): every unseen word costs
  at least the least of the band's words, which are all made. Only for a pattern without
  alternations: a word keeps its branches, and a branch may have no word within the reach
  (then only the core bounds).

The objective sums over symbols, so what the core's symbols deviate and what a band word's
other symbols must shrink add up: the bound is the core's plus the least band word's."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from typing import NamedTuple

from facadecli.patterns.ast import Alt, Fixed, Named, Node, Seq, Sym, walk
from facadecli.patterns.words import Word
from facadecli.solver import construct
from facadecli.solver.budgets import NEAR
from facadecli.solver.candidates import CandidateSpace, PatternUse, finite
from facadecli.solver.rows import Row, RowCache, WordTraits, make_rows
from facadecli.spec.model import Spec

INF = math.inf
SHRINK_STEPS = 60  # halvings of the multiplier's interval (a bound at every step)


class Unseen(NamedTuple):
    """Lower bounds of an axis beyond its candidates' own."""

    every: float  # on every candidate's objective (the core's relaxation)
    beyond: float  # on every candidate with a word beyond the reach


def unseen_bounds(
    spec: Spec,
    uses: Sequence[PatternUse],
    space: CandidateSpace,
    canvas: float,
    full: frozenset[int],
) -> Unseen:
    """The bounds of the core and of the candidates never made (``beyond`` at least
    ``space.beyond``)."""
    core = core_rows(spec, uses, space, full)
    relaxed = construct.relax(spec, core, canvas, _gives_way(uses, full)) if core else None
    if core and relaxed is None:
        return Unseen(INF, INF)  # the rows every candidate has cannot fit the canvas
    every = 0.0 if relaxed is None else relaxed.bound
    taken = {letter.symbol for rows in core.values() for row in rows for letter in row.word}
    reach = space.reach * canvas
    least = INF
    for use in uses:
        if use.key not in space.reached:
            continue  # every word of it is made
        words = space.words[use.key]
        if not any(item.length <= reach for item in words):
            return Unseen(every, max(every, space.beyond))  # its words start beyond the reach
        if not descends(use):
            least = 0.0  # a word beyond the reach may have no made word under it
            break
        step = repeat_step(use, spec)
        band = [item for item in words if reach - step < item.length <= reach]
        shrunk = (_shrink(spec, item.word, taken, canvas) for item in band)
        least = min(least, min(shrunk, default=0.0))
    return Unseen(every, max(every, space.beyond, every + least if least < INF else INF))


def core_rows(
    spec: Spec, uses: Sequence[PatternUse], space: CandidateSpace, full: frozenset[int]
) -> dict[str, list[Row]]:
    """The rows of the layers whose pattern has a single word, by group: every candidate
    has them."""
    members: dict[str, list[tuple[int, Word]]] = {}
    for use in uses:
        words = space.words.get(use.key, [])
        if finite(use) and use.key not in space.reached and len(words) == 1:
            for layer, group in use.layers:
                members.setdefault(group, []).append((layer, words[0].word))
    known: WordTraits = {}
    cache = RowCache()
    return {group: make_rows(spec, found, full, known, cache) for group, found in members.items()}


def _gives_way(uses: Sequence[PatternUse], full: frozenset[int]) -> construct.GivesWay:
    """Whether a row may make room for a layer in front in *some* candidate: a layer of its
    group in front of it shows all along the other axis (what :meth:`.Row.covers` asks of
    a row in front, whatever its word)."""
    layers: dict[str, list[int]] = {}
    for use in uses:
        for layer, group in use.layers:
            layers.setdefault(group, []).append(layer)
    group_of = {layer: group for use in uses for layer, group in use.layers}

    def gives_way(row: Row, rows: Sequence[Row]) -> bool:
        group = group_of[row.lowest]
        return any(other > row.highest and other in full for other in layers[group])

    return gives_way


def descends(use: PatternUse) -> bool:
    """Whether every word of the pattern comes down, one repeat at a time, to its shortest:
    no alternation (a word keeps its branches as its repeats go, and a branch whose
    shortest word is beyond the reach has no made word under it) and no contents."""
    return not use.pattern.contents and not any(
        isinstance(node, Alt) for node in walk(use.pattern.root)
    )


def repeat_step(use: PatternUse, spec: Spec) -> float:
    """The most length (preferred sizes) that taking one repeat away from a word of the
    pattern removes: one count less of a counter takes a body from every repeat it counts.
    INF where that is not bounded or not known (a counted repeat inside another, or a
    pattern with contents): then every word is in the band."""
    if use.pattern.contents:
        return INF
    steps: dict[object, float] = {}
    if not _steps(use.pattern.root, spec, 1, False, steps):
        return INF
    return max(steps.values(), default=0.0)


def _steps(node: Node, spec: Spec, times: int, counted: bool, steps: dict[object, float]) -> bool:
    """Add to ``steps`` what one count less of each counter of ``node`` takes away (the
    node shows ``times`` times); False when a counted repeat is inside another."""
    if isinstance(node, Sym):
        return True
    if isinstance(node, Seq):
        return all(_steps(item, spec, times, counted, steps) for item in node.items)
    if isinstance(node, Alt):
        return all(_steps(branch, spec, times, counted, steps) for branch in node.branches)
    if isinstance(node.count, Fixed):
        return _steps(node.body, spec, times * abs(node.count.value), counted, steps)
    if counted:
        return False
    key = node.count.name if isinstance(node.count, Named) else id(node)
    steps[key] = steps.get(key, 0.0) + times * _longest(node.body, spec)
    return _steps(node.body, spec, times, True, steps)


def _longest(node: Node, spec: Spec) -> float:
    """The longest a node makes at preferred sizes (INF with a counted repeat in it)."""
    if isinstance(node, Sym):
        symbol = spec.symbols.get(node.name)
        return (symbol.size if symbol is not None else None) or 0.0
    if isinstance(node, Seq):
        return sum(_longest(item, spec) for item in node.items)
    if isinstance(node, Alt):
        return max((_longest(branch, spec) for branch in node.branches), default=0.0)
    if isinstance(node.count, Fixed):
        return abs(node.count.value) * _longest(node.body, spec)
    return INF


def _shrink(spec: Spec, word: Word, taken: set[str], canvas: float) -> float:
    """A lower bound on what the sized symbols of ``word`` outside ``taken`` deviate when
    the word is laid within the canvas (the symbols in ``taken`` at their ``min`` at
    least, placeholders at 0 at least): the Lagrangian dual of that one-row program at a
    multiplier found by bisection (every multiplier gives a lower bound)."""
    counts: Counter[str] = Counter(letter.symbol for letter in word)
    room = canvas
    own: list[tuple[int, float, float]] = []  # (count, preferred, least)
    for name, count in counts.items():
        symbol = spec.symbols.get(name)
        if symbol is None or symbol.size is None:
            continue
        least = symbol.min or 0.0
        if name in taken:
            room -= count * least
        else:
            own.append((count, symbol.size, least))
    if _filled(own, 0.0) <= room:  # fits with every symbol at its size (or its min)
        return _dual(own, room, 0.0)
    if sum(count * least for count, _, least in own) > room + NEAR * max(1.0, canvas):
        return INF  # not even at their min: the word cannot be laid on the canvas
    low, high = 0.0, 1.0
    while _filled(own, high) > room and high < 1e15:
        high *= 2.0
    best = 0.0
    for _ in range(SHRINK_STEPS):
        middle = (low + high) / 2.0
        best = max(best, _dual(own, room, middle))
        if _filled(own, middle) > room:
            low = middle
        else:
            high = middle
    return max(best, _dual(own, room, low), _dual(own, room, high))


def _sizes(own: Sequence[tuple[int, float, float]], multiplier: float) -> list[float]:
    return [max(least, size - multiplier * count / 2.0) for count, size, least in own]


def _filled(own: Sequence[tuple[int, float, float]], multiplier: float) -> float:
    return sum(c * x for (c, _, _), x in zip(own, _sizes(own, multiplier), strict=True))


def _dual(own: Sequence[tuple[int, float, float]], room: float, multiplier: float) -> float:
    """The dual function at ``multiplier``: a lower bound on min sum (x - p)^2 subject to
    sum c x <= room and x >= least."""
    xs = _sizes(own, multiplier)
    value = sum((x - p) ** 2 for (_, p, _), x in zip(own, xs, strict=True))
    return value + multiplier * (_filled(own, multiplier) - room)
