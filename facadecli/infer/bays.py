"""Shared bay kinds: a façade's elements as one sequence of bays, written with counters
(issue 34).

A *bay* is a vertical strip of the façade cut on its openings (``CUTS``: windows and
doors; a window with the windows over it, the door with the windows over it): openings
overlapping along x are one strip, and each wall between two strips is cut at its
middle, or beside a pillar of its own standing across the middle (``_wall_cut``: the
cut moves no further than the pillar reaches); the first and last bays reach as far
out as half the wall on their inner side, and over what stands wholly in the margin
beyond (a pillar beside the first window column). Every other element (a sill, a
blind, a balcony under one window, a pillar in a wall) is in the bay it stands in; one
that stands across a cut all the same (a balcony or a cornice over two bays, a shop
front) or out at the façade's edge is in none: it stays as the structure put it, in a
layer of its own (``Bays.apart``) with its own x word. Bands across the façade
(``layers.BAND``) are in no bay either; one standing within a bay stands apart too.

Bays whose openings are alike (label, place in the bay, size and rows within ``ALIKE``
of the bay's width, read as drawn or mirrored) are one *kind*, compared about the middle
of their openings and measured by their nearer pitch (``Frames``: where the cut between
two bays fell does not make them unlike), else as cut. A bay drawn once that differs from
a kind of several bays in at most ``ODD`` opening each way is a *variant* of it
(``_variants``): its own kind, written once, on its base's width and symbols. Of the
bays' other elements, those every bay of the kind shows alike stay in it, the rest stand
apart (a balcony on one of them). Each kind is put on one shape (the median of its
bays, so that every layer's word repeats it exactly) on one set of lines along x that
its layers share (``_lined``: edges within ``COLUMN`` are one, so every layer writes
its gaps in the bay between the same lines), and the façade's x words become
one sequence of bays, written alike in every layer that stands in bays (each layer shows its own
elements; a bay where it shows none is one hidden spacer): a repeated unit of one or
two bays (never a unique label's: a door's bay is written once) gets a counter, at
most ``COUNTERS`` of them; kinds found only at the façade's ends share one counter
that can only drop them (its most: one, as drawn), unless no other bay may repeat
(``_ends_repeat``: then it has no most, and a spare copy of the last bay, at most one,
lets the end bays change one at a time, ``_spare``; not where the façade is mirrored,
which keeps its mirror and a word a layer); a door's bay is unique unless
every bay has a door (``_unique``).
Where no unit repeats (a façade
drawn by hand, each bay a little unlike every other: most of CMP's), each inner bay
but a unique one is written once with a counter, at one where drawn, so the layout at
the input's size is the drawing's and a façade of another width drops or gains copies
of those bays (``_drawn_once``: bays the same way in from either end on one counter,
every other such pair on a second). They are counted in the smallest unit that repeats
(``_units``): single bays, or, where single bays hold unlike numbers of openings (a
column of windows beside a narrow bay of one attic window), pairs side by side whose
openings are alike, so that the façade gains and drops a column with its narrow bay
and keeps its windows a metre; where one counter holds every unit and drops more than
``1 - NARROWEST`` of the bays at once, a spare copy of the last unit (``_spare_unit``)
lets them change one at a time. Where those units hold more windows a metre than the
façade as a whole (its end bays, a door's bay or its margins hold fewer), the copies a
wider façade gains are a counter of their own, nested in each unit, each with a wall
before it that puts it at the façade's windows a metre (``_gains``). A sequence that
reads the same mirrored is written
as its left half, the middle and the half reflected (SPEC 2.2), so a wider façade
gains bays on both sides alike.

The openings make the bays; a kind's other elements (sills, blinds, ledges: the
openings' companions) stand on its shape only where that keeps every one of them within
``FOLLOW`` of where it was drawn, the tidy-up's own move limit (thin ones drawn a good
share of their size off their row in some bay would move further), or within ``HELD``
where the looser limit would cost the façade its bays (``_faithful``). A slot further
only along y (a thin sill drawn a good share of its height off its row in some bay)
stands on the shape along x and on one row of its own along y (the structure's where
it has one in every bay of the kind, else their median where each element stays a
companion of its openings: touching them, not behind one, its height within
``SIZED`` but in at most ``ODD`` bay of several, a hand's outlier), as many such
slots as keep the layout within ``KEEP`` of the structure's IoU, the cheapest first.
Otherwise a slot's elements stay as the structure put them, in
layers of their own off the bays (``Bays.apart``), with their own x words, and do not
follow their windows when the façade gains or drops bays.

Every bay's letters keep their size but the wall after its last element, which every
layer's word of the bay ends with (one symbol a kind: the layers stay together) and
which may narrow to ``WALL`` of itself; the two margins take the rest of the slack. A
façade of another width gains or drops whole bays (narrower, it keeps a bay more where
narrowing the walls between them lets it). Where the openings mirror about the
façade's middle, the bays stand in the middle (their frames shifted on the elements, as
far as each bay's elements stay inside it): the two margins are one symbol, so the
façade keeps its axis in the middle whatever bays it gains or drops.
A façade this cannot narrow to ``NARROWEST`` of its width (every bay its own kind, as
on an irregular façade drawn by hand), or whose kinds would make elements overlap, is
left to the per-layer words: ``bays`` says why, and the spec, the report and a warning
say so. So is one whose layout on the kinds' shapes would be less faithful to the
drawing than the structure's (``_faithful``: ``KEEP``), unless it keeps the issue's
bar (``_fair``: a mean IoU of ``FAITHFUL`` or more, within ``LOOSE`` of the structure's,
no element more lost or fused): shared bays let a façade drop and gain bays at other
widths, which per-layer words cannot, and that is worth a little of the 1x fidelity.
Where neither way keeps it, every bay is a kind of its own, on the shape the structure
gave it (``separate``): as faithful as the structure, its inner bays on counters.
"""

from __future__ import annotations

import statistics
from collections import Counter, defaultdict
from collections.abc import Iterator
from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from facadecli.grammar.fidelity import FAITHFUL, Fidelity, fidelity
from facadecli.grammar.inputs import BACKGROUND, LabelledLayout, Rect
from facadecli.infer.companions import touching
from facadecli.infer.layers import BAND, OPENINGS, Grid, Span
from facadecli.infer.structure import SHARE, beyond_limits
from facadecli.solver.sizing import MIN_SIZE

ALIKE = 0.05  # of the bay's width: elements this close are the same in two bays
COUNTERS = 2  # the most counters of runs of bays
PAIRED = 2  # counters of the bays drawn once where no unit repeats (``_drawn_once``)
UNITS = (1, 2)  # bays: the units the bays drawn once are counted in, the smallest first
AS_MANY = 1 / 3  # of the most: units whose openings are this near in number are alike
NARROWEST = 0.7  # of the input's width: the bays must be able to narrow to this
WALL = 0.85  # of itself: the narrowest the wall after a bay's last element may become
COLUMN = 0.01  # m: a kind's elements of a label and size this close stand in one column
MARGIN = 0.005  # of the façade's width: what an end bay leaves of the margin beyond it
DIGITS = 4  # of a metre: a kind's shape is rounded to this, so every word adds up alike
ROUNDING = 1e-4  # m: the most rounding to DIGITS moves an edge, with float noise
SLIVER = MIN_SIZE  # m: a bay's edges this near one another are one line, as placed (``_lined``)
CENTRED = 1e3  # the weight of a mirrored façade's bays standing in its middle
SETTLE = 1e-3  # the weight of a kind's width and centres as first read, against the elements'
AXIS = 0.01  # of the façade's width: an opening this close to another's reflection mirrors it
ASIDE = 0.1  # of the openings: these may lack a mirror image on a façade mirrored as a whole
UNIQUE = ("door",)  # labels whose bays are never repeated
CUTS = ("window", "door")  # the openings the bays are cut on
KEEP = 0.002  # of the mean IoU against the drawing: the most the bays' shapes may lose
LOOSE = 0.01  # of it: the most they may lose where no way keeps KEEP, staying at FAITHFUL
HELD = SHARE / 2  # of the narrowest span an edge bounds: the most a kind's shape moves it
FOLLOW = SHARE  # of it: the most a kind's shape moves a companion's edge from where drawn
ODD = 1  # openings: a bay this many unlike a kind's (each way) is a variant of it; and
# companions: this many of a slot's may be resized past SIZED onto its row (``_apart``)
OVERHANG = 0.1  # of its width: the most a wall's own element reaches over the openings beside it
SIZED = 0.15  # of its size: the most a companion put on its slot's row may grow or shrink
DENSE = 0.05  # of a unit's width: copies this much denser than the façade gain wall (``_gains``)
FEW_BAYS = "fewer than two bays"  # why a façade of one bay (or none) has none to share

Slot = tuple[str, float, float, float, float]  # label, centre x in the bay, width, y0, y1
Ties = dict[int, tuple[int, list[int | None]]]  # variant kind: its base, each slot's in it
Move = tuple[list[int], Span]  # a slot's rectangles, and the row they would stand on
Spares = tuple[str | None, str | None]  # the spare copies' counters: the last bay's, the first's


@dataclass(frozen=True)
class Run:
    """``copies`` of the unit of bays starting at ``start`` (``unit`` bays long), written
    with ``counter`` (None: as drawn); ``most``: the counter's most (None: unbounded)."""

    start: int
    unit: int
    copies: int
    counter: str | None = None
    most: int | None = None


@dataclass(frozen=True)
class Gain:
    """Copies of the units on counter ``drawn`` (each unit drawn once) gained at the
    façade's density: each a unit with ``wall`` metres of wall before it, written after
    its unit within its run (``(unit (wall unit)^counter)^drawn``: gained only where the
    unit is kept) with counter ``counter`` (none as drawn, no most); ``drawn`` has a most
    of one (it may drop its units, not copy them at their drawn pitch). The copies are
    nested in each of ``guards`` too: gained only where no other such unit is dropped."""

    drawn: str
    counter: str
    wall: float
    guards: tuple[str, ...] = ()  # the other gains' drawn counters (``_gains``)


