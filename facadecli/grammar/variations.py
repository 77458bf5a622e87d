"""The layouts of a new size, and the grammar at every size asked for: of the derivations
the repeat counts allow (:mod:`facadecli.grammar.derive`), the layouts that copy the
source's whole bays and floors instead (:mod:`facadecli.grammar.slabs`) and their
variations (:mod:`facadecli.grammar.vary`), each tidied (:mod:`facadecli.grammar.align`),
the one written keeps the most of the source's style, then is the nearest the source's
sizes, wall included; the other variations (Bao et al. 2013) are drawn among those that
keep as much, each differing visibly from the others.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, NamedTuple

from facadecli import proportions
from facadecli.grammar.align import tidy_derivation
from facadecli.grammar.derive import STRETCH, TooLarge, derive_at, with_runs
from facadecli.grammar.derived_layout import pieces_layout, safe_name
from facadecli.grammar.model import (
    Candidate,
    Constraint,
    DerivedSize,
    Extraction,
    Kept,
    Piece,
    Progress,
    Proportions,
    Shuffle,
    Variation,
    no_progress,
)
from facadecli.grammar.pieces import apart, elements_of, likeness, pieces_key, score
from facadecli.grammar.slabs import retargeted
from facadecli.grammar.split import Grammar, Part
from facadecli.grammar.style import check, style_of
from facadecli.grammar.tiling import Tiling
from facadecli.grammar.vary import (
    CANDIDATES_MAX,
    STYLE_MAX,
    count_offsets,
    drawn_proportions,
    proportioned,
    proportioned_copies,
    shuffles,
)

if TYPE_CHECKING:
    from facadecli.layout import Layout

TEMPERATURE = 0.1  # of the score: how strongly variations near the source's sizes are preferred
APART = 0.01  # of the façade's smaller side: the least mean displacement between variations
SCALE_NOTED = 8.0  # a derived size this many times the input's (or less) is noted


@dataclass(frozen=True)
class Target:
    """A grammar to derive at a new size, and the source's style to keep there."""

    grammar: Grammar  # with its runs (:func:`~facadecli.grammar.derive.with_runs`)
    source: tuple[float, float]
    width: float
    height: float
    style: Sequence[Constraint]

    @property
    def size(self) -> tuple[float, float]:
        return (self.width, self.height)

    def kept(self, pieces: list[Piece]) -> Kept:
        """The source's style a derivation at this size keeps."""
        return check(self.style, elements_of(pieces, self.width, self.height))

    def candidate(
        self, offsets: dict[str, int], shuffle: Shuffle | None = None, drawn: Proportions = ()
    ) -> Candidate | None:
        """The grammar derived here with repeat counts offset, a split's parts shuffled or
        its parts' proportions drawn (None when too large to derive)."""
        rules = self.grammar
        if shuffle is not None:
            rule = rules.rules[shuffle[0]]
            parts = tuple(Part(p.size, s) for p, s in zip(rule.parts, shuffle[1], strict=True))
            rules = replace(rules, rules={**rules.rules, shuffle[0]: replace(rule, parts=parts)})
        if drawn:
            rules = proportioned(rules, drawn, self.source)
        try:
            pieces = derive_at(rules, self.source, self.width, self.height, offsets)
        except TooLarge:
            return None
        changes = tuple(sorted(offsets.items()))
        return Candidate(score(pieces), changes, shuffle, pieces, self.kept(pieces), drawn)


class Laid(NamedTuple):
    """A candidate as written: its pieces tidied, the tidy-up's warnings, the style kept."""

    candidate: Candidate
    pieces: list[Piece]
    warnings: list[str]
    kept: Kept


