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
from dataclasses import replace
from typing import TYPE_CHECKING

from facadecli import proportions
from facadecli.grammar.align import tidy_derivation
from facadecli.grammar.derive import STRETCH, TooLarge, derive_at, with_runs
from facadecli.grammar.derived_layout import pieces_layout, safe_name
from facadecli.grammar.model import (
    Candidate,
    DerivedSize,
    Extraction,
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
from facadecli.grammar.style import Constraint, Kept, check, style_of
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
    as much, then among the rest, favouring low scores, and ordered by what they keep and
    their score; each differs visibly from every one before it (``pieces.apart``: more
    or fewer elements of a label, or its elements a mean ``APART`` of the façade's smaller
    side or more from theirs) and
    keeps as much of the style as variation 0, so fewer than ``count`` may exist. Named
    ``<name>-<W>x<H>`` when ``count`` is 1, else ``<name>-<W>x<H>-v<K>``."""
    source = (tiling.xs[-1], tiling.ys[-1])
    stem = f"{safe_name(name)}-{width:g}x{height:g}"
    grammar = with_runs(grammar, source)

    def named(k: int) -> str:
        return stem if count == 1 else f"{stem}-v{k}"

    def kept(pieces: list[Piece]) -> Kept:
        return check(style, elements_of(pieces, width, height))

    def candidate(
        offsets: dict[str, int], shuffle: Shuffle | None = None, drawn: Proportions = ()
    ) -> Candidate | None:
        rules = grammar
        if shuffle is not None:
            rule = grammar.rules[shuffle[0]]
            parts = tuple(Part(p.size, s) for p, s in zip(rule.parts, shuffle[1], strict=True))
            rules = replace(
                grammar, rules={**grammar.rules, shuffle[0]: replace(rule, parts=parts)}
            )
        if drawn:
            rules = proportioned(rules, drawn, source)
        try:
            pieces = derive_at(rules, source, width, height, offsets)
        except TooLarge:
            return None
        changes = tuple(sorted(offsets.items()))
        return Candidate(score(pieces), changes, shuffle, pieces, kept(pieces), drawn)

    used: set[str] = set()
    best = derive_at(grammar, source, width, height, used=used)
    best_kept = kept(best)
    candidates: list[Candidate | None] = [Candidate(score(best), (), None, best, best_kept)]
    if (width, height) != source:  # whole bays copied from the source's own terminals
        at_source = derive_at(grammar, source, *source)
        for pieces, stretch, text in retargeted(at_source, source, width, height, style):
            candidates.append(
                Candidate(score(pieces) + stretch, (), None, pieces, kept(pieces), (), text)
            )
    if count > 1 or best_kept.broken:
        rng = random.Random(seed)
        most = CANDIDATES_MAX if count > 1 else STYLE_MAX
        candidates += [candidate(offsets) for offsets in count_offsets(grammar, used, rng, most)]
    if count > 1:
        candidates += [candidate({}, shuffle) for shuffle in shuffles(grammar)]
        rng = random.Random(seed)
        draws = drawn_proportions(grammar, source, rng, proportions.DRAWS * count)
        candidates += [candidate({}, None, factors) for factors in draws]
        if (width, height) != source:  # until enough keep the most of the style
            size = (width, height)
            made = [c for c in candidates if c is not None]
            most = max(len(c.kept.kept) for c in made)
            good = {pieces_key(c.pieces) for c in made if len(c.kept.kept) >= most}
            candidates += proportioned_copies(
                at_source, source, size, style, random.Random(seed), kept, (most, count, good)
            )
    # most constraints kept, then the best fit, then nearest the source; the same pieces once
    seen: set[tuple[tuple[str, float, float, float, float], ...]] = set()
    ranked = []
    for found_one in sorted((c for c in candidates if c is not None), key=lambda c: c.rank):
        key = pieces_key(found_one.pieces)
        if key not in seen:
            seen.add(key)
            ranked.append(found_one)
    # drawn proportions only vary a layout: the layout of a size is the grammar's own
    # the best of the grammar's and the best of whole bays copied, as each is written:
    # tidying makes a near miss of the style exact, so either may keep more in the end
    finalists = [
        next((c for c in ranked if not c.proportions and bool(c.retarget) is copied), None)
        for copied in (False, True)
    ]
    # at the input's own size the best fit is the input itself: nothing to tidy (the QP
    # once halved cmp_b0001's windows there, keeping as much of the style)
    tidied = [
        (c, c.pieces, [], c.kept)
        if (width, height) == source and not c.offsets and c.shuffle is None
        else (c, *tidy_derivation(c.pieces, c.kept, kept, width, height, style, bool(c.retarget)))
        for c in finalists
        if c is not None
    ]
    first, aligned, warnings, keeps = min(tidied, key=lambda t: (-len(t[3].kept), likeness(t[1])))
    layout = pieces_layout(aligned, width, height, named(0), warnings)
    found = [
        Variation(
            layout,
            first.offsets,
            first.score,
            keeps,
            first.shuffle,
            (),
            tuple(aligned),
            first.retarget,
        )
    ]
    if count == 1:
        return found, []
    # a weighted draw without replacement (Efraimidis and Spirakis): keys u^(1/w), drawn
    # first among the candidates that keep as much of the style as variation 0
    rng = random.Random(seed)
    drawn = sorted(
        (c for c in ranked if c is not first),
        key=lambda c: (
            -len(c.kept.kept),
            -math.log(rng.random() or 1e-300)
            * math.exp(min((c.score - first.score) / TEMPERATURE, 700.0)),
        ),
    )
    chosen: list[tuple[Candidate, list[Piece], list[str], Kept]] = []
    aligned_seen = {pieces_key(aligned)}
    shown = [aligned]  # the variations so far: another differs visibly from each
    least = APART * min(width, height)
    for other in drawn:  # aligned, two could still coincide
        if len(chosen) == count - 1:
            break
        if not all(apart(other.pieces, p, least) for p in shown):
            continue  # too near one as derived: not tidied (tidying moves edges a little)
        moved, moved_warnings, keeps = tidy_derivation(
            other.pieces, other.kept, kept, width, height, style, bool(other.retarget)
        )
        key = pieces_key(moved)
        if (
            key not in aligned_seen
            and len(keeps.kept) >= len(found[0].kept.kept)  # the style, as variation 0 keeps it
            and all(apart(moved, p, least) for p in shown)
        ):
            aligned_seen.add(key)
            shown.append(moved)
            chosen.append((other, moved, moved_warnings, keeps))
    chosen.sort(key=lambda c: (-len(c[3].kept), c[0].rank[2:]))
    for k, (other, moved, moved_warnings, keeps) in enumerate(chosen, start=1):
        layout = pieces_layout(moved, width, height, named(k), moved_warnings)
        found.append(
            Variation(
                layout,
                other.offsets,
                other.score,
                keeps,
                other.shuffle,
                other.proportions,
                tuple(moved),
                other.retarget,
            )
        )
    notes = []
    if len(found) < count:
        notes.append(
            f"only {len(found)} of {count} variations exist (repeat counts within 1 of the "
            f"best fit whose copies stretch by at most {STRETCH:.0%}, parts of a split "
            "that are as long as each other in a new order, and parts' proportions drawn "
            "near the source's; each keeping as much of the style as the first, with more "
            f"or fewer elements, or its elements a mean {APART:.0%} of the façade's smaller "
            "side or more from every other's)"
        )
    return found, notes


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