@dataclass(frozen=True)
class Bays:
    """A façade's bays (see the module): the layout with each kind on one shape, each
    bay's span, kind and whether it is drawn mirrored, the margins, and the word's plan."""

    layout: LabelledLayout
    spans: tuple[Span, ...]
    kinds: tuple[int, ...]
    mirrored: tuple[bool, ...]
    widths: tuple[float, ...]  # per kind
    margins: tuple[float, float]
    runs: tuple[Run, ...]  # covering the bays written (the left half if ``reflected``)
    reflected: bool  # written as the left half, the middle bay (if odd) and the half mirrored
    counters: tuple[tuple[str, float, int, int | None], ...]  # name, pitch, count, most
    walls: tuple[float, ...]  # per kind: the wall after its last element (0: none)
    apart: frozenset[int] = frozenset()  # rectangles left as drawn, in layers of their own
    spare: str | None = None  # the counter (at most 1) of a copy of the last bay (``_spare``)
    spare_first: str | None = None  # and of a copy of the first bay
    gains: tuple[Gain, ...] = ()  # copies gained at the façade's density (``_gains``)
    sparse: tuple[str, ...] = ()  # counters of units sparser than the façade: drop only

    def steady(self) -> frozenset[int]:
        """The kinds whose wall keeps its size (the rest may narrow to ``WALL``): where
        the bays stand in the façade's middle (one margin each side), the last bay's
        kind where it stands nowhere else. Its wall is the last before the margin:
        narrowed, it moved that bay's elements off the mirror image of the first's
        (family seed 14 with defects at 2x, once the tidy-up kept its drawn widths)."""
        last = self.kinds[-1]
        if self.margins[0] != self.margins[1] or self.kinds.count(last) > 1:
            return frozenset()
        return frozenset({last})

    def describe(self) -> str:
        letters = "".join(chr(ord("A") + k) for k in self.kinds)
        return f"{len(self.spans)} bays of {len(self.widths)} kinds ({letters})"


@dataclass(frozen=True)
class Frames:
    """How two bays' elements are compared: each read in the other's frame. ``mids``:
    the middle of each bay's openings in its frame, which bays alike share (read
    mirrored: about it), so a bay's own walls (where the cut between two bays fell, a
    wider wall beside an end bay) do not make it unlike; None: as cut, each read from its
    left edge (mirrored: about its middle). ``measures``: each bay's width as compared."""

    spans: list[Span]
    mids: list[float] | None
    measures: list[float]
    alike: float = ALIKE  # of a bay's width: how near elements alike are

    def tolerance(self, k: int, ref: int) -> float | None:
        """How near bays ``k`` and ``ref``'s elements must be to be alike (``alike`` of
        the wider), or None when the two are not as wide."""
        tolerance = self.alike * max(self.measures[k], self.measures[ref])
        return tolerance if abs(self.measures[k] - self.measures[ref]) <= tolerance else None

    def read(self, slots: list[Slot], k: int, ref: int, flip: bool) -> list[Slot]:
        """Bay ``k``'s slots in bay ``ref``'s frame, mirrored if ``flip``."""
        if self.mids is None:
            width = self.spans[k][1] - self.spans[k][0]
            return [_flip(s, width) for s in slots] if flip else slots
        shift = self.mids[ref] - self.mids[k]
        if flip:
            return [
                (lb, self.mids[ref] + self.mids[k] - c, w, y0, y1) for lb, c, w, y0, y1 in slots
            ]
        return [(lb, c + shift, w, y0, y1) for lb, c, w, y0, y1 in slots]


def _frames(
    rects: tuple[Rect, ...],
    strips: list[tuple[Span, list[int]]],
    spans: list[Span],
    on_openings: bool,
    alike: float = ALIKE,
) -> Frames:
    """The bays' frames (``Frames``): ``on_openings``, each bay read about its openings'
    middle (those not of a unique label where it has others: a door wider than the
    windows over it) and measured by the nearer of its pitches to the next bays' (an
    end bay: as cut); else as cut. ``alike``: how near elements alike are (``Frames``)."""
    widths = [b - a for a, b in spans]
    if not on_openings:
        return Frames(spans, None, widths, alike)
    middles = []
    for _, held in strips:
        shown = [rects[k] for k in held if _cuts(rects[k])]
        common = [r for r in shown if r.label not in UNIQUE] or shown
        middles.append((min(r.x0 for r in common) + max(r.x1 for r in common)) / 2)
    pitches = [b - a for a, b in pairwise(middles)]
    measures = [
        widths[k] if k in (0, len(spans) - 1) else min(pitches[k - 1], pitches[k])
        for k in range(len(spans))
    ]
    mids = [m - a for m, (a, _) in zip(middles, spans, strict=True)]
    return Frames(spans, mids, measures, alike)


def find_bays(layout: LabelledLayout, drawn: LabelledLayout | None = None) -> Bays | str:
    """The façade's bays (see the module), or why it has none to write; ``drawn``: the
    layout as drawn, its rectangles in the same order (None: ``layout``), which the
    elements but the openings stay near (``_apart``). The bays are compared about their
    openings first (``Frames``), which must then leave every opening within ``HELD`` of
    the structure's move limit of where the structure put it (``_moved``); else as cut.
    Either way the layout on the kinds' shapes must be as faithful to the drawing as
    the structure's (``_faithful``); where no way is, the first that keeps the issue's
    bar (``_fair``) is taken, else every bay a kind of its own (``_found``'s
    ``separate``), where that is as faithful (CMP's b0004: its two bays alike either
    side of the door fail the gate on one shape, each on its own they keep it)."""
    reason = ""
    fair: Bays | None = None
    for on_openings in (True, False):
        # companions on the shapes, else fewer of them: the kinds are found once for both
        for found in _found(layout, drawn, on_openings, (FOLLOW, HELD)):
            if isinstance(found, str):
                reason = found
            elif drawn is None or _faithful(drawn, layout, found.layout):
                return found
            else:
                reason = (
                    f"its bays on their kinds' shapes would lose more than {KEEP} of IoU "
                    f"and keep under {FAITHFUL} or lose more than {LOOSE}"
                )
                if fair is None and _fair(drawn, layout, found.layout):
                    fair = found
    if fair is not None or drawn is None:
        return fair if fair is not None else reason
    for found in _found(layout, drawn, False, (FOLLOW, HELD), separate=True):
        if not isinstance(found, str) and _faithful(drawn, layout, found.layout):
            return found
    return reason


def _found(
    layout: LabelledLayout,
    drawn: LabelledLayout | None,
    on_openings: bool,
    follows: tuple[float, ...],
    alike: float = ALIKE,
    separate: bool = False,
) -> Iterator[Bays | str]:
    """``find_bays`` with the bays' frames on their openings or as cut (``_frames``): for
    each of ``follows`` in turn, the bays with the openings' companions on the kinds'
    shapes within it (``_apart``), or why there are none; one reason alone when it does
    not depend on that limit (the kinds, their shapes and the bays' places do not).
    ``alike``: the share of a bay's width within which two bays' elements are alike
    (``ALIKE``; ``tests/benchmarks/kinds_bench.py`` reads the bays at looser ones).
    ``separate``: every bay a kind of its own, as the structure put it (``_drawn_once``
    gives the inner ones counters)."""
    width = layout.width
    strips, spans, over = _strips(layout)
    if len(strips) < 2:
        yield FEW_BAYS
        return
    frames = _frames(layout.rects, strips, spans, on_openings, alike)
    order = _right_half_mirrored_first(len(strips))
    unlike = set() if separate else _unlike(layout, [held for _, held in strips], frames, order)
    over |= unlike
    strips = [(span, [k for k in held if k not in unlike]) for span, held in strips]
    slots = [
        _slots([layout.rects[k] for k in held], span)
        for (_, held), span in zip(strips, spans, strict=True)
    ]
    if separate:
        kinds, mirrored = list(range(len(slots))), [False] * len(slots)
        matches = [list(range(len(mine))) for mine in slots]
        ties: Ties = {}
    else:
        kinds, mirrored, matches = _kinds(slots, frames, order)
        ties = _variants(slots, frames, kinds, mirrored, order)
    cut = _frames(layout.rects, strips, spans, False, alike)  # the shapes' first guess: as cut
    # each bay drawn once: as the structure put it, unless the openings mirror (then on
    # shapes fitted about the middle: as placed, the bays of family seeds 8 and 14 with
    # defects passed the gate and, never written reflected, went lopsided at 0.7x, 2x)
    mirror = _about_middle(list(layout.rects), width)  # centred or not, no spare end bays
    centred = mirror
    if len(set(kinds)) == len(kinds) and not centred:
        start, widths, shapes = _as_placed(slots, spans)
    else:
        shapes = _tied(_shapes(slots, kinds, mirrored, matches, cut), ties)
        widths = tuple(
            statistics.median(
                b - a
                for (a, b), k in zip(spans, kinds, strict=True)
                if k == ties.get(kind, (kind,))[0]
            )
            for kind in range(len(shapes))
        )
        fitted = _fitted(
            slots, spans, kinds, mirrored, matches, shapes, widths, width if centred else 0, ties
        )
        if centred and not _framed(fitted[2], fitted[1]):
            centred = False  # centred, a bay's elements would leave its frame: as drawn
            fitted = _fitted(slots, spans, kinds, mirrored, matches, shapes, widths, 0, ties)
        start, widths, shapes = fitted
        shapes = _tied([_lined(s, w, COLUMN) for s, w in zip(shapes, widths, strict=True)], ties)
    laid = _laid(kinds, mirrored, spans, width, widths, shapes, ties, start, centred, mirror)
    if isinstance(laid, str):
        yield laid
        return
    symmetric, start, runs, counters, end, spares = laid
    gains: tuple[Gain, ...] = ()  # not where copies on one side would lose the mirror
    sparse: tuple[str, ...] = ()
    if symmetric or not centred:
        counters, gains, sparse = _gains(runs, counters, kinds, widths, _windows(shapes), width)
    narrowest = _narrowest(runs, kinds, widths, symmetric)
    if narrowest > NARROWEST * width:
        yield (
            f"its {len(kinds)} bays of {len(shapes)} kinds cannot narrow below "
            f"{narrowest / width:.2f} of its width (bays of a kind repeat; most are unlike)"
        )
        return
    members = [held for _, held in strips]
    on_shapes, new_spans = _placed(layout, members, kinds, mirrored, matches, shapes, widths, start)
    drawn = drawn if drawn is not None and len(drawn.rects) == len(layout.rects) else layout
    walls = tuple(
        max(
            0.0,
            round(widths[k] - max(round(c - w / 2, DIGITS) + w for _, c, w, _, _ in shape), DIGITS),
        )
        for k, shape in enumerate(shapes)
    )
    for follow in follows:
        apart, moves = _apart(drawn, layout, on_shapes, members, kinds, matches, follow)
        count = _followed(drawn, layout, on_shapes, apart | over, moves)
        placed = _rowed(layout, on_shapes, apart | over, moves, count)
        apart = apart.union(over, *(indices for indices, _ in moves[count:]))
        if on_openings and _moved(layout, placed):
            yield "its bays put on their kinds' shapes would move openings from where drawn"
        elif _new_overlaps(layout.rects, placed):
            yield "its bays put on their kinds' shapes would overlap elements"
        else:
            yield Bays(
                LabelledLayout(layout.width, layout.height, tuple(placed)),
                tuple(new_spans),
                tuple(kinds),
                tuple(mirrored),
                widths,
                (start, end),
                tuple(runs),
                symmetric,
                tuple(counters),
                walls,
                frozenset(apart),
                *spares,
                gains,
                sparse,
            )