def derive_variations(
    grammar: Grammar,
    tiling: Tiling,
    width: float,
    height: float,
    name: str,
    count: int,
    seed: int,
    style: Sequence[Constraint] = (),
) -> tuple[list[Variation], list[str]]:
    """Up to ``count`` different layouts of the grammar at a size, and warnings (fewer than
    asked). Candidates vary the best-fitting count of each repeat rule by -1, 0 or +1 (one
    offset per rule, so a rule's copies stay equal and the two halves of a mirrored split
    stay alike; one offset for all repeats of one period along one axis, so columns of
    windows and of their sills stay lined up), where the copies stretch by at most
    ``STRETCH`` (elsewhere the best fit stays); shuffle the parts of a split that are as
    long as each other (``shuffles``); or draw new proportions near the source's
    (``drawn_proportions``, ``proportions.DRAWS`` per variation asked for; never variation 0).

    Variation 0 keeps the most of the source's ``style`` (Bao et al. 2013's constraints),
    and among those it is the nearest the source's sizes (the best fit, when it keeps as
    much as any). The others are drawn at random (``seed``) among the candidates that keep
    every constraint it keeps, then among the rest, favouring low scores, and ordered by
    what they keep and their score; each differs visibly from every one before it
    (``pieces.apart``: more or fewer elements of a label, or its elements a mean
    ``APART`` of the façade's smaller side or more from theirs) and keeps every
    constraint of the style variation 0 keeps (its windows' sizes and floor pitch among
    them), so fewer than ``count`` may exist. Named ``<name>-<W>x<H>`` when ``count`` is
    1, else ``<name>-<W>x<H>-v<K>``."""
    source = (tiling.xs[-1], tiling.ys[-1])
    target = Target(with_runs(grammar, source), source, width, height, style)
    stem = f"{safe_name(name)}-{width:g}x{height:g}"
    names = [stem] if count == 1 else [f"{stem}-v{k}" for k in range(count)]
    ranked = ranked_candidates(candidates(target, count, seed))
    first = first_laid(target, ranked)
    found = [variation_of(first, target, names[0])]
    if count == 1:
        return found, []
    chosen = apart_laid(target, drawn_order(ranked, first, seed), first, count)
    found += [variation_of(laid, target, names[k]) for k, laid in enumerate(chosen, start=1)]
    return found, fewer_note(len(found), count)


def candidates(target: Target, count: int, seed: int) -> list[Candidate | None]:
    """The layouts considered for a size, in the order made (ties are ranked so): the
    grammar's best fit, whole bays copied from the source's own terminals, repeat counts
    offset (also for one layout, when the best fit breaks some of the style), then for
    variations shuffled parts, drawn proportions and copies of drawn proportions."""
    used: set[str] = set()
    best = derive_at(target.grammar, target.source, *target.size, used=used)
    best_kept = target.kept(best)
    found: list[Candidate | None] = [Candidate(score(best), (), None, best, best_kept)]
    at_source: list[Piece] = []
    if target.size != target.source:  # whole bays copied from the source's own terminals
        at_source = derive_at(target.grammar, target.source, *target.source)
        found += copied(target, at_source)
    if count > 1 or best_kept.broken:
        most = CANDIDATES_MAX if count > 1 else STYLE_MAX
        offsets = count_offsets(target.grammar, used, random.Random(seed), most)
        found += [target.candidate(offset) for offset in offsets]
    if count > 1:
        found += [target.candidate({}, shuffle) for shuffle in shuffles(target.grammar)]
        rng = random.Random(seed)
        draws = drawn_proportions(target.grammar, target.source, rng, proportions.DRAWS * count)
        found += [target.candidate({}, None, factors) for factors in draws]
        if target.size != target.source:  # until enough keep the most of the style
            found += copied_proportions(target, at_source, found, count, seed)
    return found


def copied(target: Target, at_source: list[Piece]) -> list[Candidate | None]:
    """Whole bays and floors copied from the source's terminals (``slabs.retargeted``),
    scored with how far their walls stretched."""
    return [
        Candidate(score(pieces) + stretch, (), None, pieces, target.kept(pieces), (), text)
        for pieces, stretch, text in retargeted(
            at_source, target.source, target.width, target.height, target.style
        )
    ]


