"""The ways a derivation is varied (Bao et al. 2013), each a candidate for
:func:`~facadecli.grammar.variations.derive_variations`: repeat counts one more or one
fewer than the best fit (:func:`count_offsets`), parts of a split as long as each other
in a new order (:func:`shuffles`), new proportions drawn near the source's for the
grammar's parts (:func:`drawn_proportions`, :func:`proportioned`) and for the source's
terminals before whole bays are copied (:func:`proportioned_copies`)."""

from __future__ import annotations

import itertools
import random
from collections import defaultdict
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace

from facadecli import proportions
from facadecli.grammar.align import ALIGN
from facadecli.grammar.derive import THIN
from facadecli.grammar.model import Candidate, Constraint, Kept, Piece, Proportions, Shuffle
from facadecli.grammar.pieces import elements_of, pieces_key, score
from facadecli.grammar.slabs import retargeted
from facadecli.grammar.split import Grammar, Part
from facadecli.grammar.style import check
from facadecli.grammar.tiling import BACKGROUND

CANDIDATES_MAX = 729  # repeat-count choices tried per size (all of them when fewer: 3^6)
SHUFFLES_MAX = 6  # new orders of one split rule's parts tried as variations
STYLE_MAX = 81  # ... and for one layout, when the best fit breaks some of the style (3^4)


def count_offsets(
    grammar: Grammar, used: set[str], rng: random.Random, most: int
) -> Iterator[dict[str, int]]:
    """Changes to the best-fitting repeat counts (see :func:`derive_variations`): every
    choice of -1, 0 or +1 per group of repeats when there are at most ``most``, else
    ``most`` drawn at random."""
    linked: dict[tuple[str, float], list[str]] = defaultdict(list)
    for symbol in sorted(used):  # repeats of one period along one axis vary together
        rule = grammar.rules[symbol]
        period = rule.parts[:2] if rule.op == "run" else rule.parts
        linked[(rule.axis, round(sum(p.size for p in period), 6))].append(symbol)
    groups = [linked[k] for k in sorted(linked)]
    if 3 ** len(groups) <= most:
        choices = list(itertools.product((-1, 0, 1), repeat=len(groups)))
    else:
        choices = sorted({tuple(rng.choice((-1, 0, 1)) for _ in groups) for _ in range(most)})
    for choice in choices:
        offsets = {s: o for g, o in zip(groups, choice, strict=True) if o for s in g}
        if offsets:
            yield offsets


def shuffles(grammar: Grammar) -> list[Shuffle]:
    """New orders of split rules' parts (Bao et al. 2013's shuffles, ABB -> BAB): parts as
    long as each other (and not plain wall) change places; a mirrored split's centre stays,
    and its halves stay mirrored (the rule lays them). At most ``SHUFFLES_MAX`` a rule."""
    found: list[Shuffle] = []
    for name in sorted(grammar.rules):
        rule = grammar.rules[name]
        if rule.op not in ("split", "symsplit"):
            continue
        movable = len(rule.parts) - (1 if rule.op == "symsplit" and rule.centre else 0)
        by_size: dict[float, list[int]] = defaultdict(list)
        for i, part in enumerate(rule.parts[:movable]):
            if part.symbol != BACKGROUND:
                by_size[round(part.size, 6)].append(i)
        symbols = [p.symbol for p in rule.parts]
        for places in by_size.values():
            here = [symbols[i] for i in places]
            if len(set(here)) < 2:
                continue
            orders = sorted(set(itertools.permutations(here)) - {tuple(here)})
            for order in orders[:SHUFFLES_MAX]:
                new = list(symbols)
                for i, symbol in zip(places, order, strict=True):
                    new[i] = symbol
                found.append((name, tuple(new)))
    return found