def _laid(
    kinds: list[int],
    mirrored: list[bool],
    spans: list[Span],
    width: float,
    widths: tuple[float, ...],
    shapes: list[list[Slot]],
    ties: Ties,
    start: float,
    centred: bool,
    mirror: bool,
) -> tuple[bool, float, list[Run], list[tuple[str, float, int, int | None]], float, Spares] | str:
    """The bays on their kinds' ``widths`` laid along the façade: whether they are
    written mirrored, the first's start, the runs and counters (``_plan``), the
    margin after the last (``centred``: the same as before the first; the openings
    mirror about the middle, ``_about_middle``, and the bays' elements stay in their
    frames there) and the spare end bays' counters (``_spare``: the last's, the first's;
    none where the openings mirror, ``mirror``, centred or not: CMP's b0005, once the
    ornaments between its windows stood in its bays, was not centred, took spares and
    lost its mirror at 0.7x and 2x); or why they cannot be (no margin, no repeat)."""
    symmetric = _palindrome(kinds, mirrored)
    left, right = spans[0][0], width - spans[-1][1]
    total = sum(widths[k] for k in kinds)
    if symmetric and abs(left - right) <= ALIKE * statistics.median(widths):
        start = round((width - total) / 2, DIGITS)
    else:
        symmetric = False
    end = start if centred else round(width - start - total, DIGITS)
    if start <= 0 or end <= 0:
        return "the bays reach the façade's edge (no margin to take the slack)"
    unique = _unique(shapes, kinds) | set(ties)  # a variant is written once, as drawn
    openings = tuple(sum(s[0] in CUTS for s in shape) for shape in shapes)
    runs, counters, spares = _plan(kinds, mirrored, unique, widths, symmetric, mirror, openings)
    if symmetric and not any(r.counter and r.most is None for r in runs):
        symmetric = False  # the halves would keep no repeat: the whole sequence, then
        runs, counters, spares = _plan(kinds, mirrored, unique, widths, False, mirror, openings)
    if not any(r.counter and r.most is None for r in runs):
        if mirror and any(most is not None for *_, most in counters):
            return (
                f"none of its {len(kinds)} bays of {len(shapes)} kinds repeat but its end "
                "bays, and it is mirrored (dropping both would leave the middle alone, one "
                "would lose the mirror)"
            )
        return f"none of its {len(kinds)} bays of {len(shapes)} kinds repeat"
    return symmetric, start, runs, counters, end, spares


def _unique(shapes: list[list[Slot]], kinds: list[int]) -> set[int]:
    """The kinds never repeated: those with an element of a unique label (a door),
    unless every bay has one (a shop's door in every bay singles none out: the façade
    repeats its bays, doors and all)."""
    marked = {k for k, shape in enumerate(shapes) if any(s[0] in UNIQUE for s in shape)}
    return set() if set(kinds) <= marked else marked


def _rowed(
    layout: LabelledLayout, after: list[Rect], apart: set[int], moves: list[Move], count: int
) -> list[Rect]:
    """The rectangles on their kinds' shapes (``after``), but those ``apart`` and those of
    the moves after the first ``count`` as the structure put them (``layout``), and those
    of the first ``count`` moves on the shape along x and on the move's row along y."""
    placed = list(after)
    for index in apart.union(*(indices for indices, _ in moves[count:])):
        placed[index] = layout.rects[index]
    for indices, (y0, y1) in moves[:count]:
        for index in indices:
            r = after[index]
            placed[index] = Rect(r.label, r.x0, y0, r.x1, y1, r.z)
    return placed


def _followed(
    drawn: LabelledLayout,
    layout: LabelledLayout,
    after: list[Rect],
    apart: set[int],
    moves: list[Move],
) -> int:
    """How many of the ``moves`` (the cheapest first) the bays can take and stay as
    faithful to the drawing as the structure's layout (``KEEP``, as ``_faithful``) with no
    new overlap: the most found by halving (each try is one comparison with the drawing;
    what a move costs is nearly what it adds to the moves before it)."""
    if not moves:
        return 0
    was = fidelity(drawn, layout)

    def holds(count: int) -> bool:
        placed = _rowed(layout, after, apart, moves, count)
        now = LabelledLayout(layout.width, layout.height, tuple(placed))
        return not _new_overlaps(layout.rects, placed) and kept(was, fidelity(drawn, now))

    if holds(len(moves)):
        return len(moves)
    low, high = 0, len(moves) - 1  # low holds (none moved: the layout as before), high may
    while low < high:
        middle = (low + high + 1) // 2
        if holds(middle):
            low = middle
        else:
            high = middle - 1
    return low


def _about_middle(rects: list[Rect], width: float) -> bool:
    """The openings (but a unique one: a door off the middle) mirror about the façade's
    middle: all but ``ASIDE`` of them have one of their label and size whose centre is
    within ``AXIS`` of the façade of where their centre reflected is."""
    shown = [r for r in rects if r.label in OPENINGS and r.label not in UNIQUE]
    near = AXIS * width
    kept = sum(
        any(
            q.label == r.label
            and abs((q.x0 + q.x1) - (2 * width - r.x0 - r.x1)) <= 2 * near
            and abs(q.y0 - r.y0) <= near
            and abs((q.x1 - q.x0) - (r.x1 - r.x0)) <= near
            for q in shown
        )
        for r in shown
    )
    return len(shown) >= 2 and kept >= (1 - ASIDE) * len(shown)


def _cuts(rect: Rect) -> bool:
    """Whether the rectangle is one of the openings the bays are cut on."""
    return rect.label in CUTS


def _strips(
    layout: LabelledLayout,
) -> tuple[list[tuple[Span, list[int]]], list[Span], set[int]]:
    """The openings the bays are cut on (``CUTS``) merged into strips along x where they
    overlap, left to right, each with the openings' span and the indices of its
    openings and of every other element (not a band) standing in its bay
    (``_bay_spans``); the bays' spans; and the elements that stand in no bay: across
    the cut of a wall (a balcony or a cornice over two bays, a shop front) or out at
    the façade's edge, and a band across a good share of the façade
    standing within one bay (which the bays' words would write but not place). Those
    stay as the structure put them, in layers of their own."""
    shown = [
        k
        for k, r in enumerate(layout.rects)
        if r.label != BACKGROUND and 0 < r.x1 - r.x0 <= BAND * layout.width
    ]
    openings: list[tuple[Span, list[int]]] = []
    for k in sorted((k for k in shown if _cuts(layout.rects[k])), key=lambda k: layout.rects[k].x0):
        r = layout.rects[k]
        if openings and r.x0 < openings[-1][0][1] - 1e-9:
            (a, b), held = openings[-1]
            openings[-1] = ((a, max(b, r.x1)), [*held, k])
        else:
            openings.append(((r.x0, r.x1), [k]))
    if len(openings) < 2:
        return openings, [], set()
    others = [layout.rects[k] for k in shown if not _cuts(layout.rects[k])]
    spans = _bay_spans(openings, layout.width, others)
    over: set[int] = set()
    for k in shown:
        r = layout.rects[k]
        if _cuts(r):
            continue
        bay = next(
            (n for n, (a, b) in enumerate(spans) if a - 1e-9 <= r.x0 and r.x1 <= b + 1e-9),
            None,
        )
        if bay is None:
            over.add(k)
        else:
            openings[bay][1].append(k)
    over.update(  # a band within one bay (wider than a quarter of the façade): its own
        k
        for k, r in enumerate(layout.rects)
        if r.label != BACKGROUND
        and r.x1 - r.x0 > BAND * layout.width
        and any(a - 1e-9 <= r.x0 and r.x1 <= b + 1e-9 for a, b in spans)
    )
    return [(span, sorted(held)) for span, held in openings], spans, over


def _unlike(
    layout: LabelledLayout,
    members: list[list[int]],
    frames: Frames,
    mirrored_first: list[bool],
) -> set[int]:
    """The elements of the bays but the openings that not every bay of their kind shows
    alike (label, place and rows within ``ALIKE`` of the bay), the kinds those of the
    openings alone (``_kinds``; a bay whose openings are alike read either way is read
    the way more of its other elements are): a balcony on one bay of a kind but not on
    the rest stays where the structure put it, in a layer of its own, and the bays of
    a kind remain one kind."""
    rects = layout.rects
    spans = frames.spans
    openings = [
        _slots([rects[j] for j in held if _cuts(rects[j])], span)
        for held, span in zip(members, spans, strict=True)
    ]
    kinds, mirrored, _ = _kinds(openings, frames, mirrored_first)
    unlike: set[int] = set()
    for kind in set(kinds):
        bays = [k for k, mine in enumerate(kinds) if mine == kind]
        tolerance = frames.alike * statistics.median(frames.measures[k] for k in bays)

        def others(k: int, flip: bool, first: int = bays[0]) -> list[tuple[int, Slot]]:
            held = [j for j in members[k] if not _cuts(rects[j])]
            mine = frames.read(_slots([rects[j] for j in held], spans[k]), k, first, flip)
            return list(zip(held, mine, strict=True))

        first = others(bays[0], False)
        seen = [first]
        for k in bays[1:]:
            ways = [mirrored[k]]
            turned = frames.read(openings[k], k, bays[0], not mirrored[k])
            if _match(openings[bays[0]], turned, tolerance) is not None:
                ways.append(not mirrored[k])  # alike read either way: the way more are
            seen.append(
                max(
                    (others(k, flip) for flip in ways),
                    key=lambda mine: sum(
                        any(_alike(p, q, tolerance) for _, q in mine) for _, p in first
                    ),
                )
            )
        shared: set[int] = set()
        for index, slot in first:
            row = [index]
            for candidates in seen[1:]:
                match = next(
                    (
                        j
                        for j, other in candidates
                        if j not in shared and _alike(slot, other, tolerance)
                    ),
                    None,
                )
                if match is None:
                    break
                row.append(match)
            else:
                shared.update(row)
        unlike.update(j for bay in seen for j, _ in bay if j not in shared)
    return unlike