def copied_proportions(
    target: Target,
    at_source: list[Piece],
    made: list[Candidate | None],
    count: int,
    seed: int,
) -> list[Candidate]:
    """Copies of the source's terminals with drawn proportions, until ``count`` layouts
    keep as much of the style as the best of those ``made``."""
    found = [c for c in made if c is not None]
    most = max(len(c.kept.kept) for c in found)
    good = {pieces_key(c.pieces) for c in found if len(c.kept.kept) >= most}
    return proportioned_copies(
        at_source,
        target.source,
        target.size,
        target.style,
        random.Random(seed),
        target.kept,
        (most, count, good),
    )


def ranked_candidates(made: list[Candidate | None]) -> list[Candidate]:
    """The candidates by rank (most constraints kept, then the best fit, then nearest the
    source), the same pieces once."""
    seen: set[tuple[tuple[str, float, float, float, float], ...]] = set()
    ranked = []
    for candidate in sorted((c for c in made if c is not None), key=lambda c: c.rank):
        key = pieces_key(candidate.pieces)
        if key not in seen:
            seen.add(key)
            ranked.append(candidate)
    return ranked


def first_laid(target: Target, ranked: list[Candidate]) -> Laid:
    """Variation 0: the best of the grammar's and the best of whole bays copied, as each
    is written (tidying makes a near miss of the style exact, so either may keep more in
    the end), the one keeping more of the style, then the likelier. Drawn proportions
    only vary a layout: the layout of a size is the grammar's own."""
    finalists = [
        next((c for c in ranked if not c.proportions and bool(c.retarget) is copies), None)
        for copies in (False, True)
    ]
    laid = [laid_out(target, c) for c in finalists if c is not None]
    return min(laid, key=lambda t: (-len(t.kept.kept), likeness(t.pieces)))


def laid_out(target: Target, candidate: Candidate) -> Laid:
    """A candidate tidied (:func:`~facadecli.grammar.align.tidy_derivation`); at the
    input's own size the best fit is the input itself: nothing to tidy (the QP once
    halved cmp_b0001's windows there, keeping as much of the style)."""
    if target.size == target.source and not candidate.offsets and candidate.shuffle is None:
        return Laid(candidate, candidate.pieces, [], candidate.kept)
    return Laid(candidate, *tidied(target, candidate))


def tidied(target: Target, candidate: Candidate) -> tuple[list[Piece], list[str], Kept]:
    return tidy_derivation(
        candidate.pieces,
        candidate.kept,
        target.kept,
        target.width,
        target.height,
        target.style,
        bool(candidate.retarget),
    )


def drawn_order(ranked: list[Candidate], first: Laid, seed: int) -> list[Candidate]:
    """The candidates other than variation 0's in a weighted draw without replacement
    (Efraimidis and Spirakis: keys u^(1/w)), drawn first among those that keep every
    constraint variation 0 keeps, then among those keeping as many, favouring low scores
    (``TEMPERATURE``)."""
    rng = random.Random(seed)
    return sorted(
        (c for c in ranked if c is not first.candidate),
        key=lambda c: (
            not keeps_all(c.kept, first.kept),
            -len(c.kept.kept),
            -math.log(rng.random() or 1e-300)
            * math.exp(min((c.score - first.candidate.score) / TEMPERATURE, 700.0)),
        ),
    )