def drawn_proportions(
    grammar: Grammar, source: tuple[float, float], rng: random.Random, draws: int
) -> list[Proportions]:
    """``draws`` sets of new proportions (:mod:`facadecli.proportions`): a factor per class
    of part sizes along an axis (sizes within ``ALIGN`` of the façade's extent), so parts
    of one size, in whatever rule, stay alike."""
    keys: list[tuple[str, str, int]] = []  # axis, size, class
    for axis, extent in zip(("x", "y"), source, strict=True):
        sizes = {
            part.size
            for rule in grammar.rules.values()
            if rule.op != "gridsplit" and rule.axis == axis
            for part in rule.parts
        }
        classes = proportions.size_classes(sizes, ALIGN * extent)
        keys += [(axis, size_key(size), number) for size, number in sorted(classes.items())]
    found = []
    for _ in range(draws if keys else 0):
        factors: dict[tuple[str, int], float] = {}
        for axis, _, number in keys:
            if (axis, number) not in factors:
                factors[(axis, number)] = proportions.factor(rng)
        found.append(tuple((axis, size, factors[(axis, number)]) for axis, size, number in keys))
    return found


def size_key(size: float) -> str:
    return f"{size:.6g}"


def proportioned(grammar: Grammar, drawn: Proportions, source: tuple[float, float]) -> Grammar:
    """The grammar with its parts' sizes multiplied by their factors; parts thinner than
    ``THIN`` keep their size (frames and sills keep their absolute size anyway)."""
    factor = {(axis, size): f for axis, size, f in drawn}
    thin = {"x": THIN * source[0], "y": THIN * source[1]}
    rules = {}
    for name, rule in grammar.rules.items():
        if rule.op == "gridsplit":
            rules[name] = rule
            continue
        parts = tuple(
            p
            if p.size < thin[rule.axis]
            else Part(p.size * factor[(rule.axis, size_key(p.size))], p.symbol)
            for p in rule.parts
        )
        rules[name] = replace(rule, parts=parts)
    return replace(grammar, rules=rules)


def proportioned_copies(
    source_pieces: list[Piece],
    source: tuple[float, float],
    size: tuple[float, float],
    style: Sequence[Constraint],
    rng: random.Random,
    kept: Callable[[list[Piece]], Kept],
    wanted: tuple[int, int, set[tuple[tuple[str, float, float, float, float], ...]]],
) -> list[Candidate]:
    """Whole bays and floors copied (:func:`~facadecli.grammar.slabs.retargeted`) from the
    source's terminals with new proportions (:func:`facadecli.proportions.warp` along
    each axis): variations of a copied layout that keep its style, where a façade has
    one good way to be copied. A draw that keeps less of the style at the source's size
    is skipped; the pieces keep their sizes in the source, so the score says how far the
    draw moved them. ``wanted`` = (most, count, good): draws stop once ``count``
    different layouts keep ``most`` of the style (``good`` holds those found already,
    :func:`pieces_key`), and after ``count`` copied or ``proportions.DRAWS`` times as many
    drawn (the work counted in draws, not time)."""

    def kept_at_source(pieces: list[Piece]) -> int:
        return len(check(style, elements_of(pieces, *source)).kept)

    whole = kept_at_source(source_pieces)
    found: list[Candidate] = []
    most, count, good = wanted
    good = set(good)
    copied = 0
    for _ in range(proportions.DRAWS * count):
        if copied == count or len(good) >= count:
            break
        xs, drawn_x = proportions.warp(
            [(p.x0, p.x1, p.label) for p in source_pieces],
            source[0],
            ALIGN * source[0],
            rng,
            mirrored=any(c.kind in ("symmetry", "centre") for c in style),
        )
        ys, drawn_y = proportions.warp(
            [(p.y0, p.y1, p.label) for p in source_pieces], source[1], ALIGN * source[1], rng
        )
        moved = [
            replace(p, x0=xs[p.x0], x1=xs[p.x1], y0=ys[p.y0], y1=ys[p.y1]) for p in source_pieces
        ]
        if kept_at_source(moved) < whole:
            continue
        copied += 1
        drawn: Proportions = (
            *(("x", kind, f) for kind, f in drawn_x),
            *(("y", kind, f) for kind, f in drawn_y),
        )
        for pieces, stretch, text in retargeted(moved, source, *size, style):
            made = f"{text}; proportions drawn"
            found.append(
                Candidate(score(pieces) + stretch, (), None, pieces, kept(pieces), drawn, made)
            )
            if len(found[-1].kept.kept) >= most:
                good.add(pieces_key(pieces))
    return found