def _alike(a: Slot, b: Slot, tolerance: float) -> bool:
    """Two slots are the same element: one label, centre, width and rows within
    ``tolerance``."""
    return a[0] == b[0] and all(abs(p - q) <= tolerance for p, q in zip(a[1:], b[1:], strict=True))


def _bay_spans(
    strips: list[tuple[Span, list[int]]], width: float, others: list[Rect] | None = None
) -> list[Span]:
    """Each strip widened to the wall's cut on either side (``_wall_cut``: its middle,
    or beside a pillar of the wall's own among the ``others``, the elements but the
    openings), the end ones outwards by the half wall on their inner side and over what
    of ``others`` stands wholly in the margin beyond, leaving the margin ``MARGIN`` of
    the façade where it is that wide: the margins take the slack."""
    middles = [(a[1] + b[0]) / 2 for (a, _), (b, _) in pairwise(strips)]
    cuts = [_wall_cut(a[1], b[0], others or []) for (a, _), (b, _) in pairwise(strips)]
    first, last = strips[0][0], strips[-1][0]
    edge = MARGIN * width  # left of the margin to the façade's edge, where it is that wide
    low = first[0] - min(middles[0] - first[1], max(0.0, first[0] - edge))
    high = last[1] + min(last[0] - middles[-1], max(0.0, width - last[1] - edge))
    # and out over what stands wholly in a margin, inside its edge (a pillar beside the
    # first window column): it is the end bay's, dropped and gained with it
    margins = others or []
    low = min([low, *(r.x0 for r in margins if edge <= r.x0 and r.x1 <= cuts[0] + 1e-9)])
    high = max([high, *(r.x1 for r in margins if r.x1 <= width - edge and r.x0 >= cuts[-1])])
    edges = [low, *cuts, high]
    return list(pairwise(edges))


def _wall_cut(low: float, high: float, others: list[Rect]) -> float:
    """Where the wall from ``low`` to ``high`` (between two strips of openings) is cut
    into the bays either side: at its middle, unless something of the wall's own
    (``_owned``) stands across the middle: a pillar, or a pilaster with its base and
    capital (``_standing_across``). Then the cut moves to an edge of the wall's own
    elements within that pillar's reach where none of them stands across it, of those
    lines the one the fewest of ``others`` stand across (a capital reaching over a
    window's blind), the nearest the middle at or left of it (the pillar goes to the bay
    on its right whatever the hand's jitter, so a bay dropped or gained leaves one
    pillar in every wall), else the nearest right of it; where no line frees it (a
    base wider than the wall, reaching a little over both openings), at the middle.
    The pillar is then in one bay, gained and dropped with it; cut at the middle, it
    stood across the cut, in no bay, and at other widths stayed where the structure put
    it in a word of its own (CMP's b0004 at 2x: its pillars bunched in the middle, over
    the windows).

    The cut moves no further than the pillar across the middle reaches, so each bay
    beside it keeps its width but for the pillar's share. Moved to wherever the fewest
    elements stood across it, a wall was cut at the end of a balcony reaching into it
    from the window beside it, past the ornaments in the wall: CMP's b0007's end
    bays grew by 0.49 and 0.23 m and at 0.7x the width it dropped two of its four
    window columns (density 0.89 -> 0.60); b0011 at 2x went out of the band (1.17). What
    reaches over an opening beside the wall (a balcony or a cornice over two bays, a
    sill wider than its window) neither moves the cut nor gives a line to cut at: cut
    at such edges too, CMP's b0012, whose walls hold nothing of their own, had other
    bays, and at 1.5x the width a density of 1.33 for 1.00."""
    middle = (low + high) / 2
    own = [r for r in others if _owned(r, low, high)]
    pillar = _standing_across(own, middle)
    if not pillar:
        return middle
    reach = min(r.x0 for r in pillar), max(r.x1 for r in pillar)
    edges = {min(high, max(low, x)) for r in own for x in (r.x0, r.x1)}
    lines = [x for x in sorted(edges) if reach[0] - 1e-9 <= x <= reach[1] + 1e-9]

    def across(x: float, rects: list[Rect]) -> int:
        return sum(r.x0 < x - 1e-9 and r.x1 > x + 1e-9 for r in rects)

    free = [x for x in lines if not across(x, own)]
    if not free:
        return middle
    return min(free, key=lambda x: (across(x, others), x > middle, abs(x - middle)))


def _standing_across(rects: list[Rect], x: float) -> list[Rect]:
    """Those of ``rects`` standing across ``x`` and, in turn, every one overlapping
    them along x (a pillar with its base and capital): empty where none stands across."""
    held = [r for r in rects if r.x0 < x - 1e-9 and r.x1 > x + 1e-9]
    while held:
        low, high = min(r.x0 for r in held), max(r.x1 for r in held)
        more = [r for r in rects if r not in held and r.x0 < high - 1e-9 and r.x1 > low + 1e-9]
        if not more:
            break
        held += more
    return held


def _owned(rect: Rect, low: float, high: float) -> bool:
    """Whether ``rect`` is the wall's from ``low`` to ``high``: standing in it but for
    an overhang of at most ``OVERHANG`` of its width over the openings beside it (a
    capital a few centimetres wider than the wall: CMP's b0004), never reaching over
    them (a balcony under a window that ends in the wall is the window's)."""
    over = max(0.0, low - rect.x0) + max(0.0, rect.x1 - high)
    return rect.x1 > low and rect.x0 < high and over <= OVERHANG * (rect.x1 - rect.x0) + 1e-9


def _right_half_mirrored_first(count: int) -> list[bool]:
    """For each bay, whether a match read mirrored is tried first: in the right half,
    where a mirrored façade's bays are its left half's reflected."""
    return [k > (count - 1) / 2 for k in range(count)]


def _slots(rects: list[Rect], span: Span) -> list[Slot]:
    """A bay's elements in its own frame: label, centre from its left edge, width, rows
    (in the order of ``rects``)."""
    return [(r.label, (r.x0 + r.x1) / 2 - span[0], r.x1 - r.x0, r.y0, r.y1) for r in rects]


def _flip(slot: Slot, width: float) -> Slot:
    label, centre, size, y0, y1 = slot
    return (label, width - centre, size, y0, y1)


def _match(a: list[Slot], b: list[Slot], tolerance: float) -> list[int] | None:
    """For each slot of ``a``, the slot of ``b`` it is (same label, centre, width and
    rows within ``tolerance``), or None when the two are not alike."""
    if len(a) != len(b):
        return None
    free = set(range(len(b)))
    out = []
    for slot in a:
        found = next(
            (
                j
                for j in sorted(free)
                if b[j][0] == slot[0]
                and all(abs(p - q) <= tolerance for p, q in zip(slot[1:], b[j][1:], strict=True))
            ),
            None,
        )
        if found is None:
            return None
        free.discard(found)
        out.append(found)
    return out


def _kinds(
    slots: list[list[Slot]], frames: Frames, mirrored_first: list[bool]
) -> tuple[list[int], list[bool], list[list[int]]]:
    """Each bay's kind (the first bay alike, as drawn or mirrored, else a kind of its
    own), whether it is its kind's first bay mirrored, and which of its slots is each of
    the first bay's."""
    reps: list[int] = []
    kinds, mirrored, matches = [], [], []
    for k, mine in enumerate(slots):
        found = None
        for kind, rep in enumerate(reps):
            tolerance = frames.tolerance(k, rep)
            if tolerance is None:
                continue
            tries = [
                (True, frames.read(mine, k, rep, True)),
                (False, frames.read(mine, k, rep, False)),
            ]
            for flip, candidate in tries if mirrored_first[k] else tries[::-1]:
                match = _match(slots[rep], candidate, tolerance)
                if match is not None:
                    found = (kind, flip, match)
                    break
            if found:
                break
        if found is None:
            found = (len(reps), False, list(range(len(mine))))
            reps.append(k)
        kinds.append(found[0])
        mirrored.append(found[1])
        matches.append(found[2])
    return kinds, mirrored, matches


def _variants(
    slots: list[list[Slot]],
    frames: Frames,
    kinds: list[int],
    mirrored: list[bool],
    mirrored_first: list[bool],
) -> Ties:
    """The bays of a kind of their own that are a *variant* of a kind of several bays:
    as wide (``ALIKE``), their openings alike but at most ``ODD`` each way (a window
    missing on a floor, or one wider or narrower than the kind's), at least one alike.
    Such a bay stays a kind of its own (written once, never repeated), but stands on
    its base kind's shape: its width and the elements it shares with the base are the
    base's symbols (``_fitted``), so it keeps the base's columns wherever the bays go,
    and its odd elements keep their place in it as drawn. ``mirrored`` is set for a
    variant read mirrored against its base; a door's bay is no variant. Returns, per
    variant kind, its base and each of its slots' slot in the base (None: its own)."""
    counts = Counter(kinds)
    reps = {kind: kinds.index(kind) for kind in counts}
    ties: Ties = {}
    for k, kind in enumerate(kinds):
        if counts[kind] > 1 or any(s[0] in UNIQUE for s in slots[k]):
            continue
        best: tuple[int, int, bool, list[int | None]] | None = None  # alike, base, flip, tie
        for base, rep in reps.items():
            if counts[base] < 2 or base in ties:
                continue
            tolerance = frames.tolerance(k, rep)
            if tolerance is None:
                continue
            for flip in (True, False) if mirrored_first[k] else (False, True):
                read = frames.read(slots[k], k, rep, flip)
                tie = _partial_match(slots[rep], read, tolerance)
                if tie is None:
                    continue
                alike = sum(m is not None for m in tie)
                if best is None or alike > best[0]:
                    best = (alike, base, flip, tie)
        if best is not None:
            ties[kind] = (best[1], best[3])
            mirrored[k] = best[2]
    return ties