def apart_laid(target: Target, drawn: list[Candidate], first: Laid, count: int) -> list[Laid]:
    """Up to ``count - 1`` more variations, in the draw's order, each as written keeping
    every constraint of the style variation 0 keeps (not merely as many: one keeping the
    windows' columns in place of their sizes is another style) and visibly apart from
    every one before it (:func:`~facadecli.grammar.pieces.apart`), ordered by what they
    keep and their rank."""
    chosen: list[Laid] = []
    seen = {pieces_key(first.pieces)}
    shown = [first.pieces]  # the variations so far: another differs visibly from each
    least = APART * min(target.width, target.height)
    for other in drawn:  # aligned, two could still coincide
        if len(chosen) == count - 1:
            break
        if not all(apart(other.pieces, p, least) for p in shown):
            continue  # too near one as derived: not tidied (tidying moves edges a little)
        laid = Laid(other, *tidied(target, other))
        key = pieces_key(laid.pieces)
        if (
            key not in seen
            and keeps_all(laid.kept, first.kept)  # the style, as variation 0 keeps it
            and all(apart(laid.pieces, p, least) for p in shown)
        ):
            seen.add(key)
            shown.append(laid.pieces)
            chosen.append(laid)
    chosen.sort(key=lambda c: (-len(c.kept.kept), c.candidate.rank[2:]))
    return chosen


def keeps_all(kept: Kept, model: Kept) -> bool:
    """Whether a layout keeps every constraint another keeps."""
    return set(model.kept) <= set(kept.kept)


def variation_of(laid: Laid, target: Target, name: str) -> Variation:
    """A laid-out candidate as a named layout and what made it."""
    candidate = laid.candidate
    layout = pieces_layout(laid.pieces, target.width, target.height, name, laid.warnings)
    return Variation(
        layout,
        candidate.offsets,
        candidate.score,
        laid.kept,
        candidate.shuffle,
        candidate.proportions,
        tuple(laid.pieces),
        candidate.retarget,
    )


def fewer_note(made: int, count: int) -> list[str]:
    """The note when fewer variations exist than asked for."""
    if made >= count:
        return []
    return [
        f"only {made} of {count} variations exist (repeat counts within 1 of the "
        f"best fit whose copies stretch by at most {STRETCH:.0%}, parts of a split "
        "that are as long as each other in a new order, and parts' proportions drawn "
        "near the source's; each keeping every constraint of the style the first keeps, "
        f"with more or fewer elements, or its elements a mean {APART:.0%} of the façade's "
        "smaller side or more from every other's)"
    ]


def derive_layout(
    grammar: Grammar, tiling: Tiling, width: float, height: float, name: str
) -> Layout:
    """The grammar at a new size as a layout named ``<name>-<W>x<H>`` (the name with every
    character a layout name cannot hold made ``_``): :func:`derive_variations`' first, with
    the style of the tiling the grammar comes from."""
    drawn, _ = derive_variations(grammar, tiling, width, height, name, 1, 0, style_of(tiling))
    return drawn[0].layout


def derive_sizes(
    extraction: Extraction,
    name: str,
    sizes: list[tuple[float, float]],
    variations: int = 1,
    seed: int = 0,
    progress: Progress = no_progress,
) -> list[DerivedSize]:
    """The grammar derived at every size, with up to ``variations`` layouts each (raises
    :class:`~facadecli.grammar.derive.TooLarge` for a size too large to derive)."""
    derived = []
    style = extraction.style
    source = (extraction.tiling.xs[-1], extraction.tiling.ys[-1])
    for width, height in sizes:
        progress(f"deriving at {width:g}x{height:g}")
        drawn, notes = derive_variations(
            extraction.grammar, extraction.tiling, width, height, name, variations, seed, style
        )
        scale = max(width / source[0], height / source[1], source[0] / width, source[1] / height)
        if scale > SCALE_NOTED:
            notes = [
                f"the input is {source[0]:g} x {source[1]:g} and this size {scale:.0f} times it "
                "along an axis: its elements are that many times larger or smaller (a CMP "
                "annotation is a unit square: give --size WxH in metres)",
                *notes,
            ]
        derived.append(
            DerivedSize(
                width,
                height,
                [v.layout for v in drawn],
                notes,
                [v.kept for v in drawn],
                [v.retarget or "grammar" for v in drawn],
            )
        )
    return derived