def _partial_match(base: list[Slot], mine: list[Slot], tolerance: float) -> list[int | None] | None:
    """For each of ``mine``, the slot of ``base`` it is alike (``_alike``; None: none),
    or None when more than ``ODD`` openings of either are unlike or none is alike."""
    free = set(range(len(base)))
    tie: list[int | None] = []
    for slot in mine:
        found = next((j for j in sorted(free) if _alike(base[j], slot, tolerance)), None)
        if found is not None:
            free.discard(found)
        tie.append(found)
    odd_mine = sum(m is None and s[0] in CUTS for m, s in zip(tie, mine, strict=True))
    odd_base = sum(base[j][0] in CUTS for j in free)
    alike = sum(m is not None and s[0] in CUTS for m, s in zip(tie, mine, strict=True))
    return tie if alike and odd_mine <= ODD and odd_base <= ODD else None


def _tied(shapes: list[list[Slot]], ties: Ties) -> list[list[Slot]]:
    """The shapes with each variant's elements it shares with its base as the base's
    (label, place, size and rows)."""
    out = [list(shape) for shape in shapes]
    for kind, (base, tie) in ties.items():
        for n, m in enumerate(tie):
            if m is not None:
                out[kind][n] = shapes[base][m]
    return out


def _shapes(
    slots: list[list[Slot]],
    kinds: list[int],
    mirrored: list[bool],
    matches: list[list[int]],
    frames: Frames,
) -> list[list[Slot]]:
    """Each kind's shape: per slot of its first bay, the median over its bays (read in
    the first bay's frame; its width, bottom and height those the label's elements
    anywhere share, within ``ALIKE``: ``_common``), its place and width along x rounded
    to ``DIGITS``."""
    count = max(kinds) + 1
    pool: dict[tuple[str, int], Counter[float]] = defaultdict(Counter)
    for mine in slots:
        for slot in mine:
            for i, value in enumerate(_sized(slot)):
                pool[slot[0], i][value] += 1
    shapes = []
    for kind in range(count):
        bays = [k for k in range(len(kinds)) if kinds[k] == kind]
        first = slots[bays[0]]
        shape: list[Slot] = []
        for n, slot in enumerate(first):
            seen = []
            for k in bays:
                own = frames.read(slots[k], k, bays[0], mirrored[k])
                seen.append(own[matches[k][n]])
            tolerance = frames.alike * statistics.median(frames.measures[k] for k in bays)
            values = [statistics.median(_sized(s)[i] for s in seen) for i in range(4)]
            for i in (1, 2, 3):  # sizes and rows as the façade's elements share them
                values[i] = _common(pool[slot[0], i], values[i], tolerance)
            centre, size, y0, height = values
            shape.append((slot[0], round(centre, DIGITS), round(size, DIGITS), y0, y0 + height))
        shapes.append(_columns(shape))
    return shapes


def _as_placed(
    slots: list[list[Slot]], spans: list[Span]
) -> tuple[float, tuple[float, ...], list[list[Slot]]]:
    """The bays' start, widths and shapes where each bay is a kind of its own: as the
    structure put them, each edge rounded to ``DIGITS`` in its bay (a shape's centre
    the middle of its rounded edges, unrounded, so that ``_placed`` puts every edge
    back where it was: elements drawn touching stay touching, to the digit). Snapped to
    the façade's shared sizes within ``ALIKE`` of a bay (``_shapes``), the fidelity gate
    refused CMP's b0003, b0004, b0007 and b0008; the structure's sizes and rows are
    already shared ones."""
    widths = tuple(round(b - a, DIGITS) for a, b in spans)
    shapes = []
    for mine, width in zip(slots, widths, strict=True):
        edges = [
            (round(centre - size / 2, DIGITS), round(centre + size / 2, DIGITS))
            for _, centre, size, _, _ in mine
        ]
        shape = [
            (label, (low + high) / 2, round(high - low, DIGITS), y0, y1)
            for (label, _, _, y0, y1), (low, high) in zip(mine, edges, strict=True)
        ]
        shapes.append(_lined(shape, width, SLIVER))
    return round(spans[0][0], DIGITS), widths, shapes


def _sized(slot: Slot) -> tuple[float, float, float, float]:
    """A slot's centre, width, bottom and height: a row is shared by its bottom and its
    height (each edge on its own would give elements of one height two)."""
    _, centre, width, y0, y1 = slot
    return centre, width, y0, y1 - y0


def _fitted(
    slots: list[list[Slot]],
    spans: list[Span],
    kinds: list[int],
    mirrored: list[bool],
    matches: list[list[int]],
    shapes: list[list[Slot]],
    widths: tuple[float, ...],
    centred: float,
    ties: Ties,
) -> tuple[float, tuple[float, ...], list[list[Slot]]]:
    """Where the bays side by side best meet the elements as drawn: the start of the
    first bay, each kind's width and each of its elements' centres in it that put the
    elements' centres nearest (least squares) to where they were drawn, each bay
    starting where the one before ends (read mirrored where a bay is); the kinds'
    widths and centres as they are (``widths``, ``shapes``) where the elements say
    nothing of them (weighed ``SETTLE``). With ``centred`` (a façade's width; 0: not),
    the bays side by side stand in its middle (weighed ``CENTRED``). Rounded to
    ``DIGITS``; elements standing in one column (``_columns``) stay so. A variant's
    width and its elements it shares with its base (``ties``) are its base's."""
    count = len(widths)
    offsets = [sum(len(shape) for shape in shapes[:kind]) for kind in range(count)]
    unknowns = 1 + count + sum(len(shape) for shape in shapes)
    wide = [ties.get(kind, (kind,))[0] for kind in range(count)]  # whose width it is
    placed = [[offsets[kind] + n for n in range(len(shape))] for kind, shape in enumerate(shapes)]
    for kind, (base, tie) in ties.items():
        placed[kind] = [
            offsets[kind] + n if m is None else offsets[base] + m for n, m in enumerate(tie)
        ]
    rows: list[list[float]] = []
    values: list[float] = []
    for k, (kind, flip, match) in enumerate(zip(kinds, mirrored, matches, strict=True)):
        for n, j in enumerate(match):
            row = [0.0] * unknowns
            row[0] = 1.0  # the start
            for before in kinds[:k]:
                row[1 + wide[before]] += 1.0
            centre = slots[k][j][1] + spans[k][0]
            if flip:  # at the bay's width less the centre in the kind's frame
                row[1 + wide[kind]] += 1.0
                row[1 + count + placed[kind][n]] = -1.0
            else:
                row[1 + count + placed[kind][n]] = 1.0
            rows.append(row)
            values.append(centre)
    if centred:  # the start and half the bays' widths: the middle
        row = [0.0] * unknowns
        row[0] = CENTRED
        for kind in kinds:
            row[1 + wide[kind]] += CENTRED / 2
        rows.append(row)
        values.append(CENTRED * centred / 2)
    guess = [spans[0][0], *widths, *(slot[1] for shape in shapes for slot in shape)]
    for i, value in enumerate(guess):  # what the elements leave free stays as it was
        row = [0.0] * unknowns
        row[i] = SETTLE
        rows.append(row)
        values.append(SETTLE * value)
    solution, *_ = np.linalg.lstsq(np.array(rows), np.array(values), rcond=None)
    fitted = [
        _columns(
            [
                (label, round(float(solution[1 + count + placed[kind][n]]), DIGITS), w, y0, y1)
                for n, (label, _, w, y0, y1) in enumerate(shape)
            ]
        )
        for kind, shape in enumerate(shapes)
    ]
    fitted = _tied(fitted, ties)  # a variant's shared elements stay its base's, columns and all
    fitted_widths = tuple(round(float(solution[1 + wide[kind]]), DIGITS) for kind in range(count))
    return round(float(solution[0]), DIGITS), fitted_widths, fitted


def _framed(shapes: list[list[Slot]], widths: tuple[float, ...]) -> bool:
    """Every kind's elements stand inside its bay's frame."""
    return all(
        c - w / 2 >= -1e-9 and c + w / 2 <= width + 1e-9
        for shape, width in zip(shapes, widths, strict=True)
        for _, c, w, _, _ in shape
    )


def _columns(shape: list[Slot]) -> list[Slot]:
    """A kind's elements of a label and a size whose centres are within ``COLUMN`` of one
    another in one column (their median): what a hand draws in one column (the blinds
    of two floors) leaves no sliver of a gap a layer's word would need to hold."""
    out = list(shape)
    order = sorted(range(len(shape)), key=lambda n: (shape[n][0], shape[n][2], shape[n][1]))
    group: list[int] = []
    for n in [*order, -1]:
        if group and (
            n < 0
            or shape[n][0] != shape[group[0]][0]
            or shape[n][2] != shape[group[0]][2]
            or shape[n][1] - shape[group[-1]][1] > COLUMN
        ):
            centre = round(statistics.median(shape[m][1] for m in group), DIGITS)
            for m in group:
                label, _, size, y0, y1 = shape[m]
                out[m] = (label, centre, size, y0, y1)
            group = []
        if n >= 0:
            group.append(n)
    return out


def _lined(shape: list[Slot], width: float, reach: float) -> list[Slot]:
    """A bay kind's shape on one set of lines along x that every layer of its bays
    shares: its elements' edges (of any label) within ``reach`` of one another, or of
    the bay's edges (0 and ``width``), are one line: the bay's edge, else the openings'
    edges among them (their median), else their median. Each layer's word of the bay
    writes its gaps between these lines, so no gap is a sliver the solver cannot size
    (``sizing.MIN_SIZE``). One rule for the bays as fitted (``reach``: ``COLUMN``: a
    sill drawn 0.7 mm off its window wrote a 0.7 mm gap before the kind's wall the
    window's layer did not, and hold-out seed 116's spec did not solve) and as placed
    (``SLIVER``: an element a fifth of a millimetre in from its bay's edge, CMP's b0003
    and b0008, left the drawn counts no layout, and the solver took others at 1x).
    The shape as it is where a line would leave an element no width."""
    edges = sorted(
        [
            *(
                (round(c - w / 2, DIGITS) + side * w, n, side)
                for n, (_, c, w, _, _) in enumerate(shape)
                for side in (0, 1)
            ),
            (0.0, -1, 0),  # the bay's edges
            (width, -1, 1),
        ]
    )
    at: dict[tuple[int, int], float] = {}
    cluster = edges[:1]
    for edge in [*edges[1:], (float("inf"), -1, 0)]:
        if edge[0] - cluster[-1][0] <= reach:
            cluster.append(edge)
            continue
        bay = [v for v, n, _ in cluster if n < 0]
        opening = [v for v, n, _ in cluster if n >= 0 and shape[n][0] in CUTS]
        if bay:
            line = bay[0]
        elif opening:
            line = round(statistics.median(opening), DIGITS)
        else:
            line = round(statistics.median(v for v, _, _ in cluster), DIGITS)
        at.update(((n, side), line) for _, n, side in cluster if n >= 0)
        cluster = [edge]
    out = []
    for n, (label, _, _, y0, y1) in enumerate(shape):
        low, high = at[n, 0], at[n, 1]
        if high - low <= 0:
            return shape
        out.append((label, round((low + high) / 2, DIGITS + 1), round(high - low, DIGITS), y0, y1))
    return out


def _common(seen: Counter[float], value: float, tolerance: float) -> float:
    """The median of the cluster of values ``seen`` (each as often as seen) that holds
    the one nearest ``value``, where that is within ``tolerance`` (values each within
    ``tolerance`` of the next are one cluster): the size or row the other kinds'
    elements of a label share stay shared (one symbol, one row) and sit where the
    elements were drawn, on the whole; ``value`` when none is that close."""
    if not seen or min(abs(v - value) for v in seen) > tolerance:
        return value
    ordered = sorted(seen)
    nearest = min(ordered, key=lambda v: (abs(v - value), v))
    k = ordered.index(nearest)
    low = high = k
    while low > 0 and ordered[low] - ordered[low - 1] <= tolerance:
        low -= 1
    while high + 1 < len(ordered) and ordered[high + 1] - ordered[high] <= tolerance:
        high += 1
    cluster = [v for v in ordered[low : high + 1] for _ in range(seen[v])]
    return statistics.median(cluster)


def _palindrome(kinds: list[int], mirrored: list[bool]) -> bool:
    """The sequence reads the same mirrored: each bay's partner is of its kind, drawn
    mirrored the other way."""
    n = len(kinds)
    return n >= 2 and all(
        kinds[k] == kinds[n - 1 - k] and mirrored[k] != mirrored[n - 1 - k] for k in range(n // 2)
    )


def _plan(
    kinds: list[int],
    mirrored: list[bool],
    unique: set[int],
    widths: tuple[float, ...],
    symmetric: bool,
    mirror: bool,
    openings: tuple[int, ...] = (),
) -> tuple[list[Run], list[tuple[str, float, int, int | None]], Spares]:
    """The runs the written bays are cut into (the left half's if ``symmetric``): ends
    of kinds found only there on a counter of their own (at most one: drop only), then
    up to ``COUNTERS`` repeated units of one or two bays, longest first, none of a
    unique kind; where no unit is drawn twice in a row but the bays between the ends
    that are not unique are all of one kind (a window bay between wider end bays and a
    door's), each of them on that kind's counter; where none of that repeats, the inner
    bays drawn once on counters of their own (``_drawn_once``); where still none
    repeats, the end bays (``_ends_repeat``, ``_spare``), unless the façade is
    ``mirror`` (its openings mirror about the middle); the rest one bay a run, as
    drawn."""
    n = len(kinds)
    written = n // 2 if symmetric else n
    seq = list(zip(kinds, mirrored, strict=True))
    inner = kinds[1:-1]
    ends = {k for k in (kinds[0], kinds[-1]) if k not in inner and k not in unique}
    taken: dict[int, Run] = {}
    counters: list[tuple[str, float, int, int | None]] = []
    spare_unit: Run | None = None  # a copy of a unit drawn once more (``_spare_unit``)

    def counter(pitch: float, copies: int, most: int | None) -> str:
        for name, known, count, bound in counters:
            if most is not None and bound == most:
                return name  # the ends' one counter, whatever their widths
            if abs(known - pitch) < 1e-9 and count == copies and bound is None and most is None:
                return name
        name = f"bays{len(counters) + 1}"
        counters.append((name, round(pitch, DIGITS), copies, most))
        return name

    for k in sorted({0, n - 1} & set(range(written))):
        if kinds[k] in ends:
            taken[k] = Run(k, 1, 1, counter(widths[kinds[k]], 1, 1), 1)
    counted: dict[int, int] = {}  # the kinds runs repeat, by their copies
    found = 0
    while found < COUNTERS:
        best: tuple[int, int, int, int] | None = None  # covered, start, unit, copies
        for unit in (1, 2):
            for start in range(written - unit + 1):
                if any(
                    j in taken or kinds[j] in unique or kinds[j] in ends
                    for j in range(start, start + unit)
                ):
                    continue
                copies = 1
                while start + (copies + 1) * unit <= written and all(
                    j not in taken and seq[j] == seq[j - unit]
                    for j in range(start + copies * unit, start + (copies + 1) * unit)
                ):
                    copies += 1
                if any(counted.get(kinds[j], copies) != copies for j in range(start, start + unit)):
                    continue  # a kind repeats under one counter: a run of another count stays
                if copies >= 2 and (best is None or copies * unit > best[0]):
                    best = (copies * unit, start, unit, copies)
        if best is None:
            break
        _, start, unit, copies = best
        pitch = sum(widths[kinds[j]] for j in range(start, start + unit))
        taken[start] = Run(start, unit, copies, counter(pitch, copies, None))
        counted.update((kinds[j], copies) for j in range(start, start + unit))
        for j in range(start + 1, start + unit * copies):
            taken[j] = taken[start]
        found += 1
    inner_kinds = {kinds[j] for j in range(written)} - unique - ends
    if not found and len(inner_kinds) == 1:  # one kind between the ends, never side by side
        (kind,) = inner_kinds
        for j in range(written):
            if kinds[j] == kind:
                taken[j] = Run(j, 1, 1, counter(widths[kind], 1, None))
    if not any(run.counter and run.most is None for run in taken.values()):
        once = _drawn_once(kinds, unique | ends, written, counters, widths, openings)
        for j, run in once.items():
            taken.setdefault(j, run)
        if not mirror and not symmetric:
            spare_unit = _spare_unit(once, counters, sum(widths[k] for k in kinds))
    spares: Spares = (None, None)
    if (
        not mirror  # a mirrored façade keeps its mirror: a word a layer (``_ends_repeat``)
        and not any(run.counter and run.most is None for run in taken.values())
        and _ends_repeat(taken, counters)
    ):
        spares = (_spare(kinds, widths, counters, -1), _spare(kinds, widths, counters, 0))
    runs = []
    k = 0
    while k < written:
        run = taken.get(k, Run(k, 1, 1))
        runs.append(run)
        if spare_unit is not None and spare_unit.start == run.start:
            runs.append(spare_unit)
        k = run.start + run.unit * run.copies
    return runs, counters, spares


def _windows(shapes: list[list[Slot]]) -> tuple[int, ...]:
    """Each kind's openings that may repeat (``CUTS`` but ``UNIQUE``: its windows)."""
    return tuple(sum(s[0] in CUTS and s[0] not in UNIQUE for s in shape) for shape in shapes)


def _gains(
    runs: list[Run],
    counters: list[tuple[str, float, int, int | None]],
    kinds: list[int],
    widths: tuple[float, ...],
    windows: tuple[int, ...],
    width: float,
) -> tuple[list[tuple[str, float, int, int | None]], tuple[Gain, ...], tuple[str, ...]]:
    """Copies no denser than the façade. A counter's units (those of its runs, ``runs``,
    on ``kinds`` of ``widths`` holding ``windows``) gain copies at their drawn pitch; where
    they hold more windows a metre than the façade as a whole (``width`` wide) by more than
    ``DENSE`` (the façade's end bays, a door's bay or its margins hold fewer), a façade
    gaining them grew denser than drawn (CMP's b0012: single columns 2.57 m wide beside a
    door's bay, in a façade of one column per 3.75 m; density 1.25 at 2x). Where each
    unit of such a counter is drawn once, the counter gets a most of one (it may drop
    them), and the copies gained are a counter of their own (``Gain``), nested in each
    unit's run, each unit with the wall before it that makes its pitch its windows at
    the façade's density: a façade of any width is filled at about its own. Nested, a
    copy is gained only where the units are kept: side by side (``A^k (wall A)^g``, a
    counter of units drawn several times) the solver dropped drawn units and gained wide
    ones to fit a narrower façade in between (``doorway_family`` seed 2, its columns
    drawn alike, at 0.7x: density 1.07 -> 0.71), so a run of several copies keeps its one counter;
    and nested in the other gains' counters of units drawn once, so that none of those
    is dropped where copies are gained (CMP's b0001 at 0.7x dropped two columns on one
    counter and gained two wide copies of the third on its own: its columns lost). Not
    in the end bays' counter: a narrower façade may drop its end bays and gain a copy of
    an inner unit, as it did at their drawn pitch (``tests/test_infer.py``'s blinds at
    0.8x: with it, two of four columns left). Not called where the openings mirror
    about the middle but the bays are not written mirrored: copies beside one side's
    units lose the mirror (family seed 21 at 1.5x). Where some units gain so, a counter
    of units drawn once that hold fewer windows a metre than the façade by more than
    ``DENSE`` gets a most of one too: its copies, at their drawn pitch, filled the width
    instead (``tests/test_infer.py``'s blinds at 1.5x: a bay of one attic window copied
    six times). Returns the counters (the gains' after the rest), the gains and the
    counters so capped."""
    held = sum(windows[k] for k in kinds)
    if not held:
        return counters, (), ()
    density = held / width
    out = list(counters)
    gains: list[Gain] = []
    sparse: list[int] = []  # counters whose units hold fewer windows a metre than the façade
    for n, (name, pitch, count, most) in enumerate(counters):
        mine = [run for run in runs if run.counter == name]
        if most is not None or not mine or any(run.copies != 1 for run in mine):
            continue
        units = [range(run.start, run.start + run.unit) for run in mine]
        drawn = statistics.mean(sum(widths[kinds[j]] for j in unit) for unit in units)
        shown = statistics.mean(sum(windows[kinds[j]] for j in unit) for unit in units)
        wall = round(shown / density - drawn, DIGITS)
        if wall < -DENSE * drawn:
            sparse.append(n)
        if wall <= DENSE * drawn:
            continue
        gain = f"bays{len(out) + 1}"
        out[n] = (name, pitch, count, 1)
        out.append((gain, round(drawn + wall, DIGITS), 0, None))
        gains.append(Gain(name, gain, wall))
    for n in sparse if gains else ():  # where copies gain at the façade's density, a sparser
        name, pitch, count, _ = out[n]  # unit's copies would fill the width instead
        out[n] = (name, pitch, count, 1)
    dropping = [g.drawn for g in gains]
    guarded = (
        Gain(g.drawn, g.counter, g.wall, tuple(d for d in dropping if d != g.drawn)) for g in gains
    )
    return out, tuple(guarded), tuple(out[n][0] for n in sparse) if gains else ()


def _ends_repeat(taken: dict[int, Run], counters: list[tuple[str, float, int, int | None]]) -> bool:
    """Where no bay but the end bays may repeat (every inner bay unique: a door's
    between two columns of windows), the ends' one counter loses its most: a wider
    façade gains copies of its end bays beside them (both ends alike, so a mirrored
    façade stays so) where it stretched its margins, its columns kept. Not on a façade
    whose openings mirror about its middle (``_about_middle``): narrower, it could only
    drop both end bays (the door's bay alone, a third of its windows: density 0.36-0.43
    on the generated ``ABA`` family at 0.7x) or, with the spare, one (the mirror lost:
    hold-out seeds 121 and 123 at 0.7x and 2x); a word a layer keeps both, its columns
    squeezed. ``taken`` and ``counters`` are mended in place; returns whether there was
    such a counter."""
    freed = False
    for n, (name, pitch, count, most) in enumerate(counters):
        if most is not None:
            freed = True
            counters[n] = (name, pitch, count, None)
            for j, run in list(taken.items()):
                if run.counter == name:
                    taken[j] = Run(run.start, run.unit, run.copies, name)
    return freed


def _spare(
    kinds: list[int],
    widths: tuple[float, ...],
    counters: list[tuple[str, float, int, int | None]],
    end: int,
) -> str:
    """The counter of one more copy of the bay at ``end`` (-1: the last, 0: the first),
    beside it (at most one; none as drawn), for the ends' counter that gains and drops
    an end bay at each end at once (``_ends_repeat``): with a spare at each end the end
    bays change one at a time, either first. At none, the ends' counter alone left a
    narrower ``ABC`` (a door's bay between two columns of windows) the door's bay alone,
    a third of its windows; a spare of the last bay kept a column beside the door
    (``BC``, the windows' density as drawn), but only where the last bay fits beside it:
    CMP's b0009, once its pillars stood in its bays, had a last bay 2.2 m wider than
    its first and at 0.7x only the door's bay stood (``AB`` fits). The solver takes
    whichever counts leave the margins nearest as drawn, so a wider façade may gain an
    odd number of end bays too (one end a bay more than the other): never on a mirrored
    façade, which has no spare (``_plan``). The counter goes into ``counters``."""
    name = f"bays{len(counters) + 1}"
    counters.append((name, round(widths[kinds[end]], DIGITS), 0, 1))
    return name


def _drawn_once(
    kinds: list[int],
    kept: set[int],
    written: int,
    counters: list[tuple[str, float, int, int | None]],
    widths: tuple[float, ...],
    openings: tuple[int, ...] = (),
) -> dict[int, Run]:
    """Counters for bays no unit repeats (``PAIRED``): each inner bay written (not an
    end bay, not of a kind in ``kept``: unique or found only at the ends) in a unit of
    bays (``_units``: one bay, or two side by side where one bay alone holds too few of
    the ``openings`` to stand for the others), each unit on one of two counters, at one
    where drawn, so the layout at the input's size is the drawing's. Units the same way
    in from either end share one (a narrower or wider façade drops or gains them both:
    a mirrored façade stays so), and every other such pair the other, so that a
    narrower façade can drop about half of them or a third, and a wider one gain copies
    of every unit. The counters go into ``counters`` (name, their units' mean width,
    their units drawn, no most); returns each bay's run (a unit's bays share one)."""
    n = len(kinds)
    counted = [j for j in range(1, min(written, n - 1)) if kinds[j] not in kept]
    units = _units(counted, n, [openings[kinds[j]] for j in counted] if openings else [])
    groups: dict[int, list[list[int]]] = defaultdict(list)
    for unit in units:
        groups[unit[0][1] % PAIRED].append([j for j, _ in unit])
    out: dict[int, Run] = {}
    for _, held in sorted(groups.items()):
        name = f"bays{len(counters) + 1}"
        pitch = statistics.mean(sum(widths[kinds[j]] for j in bays) for bays in held)
        counters.append((name, round(pitch, DIGITS), len(held), None))
        for bays in held:
            run = Run(bays[0], len(bays), 1, name)
            out.update((j, run) for j in bays)
    return out


def _spare_unit(
    once: dict[int, Run], counters: list[tuple[str, float, int, int | None]], bays: float
) -> Run | None:
    """A spare copy (at most one; none as drawn) of the last unit drawn once, beside it,
    where its counter is the only one of the units drawn once and drops more than
    ``1 - NARROWEST`` of the bays' width ``bays`` at once (one unit each side of a
    unique bay, each a column with its narrow bay: the generated paired family's
    ``ABAB``, CMP's b0002): with it, a narrower façade drops one unit and a wider one
    gains them one at a time. Not where the façade is mirrored, which drops and gains
    them in pairs. The counter goes into ``counters``."""
    names = {run.counter for run in once.values()}
    if len(names) != 1:
        return None
    (name,) = names
    _, pitch, count, _ = next(c for c in counters if c[0] == name)
    if count < 2 or pitch * count <= (1 - NARROWEST) * bays:
        return None
    last = max(once.values(), key=lambda run: run.start)
    spare = f"bays{len(counters) + 1}"
    counters.append((spare, pitch, 0, 1))
    return Run(last.start, last.unit, 1, spare, 1)


def _units(counted: list[int], n: int, openings: list[int]) -> list[list[tuple[int, int]]]:
    """The bays ``counted`` (of ``n``, each with its number of ``openings``) cut into
    units, each a list of (bay, the unit's place in from the nearer end): single bays
    where they hold alike numbers of openings (``AS_MANY``), else the smallest of
    ``UNITS`` bays side by side, counted in from the nearer end (so a mirrored façade's
    units mirror), whose whole units do. A column of windows beside a narrow bay of one
    attic window (``ABAB``: CMP's b0008 and b0002) holds several times its neighbour's:
    counted alone, a façade of another width gained or dropped columns for narrow bays,
    keeping its width but not its windows a metre; in pairs, every unit holds about as
    many. A bay left over (the middle one, or a pair cut by a unique bay) is then
    written once, as drawn. With no ``openings`` known: single bays."""
    by_bay = dict(zip(counted, openings, strict=True)) if openings else {}

    def place(j: int) -> int:
        return min(j, n - 1 - j) - 1

    singles = [[(j, place(j))] for j in counted]
    if not by_bay or _alike_counts(list(by_bay.values())):
        return singles
    for size in UNITS[1:]:
        cut: dict[tuple[int, int], list[int]] = defaultdict(list)
        for j in counted:
            side = 0 if 2 * j < n - 1 else 1 if 2 * j > n - 1 else 2  # the middle alone
            cut[side, place(j) // size].append(j)
        units = [
            sorted(held)
            for (side, _), held in cut.items()
            if side < 2 and len(held) == size and max(held) - min(held) == size - 1
        ]
        if len(units) >= 2 and _alike_counts([sum(by_bay[j] for j in unit) for unit in units]):
            return [[(j, place(unit[0]) // size) for j in unit] for unit in sorted(units)]
    return singles


def _alike_counts(counts: list[int]) -> bool:
    """The numbers are within ``AS_MANY`` of the most of one another."""
    return not counts or max(counts) - min(counts) <= AS_MANY * max(counts)


def _narrowest(
    runs: list[Run], kinds: list[int], widths: tuple[float, ...], symmetric: bool
) -> float:
    """The width of the bays when every counter is at none: what cannot drop."""
    kept = sum(
        widths[kinds[j]] * (run.counter is None)
        for run in runs
        for j in range(run.start, run.start + run.unit * run.copies)
    )
    if not symmetric:
        return kept
    middle = widths[kinds[len(kinds) // 2]] if len(kinds) % 2 else 0.0
    return 2 * kept + middle


def _placed(
    layout: LabelledLayout,
    members: list[list[int]],
    kinds: list[int],
    mirrored: list[bool],
    matches: list[list[int]],
    shapes: list[list[Slot]],
    widths: tuple[float, ...],
    start: float,
) -> tuple[list[Rect], list[Span]]:
    """The rectangles with each bay's elements on its kind's shape, the bays side by side
    from ``start`` (each rectangle in its place in the list), and the bays' spans."""
    out = list(layout.rects)
    spans = []
    cursor = start
    for held, kind, flip, match in zip(members, kinds, mirrored, matches, strict=True):
        width = widths[kind]
        spans.append((cursor, round(cursor + width, DIGITS)))
        for n, j in enumerate(match):
            label, centre, size, y0, y1 = shapes[kind][n]
            low = round(centre - size / 2, DIGITS)  # in the bay, to the digit: every bay alike
            if flip:
                low = round(width - low - size, DIGITS)
            x0 = round(cursor + low, DIGITS)
            index = held[j]
            out[index] = Rect(label, x0, y0, round(x0 + size, DIGITS), y1, layout.rects[index].z)
        cursor = round(cursor + width, DIGITS)
    return out, spans


def _apart(
    drawn: LabelledLayout,
    layout: LabelledLayout,
    after: list[Rect],
    members: list[list[int]],
    kinds: list[int],
    matches: list[list[int]],
    follow: float,
) -> tuple[set[int], list[Move]]:
    """The rectangles of the slots of a kind (in every bay of it) that are not openings
    and stand apart (in layers of their own, as the structure put them), and the moves
    of the slots that may stand on a row of their own instead, the cheapest first. A
    slot stands on the kind's shape where each of its rectangles would have every edge
    within ``follow`` of the narrowest element, same-label gap or visible part it bounds
    of where it was ``drawn`` (``structure.beyond_limits``; ``FOLLOW``: what the
    structure lets an edge move, an eighth). One further only along y (a thin sill drawn
    a good share of its height off its row in some bay; along x, as wide as its window,
    the hand's error is a small share of it) may still stand on the shape along x, so
    that it is gained and dropped with its bay, on one row: the structure's, where every
    bay of the kind has it on one, else the median of its rows where that keeps each of
    its rectangles a companion of its bay's openings (``_companion``) and resizes at most
    ``ODD`` of them, fewer than half, by more than ``SIZED`` (``_resized``: a sill drawn
    a fifth thinner than its kind's others, in one bay of eight, made its slot stand apart
    once the tidy-up stopped moving its edge past a thirty-second); the bays take as
    many such moves as stay faithful (``_followed``). Any other slot stands apart (the
    openings make the bays; what fits them follows them). With no such moves, 443 of
    the generated family's 575 sills stood apart (held to half that, ``HELD``, 562), and
    at other widths did not follow their windows; with them, 258."""
    rects = list(drawn.rects)
    far_x = beyond_limits(rects, [(r.x0, r.x1) for r in after], "x", drawn.width, follow)
    far_y = beyond_limits(rects, [(r.y0, r.y1) for r in after], "y", drawn.height, follow)
    slots: dict[tuple[int, int], list[int]] = defaultdict(list)  # (kind, slot): rectangles
    bay_of: dict[int, int] = {}
    for bay, (held, kind, match) in enumerate(zip(members, kinds, matches, strict=True)):
        for n, j in enumerate(match):
            slots[kind, n].append(held[j])
            bay_of[held[j]] = bay
    area: dict[str, float] = defaultdict(float)  # each label's, drawn: what a move's cost is of
    for r in rects:
        area[r.label] += (r.x1 - r.x0) * (r.y1 - r.y0)
    apart: set[int] = set()
    moves: list[tuple[float, int, Move]] = []
    for indices in slots.values():
        if rects[indices[0]].label in OPENINGS or not any(far_x[k] or far_y[k] for k in indices):
            continue
        row = None if any(far_x[k] for k in indices) else _one_row(layout, indices)
        if row is None and not any(far_x[k] for k in indices):
            row = _median_row(layout, indices)
            resized = sum(_resized(layout.rects[k], row) for k in indices)
            if (
                resized > ODD
                or 2 * resized >= len(indices)
                or not all(
                    _companion(
                        layout,
                        after,
                        k,
                        row,
                        [j for j in members[bay_of[k]] if layout.rects[j].label in OPENINGS],
                    )
                    for k in indices
                )
            ):
                row = None
        if row is None:
            apart.update(indices)
        else:
            cost = sum(_changed(layout.rects[k], after[k], row) for k in indices)
            moves.append((cost / area[rects[indices[0]].label], min(indices), (indices, row)))
    return apart, [move for _, _, move in sorted(moves, key=lambda m: m[:2])]


def _changed(was: Rect, after: Rect, row: Span) -> float:
    """The area ``was`` and itself on ``after`` along x and on ``row`` do not share."""
    x0, x1, y0, y1 = after.x0, after.x1, row[0], row[1]
    shared = max(0.0, min(was.x1, x1) - max(was.x0, x0)) * max(
        0.0, min(was.y1, y1) - max(was.y0, y0)
    )
    return (was.x1 - was.x0) * (was.y1 - was.y0) + (x1 - x0) * (y1 - y0) - 2 * shared


def _one_row(layout: LabelledLayout, indices: list[int]) -> Span | None:
    """The row the structure put every one of the rectangles on, if one."""
    found = {(layout.rects[k].y0, layout.rects[k].y1) for k in indices}
    return found.pop() if len(found) == 1 else None


def _median_row(layout: LabelledLayout, indices: list[int]) -> Span:
    """The median bottom and height of the rectangles as the structure put them."""
    y0 = statistics.median(layout.rects[k].y0 for k in indices)
    height = statistics.median(layout.rects[k].y1 - layout.rects[k].y0 for k in indices)
    return round(y0, DIGITS), round(y0 + height, DIGITS)


def _resized(was: Rect, row: Span) -> bool:
    """``was`` put on ``row`` would grow or shrink by more than ``SIZED`` of its height."""
    return abs((row[1] - row[0]) / (was.y1 - was.y0) - 1) > SIZED


def _companion(
    layout: LabelledLayout, after: list[Rect], k: int, row: Span, openings: list[int]
) -> bool:
    """Rectangle ``k`` on its shape along x (``after``) and on ``row`` along y still
    touches (``companions.touching``) each of its bay's ``openings`` it touched as the
    structure put them, and is not hidden wholly behind one of them (on their shapes)."""
    was = layout.rects[k]
    now = Rect(was.label, after[k].x0, row[0], after[k].x1, row[1], was.z)
    for j in openings:
        if touching(was, layout.rects[j]) and not touching(now, after[j]):
            return False
        if _within(now, after[j]):
            return False
    return True


def _within(a: Rect, b: Rect) -> bool:
    """``a`` stands wholly inside ``b``."""
    inside_x = b.x0 <= a.x0 + 1e-9 and a.x1 <= b.x1 + 1e-9
    return inside_x and b.y0 <= a.y0 + 1e-9 and a.y1 <= b.y1 + 1e-9


def _faithful(drawn: LabelledLayout, before: LabelledLayout, after: LabelledLayout) -> bool:
    """The layout with its bays on their kinds' shapes (``after``) is as faithful to the
    drawing as the structure's (``before``): its mean IoU per label within ``KEEP``, no
    element more lost or fused (``grammar.fidelity``)."""
    return kept(fidelity(drawn, before), fidelity(drawn, after))


def kept(was: Fidelity, now: Fidelity, keep: float = KEEP) -> bool:
    """``now`` within ``keep`` of ``was``'s mean IoU, no element more lost or fused."""
    return now.iou_mean >= was.iou_mean - keep and now.lost <= was.lost and now.fused <= was.fused


def _fair(drawn: LabelledLayout, before: LabelledLayout, after: LabelledLayout) -> bool:
    """The layout on the kinds' shapes keeps the issue's bar though less faithful than
    the structure's: its mean IoU per label against the drawing at least ``FAITHFUL``
    and within ``LOOSE`` of the structure's, no element more lost or fused. Bays shared
    let a façade drop and gain whole bays at other widths, which per-layer words cannot
    (they squeeze); that is worth a little of the 1x fidelity, never the bar."""
    was, now = fidelity(drawn, before), fidelity(drawn, after)
    return (
        now.iou_mean >= max(FAITHFUL, was.iou_mean - LOOSE)
        and now.lost <= was.lost
        and now.fused <= was.fused
    )


def _moved(before: LabelledLayout, after: list[Rect]) -> bool:
    """An opening stands further from where the structure put it (``before``) than
    ``HELD`` of what the structure lets an edge move (``structure.beyond_limits``):
    bays read alike about their openings but drawn at pitches too unlike to stand on
    one shape."""
    rects = list(before.rects)
    return any(
        (a or b) and rects[k].label in OPENINGS
        for k, (a, b) in enumerate(
            zip(
                beyond_limits(rects, [(r.x0, r.x1) for r in after], "x", before.width, HELD),
                beyond_limits(rects, [(r.y0, r.y1) for r in after], "y", before.height, HELD),
                strict=True,
            )
        )
    )


def _new_overlaps(before: tuple[Rect, ...], after: list[Rect]) -> bool:
    """Two elements of a label (openings: any two) overlap after, not before, by more
    than ``ROUNDING`` (an element on its shape, rounded to ``DIGITS``, may meet by that
    one drawn touching it and left as the structure put it, unrounded: CMP's b0003)."""

    def meet(a: Rect, b: Rect) -> bool:
        over_x = min(a.x1, b.x1) - max(a.x0, b.x0)
        return over_x > ROUNDING and min(a.y1, b.y1) - max(a.y0, b.y0) > ROUNDING

    group = ["" if r.label in OPENINGS else r.label for r in before]
    shown = [k for k, r in enumerate(before) if r.label != BACKGROUND]
    return any(
        meet(after[i], after[j]) and not meet(before[i], before[j])
        for n, i in enumerate(shown)
        for j in shown[n + 1 :]
        if group[i] == group[j]
    )


def segment(bays: Bays, grid: Grid, bay: int) -> list[Span] | None:
    """The grid's columns in bay ``bay``, in its kind's frame (read mirrored where the
    bay is), left to right; None when a column of the grid is in no bay whole."""
    a, b = bays.spans[bay]
    width = b - a
    inside = [c for c in grid.columns if c[0] >= a - 1e-6 and c[1] <= b + 1e-6]
    if bays.mirrored[bay]:
        return sorted(
            (round(width - (y - a), DIGITS), round(width - (x - a), DIGITS)) for x, y in inside
        )
    return [(round(x - a, DIGITS), round(y - a, DIGITS)) for x, y in inside]


def inside(bays: Bays, grid: Grid) -> bool:
    """Every column of the grid is inside one bay."""
    counted = sum(len(segment(bays, grid, k) or []) for k in range(len(bays.spans)))
    return counted == len(grid.columns)


def in_bays(bays: Bays, grid: Grid) -> bool:
    """Every column of the grid is inside one bay, and the grid shows alike in every bay
    of a kind (as the word repeats them)."""
    if not inside(bays, grid):
        return False
    seen: dict[int, list[Span]] = {}
    for k, kind in enumerate(bays.kinds):
        mine = segment(bays, grid, k) or []
        if seen.setdefault(kind, mine) != mine:
            return False
    return True
