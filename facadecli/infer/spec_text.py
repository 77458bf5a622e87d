"""A layered spec, as YAML text, from the grids of a labelled layout.

- The wall: the background, one opaque cell over the whole canvas, behind everything.
- One layer per grid, back to front. Along each axis its word is its elements with the
  gaps between them (and the margins to the façade's edges); its mask (``visible``) shows
  the elements only. Each layer is an alignment group of its own (SPEC 2.6): its word
  alone covers the canvas, so nothing is left to align (which would cost the solver
  dearly with dozens of layers), and the layers hold together through their shared
  symbols, which the sizing QP gives one size each.
- Symbols: a layer's gaps of one size share one (``window_gx1``, ``window_gy2``), and a
  label's elements of one size share one across layers (``window_w1``, ``window_h2``),
  with the sizes measured (in metres, to a tenth of a millimetre); all are opaque (a
  layer's gaps are hidden by its mask). Gaps are a layer's own (shared between layers of
  different columns, they would tie the words so tightly that only the input's size could
  hold them), except that layers with the same columns (rows) share their x (y) gaps:
  their words are then alike, so they stay aligned at any size.
- One floor's words: the opening layers that stand beside one another on a floor (a
  door between windows, or a floor's windows drawn in two grids) share one x word over
  all their columns (``layers.frames``), each showing its own elements by its mask, so
  at another width they keep their order and spacing and never meet. Where two grids of
  one label in such a word have a width in common, the later one's widths are symbols
  of its own (``window_2_w1``; ``_width_tables``): a mask names symbols, so each would
  show the other's window.
- Top floors (``layers.top_floors``): where the openings have no run of floors, the last
  floor like the one under it repeats upwards (``_floors_above``), every copy at its
  part's pitch, one counter a pitch, as many as fit in the height gained (the roof's
  margin never shrinks); the floors under it keep their sizes, and what stands wholly
  over it (a lower top floor, an attic) keeps its margin to the roof, clear of the
  copies.
- Repeats: where a word repeats a gap and an element twice or more (three elements), or
  an element alone three times, the run is written ``(gx2 window_w1)^n1`` with a free
  counter, so a wider or taller façade gains bays or floors. Layers whose runs have one
  pitch and one count along an axis share the counter, so windows and sills keep together.
  Along y, what stands on the openings' run of floors follows it (``infer.floors``,
  ``_floor_word``): one floor of the run repeated with the openings' counter, so sills,
  blinds and cornices are gained and dropped with their windows' floors.
  A word that reads the same backwards is written as its left half, the middle, and the
  half reflected (``^-1``), when each half keeps its run: a wider façade then gains bays on
  both sides alike.
- Shared bays (``infer.bays``): where the façade's bays repeat, the x word of every layer
  standing in them follows their one sequence instead (``_bay_word``): the margins
  (``bays_m1``), each bay its kind's hidden gaps (``bay1_g1``), the layer's elements and
  the kind's wall (``bay1_w``), runs of bays with counters (``bays1``); a comment says
  which, or why the bays are not shared. The layers of elements left where drawn, off
  the bays (``Grid.apart``), have no runs along x: their words are as drawn.
- Meshes and materials by label (frames for windows and shop fronts, doors, ledges for
  sills, cornices and mouldings, balconies, shutters for blinds, boxes for the rest),
  colours from the label palette; every layer says in a comment where it came from.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from itertools import pairwise

from facadecli.grammar.palette import label_colour
from facadecli.infer.bays import SLIVER, WALL, Bays, Spares, in_bays, segment
from facadecli.infer.bays import Run as BayRun
from facadecli.infer.floors import (
    ALIKE,
    Floors,
    floor_letters,
    floors_grid,
    floors_top,
    follows,
    mid_wall,
    on_run,
)
from facadecli.infer.layers import (
    OPENINGS,
    SIZE_KEY,
    Frame,
    Grid,
    Span,
    Stack,
    frames,
    over,
    stacks,
    top_floors,
    uncovered,
)

DECIMALS = 4  # of a metre in the sizes written
TOLERANCE = 0.01  # m: the solver's tolerance (sizes are written rounded)
RUNS = {1: 3, 2: 2}  # copies of a unit of one letter, or of two, that make a repeat
PITCH_SHARED = 0.02  # runs of one count whose pitches are this close share a counter
UNIQUE = ("door",)  # labels whose elements are never repeated (a portal stays one)
SQUEEZE = 0.9  # of its size: the narrowest an opening's width may become (never slivers;
# under the 85%, with room for the solver's tolerance)
MIRRORED = 5  # letters a word needs (two elements and more) to be written as mirrored
MESHES = {  # CMP labels; anything else is a box
    "window": ("frame", 0.1),
    "door": ("door", 0.12),
    "shop": ("frame", 0.12),
    "sill": ("ledge", 0.12),
    "cornice": ("ledge", 0.3),
    "molding": ("ledge", 0.15),
    "balcony": ("balcony", 0.9),
    "blind": ("shutter", 0.06),
    "pillar": ("box", 0.2),
    "deco": ("box", 0.08),
}
DEFAULT_MESH = ("box", 0.1)
PANE = ", pane_material: pane"  # glass that reads as glass over the wall behind it
PANE_COLOUR = "#2f4356"  # (the wall has no openings: a see-through pane would show it)
STEP = 0.02  # m: each layer stands this much further out than the one behind it


@dataclass
class _Symbols:
    """Symbol names by kind and size: one symbol per distinct size of a kind."""

    prefix: str
    sizes: dict[float, str] = field(default_factory=dict)
    keys: dict[float, float] = field(default_factory=dict)  # each size seen: its symbol's

    def of(self, size: float) -> str:
        """The symbol of ``size``: that of a size already named within ``10**-SIZE_KEY``
        of it, else a new one. Rounding alone splits sizes a float's noise apart that
        fall either side of a rounding boundary (family seed 3's windows, 0.8346675 m
        each as the structure put them, became two height symbols of one size)."""
        key = round(size, SIZE_KEY)
        known = self.keys.get(key)
        if known is None:
            known = next((k for k in self.sizes if abs(k - size) < 10**-SIZE_KEY), key)
            self.keys[key] = known
        name = self.sizes.get(known)
        if name is None:
            name = self.sizes[known] = f"{self.prefix}{len(self.sizes) + 1}"
        return name

    def seen(self, size: float) -> list[float]:
        """The sizes seen (rounded to ``SIZE_KEY``) that ``size``'s symbol names."""
        return [k for k, known in self.keys.items() if known == size]


@dataclass
class _Counters:
    """Counters by (axis, pitch, count): runs alike share one; the top floors' copies
    (``_floors_above``) one of their own, under a count of 0."""

    names: dict[tuple[str, float, int], str] = field(default_factory=dict)

    def floors(self, pitch: float) -> str:
        """The one counter of every top floor's copies at ``pitch``: a taller façade
        gains as many floors in every column of that pitch (``layers.top_floors``)."""
        return self._named(("y", round(pitch, 4), 0))

    def drop(self, pitch: float, floor: int) -> str:
        """The counter of the ``floor``-th floor from the top (0: the top floor) of the
        stacks at ``pitch`` (``layers.stacks``): 1 where it stands, 0 where a shorter
        façade drops it; shared by every stack at that pitch, so every column drops as
        many floors."""
        return self._named(("y", round(pitch, 4), -1 - floor))

    def _named(self, key: tuple[str, float, int]) -> str:
        """The counter under ``key``, named the next ``n<i>`` where there is none yet."""
        name = self.names.get(key) or f"n{len(self.names) + 1}"
        self.names[key] = name
        return name

    def of(self, axis: str, pitch: float, count: int) -> str:
        """The counter of runs along ``axis`` of ``count`` copies at ``pitch`` (within
        ``PITCH_SHARED``: a sill's run and its window's, measured apart)."""
        for (along, known, copies), name in self.names.items():
            if along == axis and copies == count and abs(known - pitch) <= PITCH_SHARED * known:
                return name
        name = self.names[(axis, round(pitch, 4), count)] = f"n{len(self.names) + 1}"
        return name


def _names(table: _Symbols) -> frozenset[str]:
    return frozenset(table.sizes.values())


def ident(label: str) -> str:
    """A label as a name a spec accepts."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", label) or "label"
    return name if name[0].isalpha() else "L" + name


Token = tuple[str, float]  # a letter of a word, and its size
Spread = dict[tuple[str, str, float], tuple[float, float]]  # (axis, label, size) -> range


def _tokens(
    spans: tuple[Span, ...],
    extent: float,
    element: _Symbols | list[_Symbols],
    gap: _Symbols,
    margin: _Symbols,
) -> list[Token]:
    """(symbol, size) of the elements and the gaps between them, from 0 to ``extent``; the
    gaps before the first element and after the last are margins (symbols of their own).
    ``element``: the symbols of the elements, or of each span (a frame's, by label)."""
    tokens: list[Token] = []
    cursor = 0.0
    for k, (a, b) in enumerate(spans):
        if a - cursor > 1e-9 * extent:
            table = margin if cursor == 0.0 else gap
            tokens.append((table.of(a - cursor), a - cursor))
        symbols = element[k] if isinstance(element, list) else element
        tokens.append((symbols.of(b - a), b - a))
        cursor = b
    if extent - cursor > 1e-9 * extent:
        tokens.append((margin.of(extent - cursor), extent - cursor))
    return tokens


def _word(
    tokens: list[Token],
    axis: str,
    counters: _Counters,
    repeated: set[str],
    repeat: bool = True,
    margins: frozenset[str] = frozenset(),
) -> str:
    """The tokens as a word (see ``_with_run``). A mirrored word (the same read backwards,
    two elements or more) is written as its first half, the middle letter, and the first
    half reflected, ``... (...)^-1`` (SPEC 2.2), when that loses no repeat: each half then
    keeps its run with one counter, and the meshes of the right half are mirrored."""
    symbols = [symbol for symbol, _ in tokens]
    if not repeat:
        return " ".join(symbols)
    half = len(tokens) // 2
    if len(tokens) >= MIRRORED and symbols == symbols[::-1]:
        left = tokens[:half]
        if 2 * _covered(_longest_run(left, margins)) >= _covered(_longest_run(tokens, margins)):
            text = _with_run(left, axis, counters, repeated, margins)
            middle = [symbols[half]] if len(tokens) % 2 else []
            return " ".join([text, *middle, f"({text})^-1"])
    return _with_run(tokens, axis, counters, repeated, margins)


Run = tuple[int, int, int, int]  # letters covered, start, unit, copies


def _longest_run(tokens: list[Token], margins: frozenset[str] = frozenset()) -> Run | None:
    """The longest run of a repeated unit (one or two letters, at least ``RUNS`` copies;
    never a margin: it takes the slack)."""
    symbols = [symbol for symbol, _ in tokens]
    best = None
    for unit in (1, 2):
        for start in range(len(tokens) - unit):
            if margins & set(symbols[start : start + unit]):
                continue
            copies = 1
            while (
                symbols[start + copies * unit : start + (copies + 1) * unit]
                == (symbols[start : start + unit])
            ):
                copies += 1
            if copies >= RUNS[unit] and (best is None or copies * unit > best[0]):
                best = (copies * unit, start, unit, copies)
    return best


def _covered(run: Run | None) -> int:
    return 0 if run is None else run[0]


def _with_run(
    tokens: list[Token],
    axis: str,
    counters: _Counters,
    repeated: set[str],
    margins: frozenset[str] = frozenset(),
) -> str:
    """The tokens as a word, the longest run written with a counter; the run's symbols go
    into ``repeated``."""
    symbols = [symbol for symbol, _ in tokens]
    best = _longest_run(tokens, margins)
    if best is None:
        return " ".join(symbols)
    _, start, unit, copies = best
    pitch = sum(size for _, size in tokens[start : start + unit])
    counter = counters.of(axis, pitch, copies)
    body = " ".join(symbols[start : start + unit])
    repeated.update(symbols[start : start + unit])
    run = f"({body})^{counter}" if unit > 1 else f"{body}^{counter}"
    return " ".join([*symbols[:start], run, *symbols[start + copies * unit :]])


def spec_text(
    name: str,
    width: float,
    height: float,
    found: list[Grid],
    source: str,
    spread: Spread | None = None,
    bays: Bays | str | None = None,
    alike: float = ALIKE,
) -> str:
    """The spec (see the module): the sizes a line per label and a line per layer, and each
    layer in two lines under the comment that says where it came from. ``spread``: the
    range the input's elements of a label's size span (see ``_size``). ``bays``: the
    façade's bays (``infer.bays``), whose one sequence the x word of every layer standing
    in them follows; or why there are none (said in a comment). ``alike``: how far a
    layer's floors may be off its last to follow the openings' (``floors.Floors``)."""
    counters = _Counters()
    shared = bays if isinstance(bays, Bays) else None
    bay_gaps = [_Symbols(f"bay{k + 1}_g") for k in range(len(shared.widths) if shared else 0)]
    bay_margins = _Symbols("bays_m")
    in_bay: set[str] = set()  # element symbols of bays: they keep their size
    elements: dict[str, tuple[_Symbols, _Symbols]] = {}
    # a layer's gaps are its own, but layers with the same columns (or rows) share them:
    # their words are then alike and stay aligned at any size
    gaps_x: dict[tuple[Span, ...], tuple[_Symbols, _Symbols]] = {}
    # (by rows, and whether the layer's top floor repeats upwards: one whose top margin
    # shrinks as floors are gained never shares it with one whose margin cannot)
    gaps_y: dict[tuple[tuple[Span, ...], bool], tuple[_Symbols, _Symbols]] = {}
    owned: list[list[_Symbols]] = []  # the gap and margin symbols each layer introduces
    repeated: set[str] = set()  # symbols of runs (written with a counter)
    stretched: set[str] = set()  # elements of words without gaps: they fill the façade
    margined: set[str] = set()  # gaps of words with a margin: the margins take the slack
    loose: set[str] = set()  # symbols of words without a margin: they take the slack
    held: set[str] = set()  # gaps of words with a run and a margin: they keep their size
    grounded: set[str] = set()  # elements of words from the ground up: they do not grow
    unshrunk: set[str] = set()  # elements of layers off the bays: they never shrink below as drawn
    layers: list[tuple[str, Grid, str, str]] = []
    for grid in found:
        base = ident(grid.label)
        elements.setdefault(grid.label, (_Symbols(f"{base}_w"), _Symbols(f"{base}_h")))
    names = layer_names(found)
    kind_lines = _kind_lines(shared, found) if shared is not None else []
    framed: list[Frame | None] = frames(found) if shared is None else [None] * len(found)
    widths = _width_tables(found, framed, names, elements)
    unique = {t.prefix for g, t in zip(found, widths, strict=True) if g.label in UNIQUE}
    top = floors_top(found)
    floors = floor_run(found, height, alike)
    # a top floor repeats upwards only where no run of the openings' floors stands under
    # it, or where it stands on the run's floors: over them (an attic's windows, a top
    # floor drawn apart, the sills of the floors over the run), its copies and the floors
    # the run gains would take the same height (cmp_b0011 at 1.5x: 33 pairs of windows
    # over one another; the family with defects' seed 1: four); it moves up with the
    # floors instead, as everything over them does
    tops = {
        k: pitch
        for k, pitch in top_floors(found, width, height).items()
        if floors is None or on_run(found[k].rows, floors[1])
    }
    # a shorter façade drops the floors of its top floors that repeat upwards; a run of
    # the openings' floors drops its own (with its counter), and what stands on it
    stacked = _stacked(found, stacks(found, tops, height)) if floors is None else {}
    roofs: set[str] = set()  # the margins over top floors that repeat: free, whoever shares them
    roofed: set[str] = set()  # the margins over floors gained: they never shrink (``_gap``)
    # the layers with a margin at both ends along y (where their first and last rows
    # start, the margins) and where the top floors that repeat upwards start
    margins_y: list[tuple[float, float, str, str]] = []
    over_y: list[list[str]] = []  # the elements of each of those layers
    margined_grids: list[Grid] = []  # and their grids
    copied_from: list[float] = []
    copied_to: list[float] = []  # where the top floors that repeat upwards end
    copying: list[Grid] = []  # the openings' top floors that repeat upwards
    for index, (layer, grid, frame) in enumerate(zip(names, found, framed, strict=True)):
        symbols = (widths[index], elements[grid.label][1])
        columns = grid.columns if frame is None else tuple(c for c, _ in frame)
        bay_word = None
        if shared is not None and not grid.apart and in_bays(shared, grid):
            bay_word = _bay_word(
                shared, grid, symbols[0], bay_gaps, bay_margins, in_bay, kind_lines
            )
        row_key = (grid.rows, index in tops and grid.label not in UNIQUE)
        introduced = [
            *(
                gaps_x.setdefault(columns, (_Symbols(f"{layer}_gx"), _Symbols(f"{layer}_mx")))
                if columns not in gaps_x and bay_word is None
                else ()
            ),
            *(
                gaps_y.setdefault(row_key, (_Symbols(f"{layer}_gy"), _Symbols(f"{layer}_my")))
                if row_key not in gaps_y
                else ()
            ),
        ]
        owned.append(introduced)
        floor_word = None
        if (
            floors is not None
            and index != floors[0]
            and grid.label not in UNIQUE
            and 0 < grid.rows[0][0] < top
            and grid.rows[-1][1] < height
            and follows(grid.rows, floors[1])
        ):
            # what stands on the openings' floors follows their one sequence: gained and
            # dropped with them, at their pitch, by their counter
            floor_word, steady, roof = _floor_word(
                grid.rows, floors[1], height, symbols[1], *gaps_y[row_key], counters, repeated
            )
            held.update(steady)
            if roof is not None:
                roofs.add(roof)
        y_axis = []
        if floor_word is None:
            y_tokens = _tokens(grid.rows, height, symbols[1], *gaps_y[row_key])
            y_axis = [("y", y_tokens, grid.rows, gaps_y[row_key])]
        words = []
        if bay_word is not None:
            axes = y_axis
            words.append(bay_word)
        else:
            x_tokens = _tokens(
                columns,
                width,
                _by_owner(frame, found, framed, widths, symbols[0]),
                *gaps_x[columns],
            )
            axes = [("x", x_tokens, columns, gaps_x[columns]), *y_axis]
        for axis, tokens, spans, (gaps, margins) in axes:
            if len(tokens) == len(spans):  # no gap: nothing else takes a longer façade
                stretched.update(symbol for symbol, _ in tokens)
            ends = _names(margins)
            if axis == "x" and frame is not None:  # one word for the floor: runs of no door
                kept = frozenset(s for s, _ in tokens if s.rstrip("0123456789") in unique)
                word = _word(tokens, axis, counters, repeated, True, ends | kept)
            else:
                # elements left where drawn, off the bays, stay so along x: no runs of
                # their own (counters of their own cost the solver a search each, and
                # could not gain or drop what the bays do anyway)
                runs = grid.label not in UNIQUE and not (grid.apart and axis == "x")
                word = _word(tokens, axis, counters, repeated, runs, ends)
            stack = stacked.get(index) if axis == "y" and grid.label not in UNIQUE else None
            if stack is not None and ends >= {tokens[0][0], tokens[-1][0]}:
                # the floors of a top floor that repeats upwards, from the top: a shorter
                # façade drops them, a taller one gains copies of the top one; the layer
                # keeps its margin to the ground, its elements and gaps their sizes, and
                # the roof's margin never shrinks; that margin is the layer's own
                # (``<layer>_mr``): every other letter keeps its size, so two layers on
                # the same rows on stacks from unlike floors (a window's, its blind's)
                # each sum to the canvas to the rounding of the sizes written, a tenth of
                # a millimetre apart, and one margin shared would leave no layout
                roofs_own = _Symbols(f"{layer}_mr")
                owned[-1].append(roofs_own)
                word, steady, roof, shown = _stack_word(
                    grid.rows,
                    stack,
                    height,
                    symbols[1],
                    gaps,
                    margins,
                    roofs_own,
                    counters,
                    _deepest(stacked)[stack.pitch],
                )
                if stack.top:
                    copied_from.append(grid.rows[-1][0])
                    if grid.label in OPENINGS:
                        copied_to.append(grid.rows[-1][1])
                        copying.append(grid)
                held.update(steady)
                repeated.update(shown)
                roofs.add(roof)
                roofed.add(roof)
                words.append(word)
                continue
            pitch = tops.get(index) if axis == "y" and grid.label not in UNIQUE else None
            if pitch is not None and "^" not in word and ends >= {tokens[0][0], tokens[-1][0]}:
                # the top floor repeats upwards from none more; the layer keeps its margin
                # to the ground, and the copies and the roof's margin take what a taller
                # façade gains
                word, gap = _floors_above(tokens, pitch, gaps, counters)
                copied_from.append(grid.rows[-1][0])
                if grid.label in OPENINGS:
                    copied_to.append(grid.rows[-1][1])
                    copying.append(grid)
                held.update((tokens[0][0], gap))
                # the copies are whole floors, and the floors under them stay as drawn:
                # their elements keep their size (free, the solver shrank cmp_b0010's
                # windows 11% to fit a floor more)
                repeated.update(s for s, _ in tokens[1:-1] if s not in gaps.sizes.values())
                # and the gaps between its floors below keep their size: free, they would
                # stretch while the openings' floors keep their pitch; bounded above only,
                # a taller façade closed them up to fit a copy more than the height gained
                # holds (the family with defects' seed 13 at 1.5x height)
                held.update(gaps.sizes.values())
                roofs.add(tokens[-1][0])
                roofed.add(tokens[-1][0])
                words.append(word)
                continue
            if axis == "y" and tokens[0][0] in ends and tokens[-1][0] in ends:
                # which of its margins keeps its size is said after every layer is written
                bottom, high = tokens[0][0], tokens[-1][0]
                if bottom != high:
                    margins_y.append((grid.rows[0][0], grid.rows[-1][0], bottom, high))
                    margined_grids.append(grid)
                    over_y.append([s for s, _ in tokens if s in symbols[1].sizes.values()])
            elif axis == "y" and tokens[-1][0] in ends and tokens[0][0] not in ends:
                grounded.update(symbol for symbol, _ in tokens[:-1])  # a door keeps its height
            if not {tokens[0][0], tokens[-1][0]} & ends:  # no margin: its letters stay free
                loose.update(symbol for symbol, _ in tokens)
            elif "^n" in word:  # a run: the counter and the margins take the slack
                held.update(gaps.sizes.values())
                bottom = tokens[0][0]
                standing = grid.rows[0][0] < top and bottom != tokens[-1][0]
                if axis == "y" and bottom in ends and standing:
                    # floors standing on the ground floor keep their margin to it both
                    # ways (as a top floor repeating upwards does, ``_floors_above``):
                    # the roof's margin and the counter take the slack, not the ground's
                    held.add(bottom)
                    roofed.add(tokens[-1][0])
            else:
                margined.update(gaps.sizes.values())
            words.append(word)
        if floor_word is not None:
            words.append(floor_word)
        if grid.apart:
            unshrunk.update(symbols[0].of(b - a) for a, b in columns)
            unshrunk.update(symbols[1].of(b - a) for a, b in grid.rows)
        layers.append((layer, grid, words[0], words[1]))
    # a taller façade grows at the top of the floors: what stands on them keeps its
    # margin to the ground, what stands above them its margin to the top; what stands
    # wholly under a top floor that repeats upwards, or on it (a window of that floor
    # drawn apart, which does not repeat), keeps its margin to the ground, as that floor
    # does (moved up with the roof, cmp_b0005's upper floors stood over the copies of its
    # top one at 1.5x height, and cmp_b0002's window over the last copy); what stands
    # wholly over it (a lower top floor, an attic) keeps its margin to the roof, and
    # since the copies never take more than the height gained (``roofed``), it stays
    # clear of them
    copies = min(copied_from, default=top)
    copies_end = min(copied_to, default=float("inf"))  # the lowest end of a top floor copied
    # over the floors: over the openings' floors, or wholly over a top floor that repeats
    # upwards in its columns (an attic's row over a part of the façade whose floors end
    # lower than the others': cmp_b0008's middle, whose copies ran into it)
    aloft = [
        first >= top or _over_copies(grid, copying)
        for (first, *_), grid in zip(margins_y, margined_grids, strict=True)
    ]
    # under or on a top floor that repeats upwards in its columns: it keeps its margin to
    # the ground (a part whose floors end lower repeats too, so the lowest copied floor's
    # end is no line for the façade: cmp_b0001's windows under the top floor in their
    # columns moved up with the roof, over that floor's copies)
    below = [_under_copies(grid, copying) for grid in margined_grids]
    if stacked:
        # over floors a shorter façade drops (an attic, a lower top floor), a layer
        # keeps its margin to the roof and its elements their size both ways: it moves
        # down with the roof into the height the floors dropped leave (free, the solver
        # squeezed a lower top floor's windows to nothing instead)
        for (_, last, _, high), shown, up in zip(margins_y, over_y, aloft, strict=True):
            if up and last >= copies:
                held.add(high)
                repeated.update(shown)
    margined.update(
        bottom
        if floors is None and copied_to and (last < copies_end or low)
        else high
        if up and last >= copies
        else bottom
        for (_, last, bottom, high), up, low in zip(margins_y, aloft, below, strict=True)
    )
    out = [
        f"# Inferred by `facade infer` from {source}: a wall and {len(layers)} layers, each",
        "# a label's elements on a grid (its columns x its rows), back to front, with the",
        "# gaps between them (<layer>_gx, _gy: hidden); runs repeat with counters (n1, ...).",
        "# Sizes in metres: a line per label's elements, then per layer's gaps.",
        *_bays_note(bays),
        "version: 1",
        f"name: {name}",
        f"canvas: {{width: {_number(width)}, height: {_number(height)}}}",
        "symbol_defaults: {opaque: true}",
        f"solver: {{tolerance: {TOLERANCE}}}",
        "symbols: {",
        f"  wall_w: {_number(width)}, wall_h: {_number(height)},",
    ]
    spread = spread or {}
    clear = uncovered(found)
    fixed = (repeated - loose) | in_bay  # a run's letters keep their size where margins take
    # the slack, and so do a bay's
    margined -= roofs  # a layer on the same rows keeps its margin to the ground instead
    held -= loose
    # a line per label's elements, then per layer's own widths (``_width_tables``)
    tables: list[tuple[str, tuple[_Symbols, ...]]] = list(elements.items())
    tables += [
        (grid.label, (table,))
        for grid, table in zip(found, widths, strict=True)
        if table is not elements[grid.label][0]
    ]
    sizes = [
        [
            (
                symbol,
                _size(
                    size,
                    None if symbol in stretched else _spread_of(spread, axis, label, table, size),
                    symbol in fixed,
                    label in clear,
                    symbol in grounded,
                    symbol in unshrunk - loose,
                    axis == "x" and label in OPENINGS,
                ),
            )
            for axis, table in zip("xy", pair, strict=False)
            for size, symbol in table.sizes.items()
        ]
        for label, pair in tables
    ]
    sizes += [
        [
            (symbol, _gap(size, symbol in fixed | held, symbol in margined, symbol in roofed))
            for gaps in mine
            for size, symbol in gaps.sizes.items()
        ]
        for mine in owned
    ]
    sizes += [
        [(symbol, _gap(size, True, False)) for size, symbol in gaps.sizes.items()]
        for gaps in bay_gaps
    ]
    if in_bay and shared is not None:
        held_walls = shared.steady()
        sizes.append(
            [
                (
                    f"bay{kind + 1}_w",
                    f"{{size: {_number(wall)}, min: {_number(least)}, max: {_number(wall)}}}",
                )
                for kind, wall in enumerate(shared.walls)
                if wall
                for least in [wall if kind in held_walls else WALL * wall]
            ]
            + [
                (
                    _gain_wall(n),
                    f"{{size: {_number(gain.wall)}, min: {_number(WALL * gain.wall)}, "
                    f"max: {_number(gain.wall)}}}",
                )
                for n, gain in enumerate(shared.gains)
            ]
        )
    sizes.append([(symbol, _number(size)) for size, symbol in bay_margins.sizes.items()])
    out += [
        "  " + ", ".join(f"{symbol}: {size}" for symbol, size in line) + ","
        for line in sizes
        if line
    ]
    out[-1] = out[-1].rstrip(",")
    out.append("}")
    bay_counters = shared.counters if shared is not None and in_bay else ()
    spares = (shared.spare, shared.spare_first) if shared is not None else (None, None)
    if counters.names or bay_counters:
        out.append("counters:")
        out += [
            f"  {n}: {{min: 0}}  # {count or 'floors over the top one'} along {axis} at a "
            f"pitch of {_number(pitch)} m"
            if count >= 0
            else f"  {n}: {{min: 0, max: 1}}  # the floor {-1 - count} under the top one"
            f" along {axis} at a pitch of {_number(pitch)} m (0: dropped)"
            for (axis, pitch, count), n in counters.names.items()
        ]
        out += [
            f"  {n}: {{min: 0{'' if most is None else f', max: {most}'}}}  # "
            + _bay_counter_note(n, count, most, spares, shared)
            + f" along x at a pitch of {_number(pitch)} m"
            for n, pitch, count, most in bay_counters
        ]
    out.append("patterns: {wall_x: wall_w, wall_y: wall_h}")
    out.append("layers:")
    out.append("  # the background")
    out.append("  - {name: wall, x: wall_x, y: wall_y, shapes: [{material: wall, thickness: 0.3}]}")
    for k, (layer, grid, x, y) in enumerate(layers, start=1):
        mesh, thickness = MESHES.get(grid.label, DEFAULT_MESH)
        rows = ", ".join(f"{_number(a)}-{_number(b)}" for a, b in grid.rows)
        shown_x = sorted({widths[k - 1].of(b - a) for a, b in grid.columns})
        # the element symbols its y word writes (a layer on the floors writes each floor of
        # the run as its last, a row within ``floors.ALIKE`` of it by the last's symbol)
        written = set(re.findall(r"\w+", y))
        shown_y = sorted(n for n in _names(elements[grid.label][1]) if n in written)
        out += [
            f"  # {grid.elements} {grid.label} of the input: {len(grid.columns)} columns, "
            f"rows at y = {rows}",
            f'  - {{name: {layer}, x: "{x}", y: "{y}",',
            f"     visible: {{x: [{', '.join(shown_x)}], y: [{', '.join(shown_y)}]}}, "
            f"groups: {{x: {layer}, y: {layer}}}, offset: {_number(STEP * k)}, "
            f"shapes: [{{material: {ident(grid.label)}, mesh: {mesh}, thickness: {thickness}"
            f"{PANE if mesh in ('frame', 'door') else ''}}}]}}",
        ]
    colours = [("wall", label_colour("facade")), ("pane", PANE_COLOUR)]
    colours += [(ident(label), label_colour(label)) for label in elements]
    out.append("materials: {" + ", ".join(f'{n}: {{color: "{c}"}}' for n, c in colours) + "}")
    return "\n".join(out) + "\n"


def _bay_counter_note(
    name: str, count: int, most: int | None, spares: Spares, bays: Bays | None
) -> str:
    """What a counter of bays counts, for its comment: a spare end bay (``spares``: the
    last's, ``Bays.spare``, and the first's, ``Bays.spare_first``), a spare unit (a run
    of most one, none as drawn: ``bays._spare_unit``), the end bays, or the units of
    one or more bays drawn."""
    unit = max((r.unit for r in bays.runs if r.counter == name), default=1) if bays else 1
    units = f"{unit} bays" if unit > 1 else "1 bay"
    drawn = (
        f"{count} {'bay' if count == 1 else 'bays'}"
        if unit == 1
        else f"{count} {'unit' if count == 1 else 'units'} of {units}"
    )
    for n, gain in enumerate(bays.gains if bays else ()):
        if name == gain.counter:
            return (
                f"copies of the units of {gain.drawn} gained, each a unit of {units} with "
                f"{_gain_wall(n)} of wall before it (the façade's windows a metre)"
            )
        if name == gain.drawn:
            return f"{drawn}, at most as drawn (a wider façade gains {gain.counter})"
    if bays is not None and name in bays.sparse:
        return f"{drawn}, at most as drawn (sparser than the façade: it may drop)"
    if name in spares:
        end = "last" if name == spares[0] else "first"
        return f"a copy of the {end} bay more (the end bays change one at a time)"
    if most is not None and not count:
        return f"a copy of a unit of {units} more (the units change one at a time)"
    if most is not None:
        return "1 end bay (it may drop)" if count == 1 else f"{count} end bays (they may drop)"
    return drawn


def _gain_wall(n: int) -> str:
    """The symbol of the wall before each copy of the ``n``-th gain (``Bays.gains``)."""
    return f"bays_w{n + 1}"


def _bays_note(bays: Bays | str | None) -> list[str]:
    """The comment saying how the x words were written: on the façade's bays, or why not."""
    if bays is None:
        return []
    if isinstance(bays, str):
        return [
            f"# Bays not shared: {bays};",
            "# each layer has its own x word (what a narrower façade cannot drop, it squeezes).",
        ]
    return [
        f"# Bays: {bays.describe()}; every layer standing in them follows one sequence of",
        "# bays along x (bayK_g: a bay's hidden gaps; bayK_w: the wall after its elements,",
        "# which may narrow), runs with counters (bays1, ...), the margins (bays_mx) taking",
        "# the slack.",
    ]


def _kind_lines(bays: Bays, found: list[Grid]) -> list[list[Span]]:
    """Each bay kind's elements along x in its frame: the span of every element that
    stands in its bays, of every layer written on them (``segment``), sorted; their
    edges are the kind's lines."""
    spans: list[set[Span]] = [set() for _ in bays.widths]
    for grid in found:
        if grid.apart or not in_bays(bays, grid):
            continue
        for k, kind in enumerate(bays.kinds):
            spans[kind].update(segment(bays, grid, k) or [])
    return [sorted(kind) for kind in spans]


def _bay_word(
    bays: Bays,
    grid: Grid,
    element: _Symbols,
    gaps: list[_Symbols],
    margins: _Symbols,
    fixed: set[str],
    lines: list[list[Span]],
) -> str:
    """The grid's x word on the façade's bays (``infer.bays``): the left margin, each run
    of bays (its unit once, with its counter, or as drawn), the right margin; mirrored
    as the left half, the middle bay and the half reflected when the bays read so. The
    element symbols go into ``fixed``. A gap between two elements is cut at most twice:
    at the first edge in it of an element of the kind (``_kind_lines``) standing over
    or under the element before it, and at the last of one standing over or under the
    element after it, so that layers name the space between an element and its
    companion's edge alike (a window's inset in its sill's span is one symbol on either
    side, the sill's gap the rest). Cut at every line of the kind, the words held every
    line of every layer (CMP's b0001: 6,058 letters along x for 2,590, five times the
    solver's work). Each bay ends with its kind's wall (``bayK_w``: ``Bays.walls``),
    alike in every layer; a bay where the layer shows nothing is one hidden spacer; the
    spare copy of the last bay (``Bays.spare``) stands beside its copies: before the
    right margin, or before the reflected half where the word is mirrored; that of the
    first (``Bays.spare_first``) after the left margin."""
    walls = [f"bay{kind + 1}_w" for kind in range(len(bays.widths))]

    def spaces(
        kind: int, start: float, end: float, before: Span | None, after: Span | None
    ) -> list[str]:
        def edges(near: Span | None) -> list[float]:
            if near is None:
                return []
            x, y = near
            return [
                v
                for a, b in lines[kind]
                if a < y - SLIVER and b > x + SLIVER
                for v in (a, b)
                if start + SLIVER < v < end - SLIVER
            ]

        first, last = edges(before), edges(after)
        cuts = sorted({*([min(first)] if first else []), *([max(last)] if last else [])})
        if len(cuts) == 2 and cuts[1] - cuts[0] <= SLIVER:
            cuts = cuts[:1]
        return [gaps[kind].of(round(b - a, 4)) for a, b in pairwise([start, *cuts, end])]

    def bay(k: int) -> str:
        kind = bays.kinds[k]
        letters, cursor = [], 0.0
        shown = segment(bays, grid, k) or []
        for n, (a, b) in enumerate(shown):
            if a - cursor > 1e-9:
                letters.extend(spaces(kind, cursor, a, shown[n - 1] if n else None, (a, b)))
            letters.append(element.of(b - a))
            fixed.add(letters[-1])
            cursor = b
        wall = bays.walls[kind]
        end = bays.widths[kind] - wall
        if end - cursor > 1e-9:
            letters.extend(
                spaces(kind, cursor, end, shown[-1], None)
                if cursor
                else [gaps[kind].of(round(end, 4))]
            )
        if wall:
            letters.append(walls[kind])
        text = " ".join(letters)
        if not bays.mirrored[k] or all(
            s in gaps[kind].sizes.values() or s in walls for s in letters
        ):
            return text  # nothing shown: nothing to mirror
        return f"({text})^-1"

    gains = {gain.drawn: (n, gain) for n, gain in enumerate(bays.gains)}

    def written(run: BayRun) -> str:
        unit = " ".join(bay(k) for k in range(run.start, run.start + run.unit))
        if run.counter is None:
            return unit
        if run.counter in gains:  # the copies gained follow the unit, each after its wall,
            n, gain = gains[run.counter]  # where no counter drops a bay
            copies = f"({_gain_wall(n)} {unit})^{gain.counter}"
            for guard in gain.guards:
                copies = f"({copies})^{guard}"
            unit = f"{unit} {copies}"
        single = run.unit == 1 and " " not in unit and "(" not in unit
        return f"{unit}^{run.counter}" if single else f"({unit})^{run.counter}"

    def sequence(runs: list[BayRun], last: list[str], first: list[str]) -> str:
        parts = [*first, *(written(run) for run in runs)]
        left = margins.of(bays.margins[0])
        if bays.reflected:
            half = " ".join([left, *parts])
            middle = [bay(len(bays.kinds) // 2)] if len(bays.kinds) % 2 else []
            return " ".join([half, *middle, *last, f"({half})^-1"])
        return " ".join([left, *parts, *last, margins.of(bays.margins[1])])

    last = len(bays.kinds) - 1  # the spare copy of the last bay stands before it, if any
    spare = [] if bays.spare is None else [written(BayRun(last, 1, 1, bays.spare, 1))]
    first = [] if bays.spare_first is None else [written(BayRun(0, 1, 1, bays.spare_first, 1))]
    return sequence(list(bays.runs), spare, first)


def _floors_above(
    tokens: list[Token], pitch: float, gaps: _Symbols, counters: _Counters
) -> tuple[str, str]:
    """The y word of a layer whose top row is its label's top floor (``layers.top_floors``;
    ``tokens`` from its margin below to its margin above), that floor repeating upwards
    at ``pitch``: ``... h (g h)^n m``, the gap ``g`` the pitch less the element ``h``,
    ``n`` none at the input's size and shared by every such layer at that pitch; and
    the gap's symbol (its size is kept: the copies stand at the pitch)."""
    element, size = tokens[-2]
    gap = gaps.of(pitch - size)
    symbols = [symbol for symbol, _ in tokens]
    run = f"({gap} {element})^{counters.floors(pitch)}"
    return " ".join([*symbols[:-1], run, symbols[-1]]), gap


def _stacked(found: list[Grid], stacked: dict[int, Stack]) -> dict[int, Stack]:
    """The stacks (``layers.stacks``), where every layer standing higher than a floor a
    shorter façade may drop (over the lowest of the deepest stacks, which stays) is on
    a stack or wholly over the top floors (an attic, a lower top floor: it moves with
    the roof); else none. A layer on the floors that is on none
    (a balcony, a blind or a sill not alike on every floor, a pillar up the façade)
    stays where drawn while the floors under it drop, and a shorter façade still has
    no layout; the spec is then as without stacks (their counters cost the solver a
    search each: on CMP's samples they took b0001's and b0006's solves at 1.5x height
    past their budgets)."""
    if not stacked:
        return {}
    deepest = _deepest(stacked)
    # the lowest floor of the deepest stacks at a pitch stays (``_stack_word``): what
    # stands on it (a door) stays with it
    bottom = min(
        stack.bottom + (stack.pitch if stack.floors == deepest[stack.pitch] else 0.0)
        for stack in stacked.values()
    )
    over = min(found[k].rows[-1][1] for k, stack in stacked.items() if stack.top)
    for k, grid in enumerate(found):
        if k not in stacked and grid.rows[-1][1] > bottom + 1e-9 and grid.rows[0][0] < over:
            return {}
    return stacked


def _over_copies(grid: Grid, copying: list[Grid]) -> bool:
    """Whether ``grid`` stands wholly over one of the openings' top floors that repeat
    upwards (``copying``), in a column of its: their copies would run into it, so it
    keeps its margin to the roof."""
    return any(over(grid, top) and grid.rows[0][0] >= top.rows[-1][1] - 1e-9 for top in copying)


def _under_copies(grid: Grid, copying: list[Grid]) -> bool:
    """Whether ``grid``'s top row starts under the end of one of the openings' top floors
    that repeat upwards (``copying``), in a column of its: it stands under that floor or
    on it, and keeps its margin to the ground as the floor does."""
    return any(over(grid, top) and grid.rows[-1][0] < top.rows[-1][1] for top in copying)


def _deepest(stacked: dict[int, Stack]) -> dict[float, int]:
    """The most floors of the stacks at each pitch (the deepest keep their lowest floor)."""
    out: dict[float, int] = {}
    for stack in stacked.values():
        out[stack.pitch] = max(out.get(stack.pitch, 0), stack.floors)
    return out


def _stack_word(
    rows: tuple[Span, ...],
    stack: Stack,
    height: float,
    element: _Symbols,
    gaps: _Symbols,
    margins: _Symbols,
    roofs: _Symbols,
    counters: _Counters,
    deepest: int,
) -> tuple[str, list[str], str, list[str]]:
    """The y word of a layer on a stack of floors (``layers.stacks``): its rows under the
    stack as drawn (from its margin to the ground), then the stack's floors from the
    lowest, each inside the one under it with its own counter (``_Counters.drop``), so
    a floor stands only where every floor under it does and a shorter façade drops them
    from the top; a floor is the layer's row on it (a gap to where it starts, the
    element, the gap to the next floor) or one hidden gap of the pitch; over the top
    floor its copies (``_Counters.floors``: the top layer's, shown; hidden gaps in the
    others), then the margin to the roof (a symbol of ``roofs``). The lowest floor of
    the ``deepest`` stacks at its pitch has no counter: a façade keeps one floor of them
    at least. With the symbols that keep their size (the margin to the ground and the
    gaps), the roof's margin, and the elements."""
    on = dict(stack.rows)
    letters: list[str] = []
    cursor = 0.0
    for a, b in sorted(r for r in rows if r not in on):
        if a - cursor > SLIVER:
            letters.append((margins if not letters else gaps).of(a - cursor))
        letters.append(element.of(b - a))
        cursor = b
    if stack.bottom - cursor > TOLERANCE:
        letters.append((margins if not letters else gaps).of(stack.bottom - cursor))
    shown = [s for s in letters if s in element.sizes.values()]
    units: dict[int, list[str]] = {}
    for (a, b), floor in stack.rows:
        # a gap under the solver's tolerance is free (``_gap``): an element that far
        # from its slot's start stands at it, and one that far from the next slot's
        # ends the slot (the roof's margin takes the centimetre)
        start = stack.bottom + (stack.floors - 1 - floor) * stack.pitch
        offset = a - start if a - start > TOLERANCE else 0.0
        unit = [gaps.of(offset)] if offset else []
        unit.append(element.of(b - a))
        shown.append(unit[-1])
        if stack.pitch - offset - (b - a) > TOLERANCE:
            unit.append(gaps.of(stack.pitch - offset - (b - a)))
        units[floor] = unit
    hidden = gaps.of(stack.pitch)
    copy = units[0] if stack.top else [hidden]
    text = f"({' '.join(copy)})^{counters.floors(stack.pitch)}"
    for floor in range(stack.floors):
        letters_on = " ".join([*units.get(floor, [hidden]), text])
        text = (
            letters_on
            if floor == deepest - 1
            else f"({letters_on})^{counters.drop(stack.pitch, floor)}"
        )
    roof = roofs.of(height - stack.bottom - stack.floors * stack.pitch)
    steady = [s for s in {*letters, *gaps.sizes.values()} if s not in shown]
    return " ".join([*letters, text, roof]), steady, roof, shown


def floor_run(found: list[Grid], height: float, alike: float = ALIKE) -> tuple[int, Floors] | None:
    """The openings' run of floors (``infer.floors``; ``alike``: ``Floors``'), with the
    index of the grid whose y word writes it: the run its word gets (``_longest_run``, of
    an element and a gap, not mirrored), or None (no run: the top floors repeat upwards
    instead, ``_floors_above``)."""
    k = floors_grid(found)
    if k is None or found[k].label in UNIQUE:
        return None
    element, gap, margin = _Symbols("e"), _Symbols("g"), _Symbols("m")
    tokens = _tokens(found[k].rows, height, element, gap, margin)
    ends = _names(margin)
    counters = _Counters()
    if "^-1" in _word(tokens, "y", counters, set(), True, ends):
        return None
    run = _longest_run(tokens, ends)
    if run is None or run[2] != 2:
        return None
    _, start, unit, copies = run
    kinds = {**{s: "element" for s in _names(element)}, **{s: "gap" for s in _names(gap)}}
    letters = [(kinds[symbol], size) for symbol, size in tokens[start : start + unit]]
    pitch = sum(size for _, size in letters)
    end = sum(size for _, size in tokens[:start]) + copies * pitch
    return k, Floors(mid_wall(end, letters, pitch), pitch, copies, alike)


def _floor_word(
    rows: tuple[Span, ...],
    floors: Floors,
    height: float,
    element: _Symbols,
    gaps: _Symbols,
    margins: _Symbols,
    counters: _Counters,
    repeated: set[str],
) -> tuple[str, list[str], str | None]:
    """The y word of a layer that follows the openings' floors (``infer.floors``): as
    drawn under the run, one floor of it repeated with the openings' counter, as drawn
    over it; the symbols that keep their size (the margin to the ground, the gaps), and
    the margin to the roof (it takes the slack; None where the layer reaches the roof).
    Its elements go into ``repeated``: they keep their size, on the run and off it."""
    parts = floor_letters(rows, floors, height)
    named: list[list[str]] = []
    for letters in parts:
        names = []
        for kind, size in letters:
            table = element if kind == "element" else margins if kind == "margin" else gaps
            # a size written alike (to ``DECIMALS``) is the symbol the layer has already:
            # the floors are cut from the openings' rows, the layer's own within that
            same = (k for k in table.sizes if abs(k - size) < 0.5 * 10**-DECIMALS)
            names.append(table.of(next(same, size)))
        named.append(names)
    under, floor, over = named
    counter = counters.of("y", floors.pitch, floors.copies)
    run = f"{floor[0]}^{counter}" if len(floor) == 1 else f"({' '.join(floor)})^{counter}"
    kinds = [kind for part in parts for kind, _ in part]
    symbols = [*under, *floor, *over]
    roof = symbols[-1] if kinds[-1] == "margin" else None
    steady = [s for s, kind in zip(symbols, kinds, strict=True) if kind != "element" and s != roof]
    repeated.update(s for s, kind in zip(symbols, kinds, strict=True) if kind == "element")
    return " ".join([*under, run, *over]), steady, roof


def _width_tables(
    found: list[Grid],
    framed: list[Frame | None],
    names: list[str],
    elements: dict[str, tuple[_Symbols, _Symbols]],
) -> list[_Symbols]:
    """Each grid's table of width symbols: its label's, but for a grid that shares a
    floor's word (``layers.frames``) with an earlier grid of its label on the label's
    table, on other columns, with a column of a width that grid has: one of its own
    (``<layer>_w``, sized alike); grids on the same columns, one unit, share one. A
    layer's mask names the symbols it shows, so two layers of one word showing one symbol
    would each show the other's element."""
    tables = [elements[grid.label][0] for grid in found]
    for k, (grid, frame) in enumerate(zip(found, framed, strict=True)):
        if frame is None:
            continue
        same = [j for j in range(k) if framed[j] == frame and found[j].columns == grid.columns]
        if same and found[same[0]].label == grid.label:
            tables[k] = tables[same[0]]  # one unit (``layers.frames``): one column, one symbol
            continue
        taken = {
            round(b - a, SIZE_KEY)
            for j in range(k)
            if framed[j] == frame and tables[j] is tables[k]
            for a, b in found[j].columns
        }
        if taken & {round(b - a, SIZE_KEY) for a, b in grid.columns}:
            tables[k] = _Symbols(f"{names[k]}_w")
    return tables


def _by_owner(
    frame: Frame | None,
    found: list[Grid],
    framed: list[Frame | None],
    widths: list[_Symbols],
    own: _Symbols,
) -> _Symbols | list[_Symbols]:
    """The width symbols of a layer's columns: its own (``own``), or along a floor's word
    (``layers.frames``), each column's grid's (the other grids' hidden by the mask)."""
    if frame is None:
        return own
    owner = {
        c: widths[k] for k, grid in enumerate(found) if framed[k] == frame for c in grid.columns
    }
    return [owner[c] for c, _ in frame]


def _spread_of(
    spread: Spread, axis: str, label: str, table: _Symbols, size: float
) -> tuple[float, float] | None:
    """The range the input's elements of ``label`` span along ``axis`` (``spread``) that
    are now the size of ``size``'s symbol in ``table`` (``_Symbols.of``: every size it
    names); None when none is (a band)."""
    ranges = [spread[key] for k in table.seen(size) if (key := (axis, label, k)) in spread]
    if not ranges:
        return None
    return min(low for low, _ in ranges), max(high for _, high in ranges)


def _gap(size: float, repeated: bool, margined: bool, roofed: bool = False) -> str:
    """A gap's size: the gaps of a word with a run and a margin keep it (``min`` and
    ``max``: the bays keep their pitch and the counter and the margins take the slack, so
    layers whose runs share a counter keep their columns together at any size); other
    gaps of a word with a margin do not grow (the margins take what the façade gains, so
    every such layer moves alike, yet a narrower façade may close them up); margins, and
    gaps of words without one, are free, and so is a gap under the solver's tolerance (a
    sliver between elements drawn touching: bounded, it leaves the solver no layout).
    ``roofed``: the margin to the roof over floors a taller façade gains, which never
    shrinks (``min``, less the solver's tolerance): the floors gained are those that fit
    in the height gained, the rest of it goes to the roof's margin (rounded to the
    nearest floor, a floor more than fits ate into it, and cmp_b0005 at 1.5x height had
    20% more windows a square metre than drawn)."""
    if size < TOLERANCE:
        return _number(size)
    if repeated:
        return f"{{size: {_number(size)}, min: {_number(size)}, max: {_number(size)}}}"
    if margined:
        return f"{{size: {_number(size)}, max: {_number(size)}}}"
    if roofed:  # to the solver's tolerance: the sizes are written rounded
        return f"{{size: {_number(size)}, min: {_number(size - TOLERANCE)}}}"
    return _number(size)


def _size(
    size: float,
    spread: tuple[float, float] | None,
    repeated: bool = False,
    unoccludable: bool = False,
    grounded: bool = False,
    kept: bool = False,
    opening: bool = False,
) -> str:
    """A symbol's size, with the bounds the input shows (``spread``: the least and
    greatest size its elements had before regularising; None for bands, which stretch
    with the façade). An element never grows beyond the greatest (``max``): a wider
    façade widens the gaps around a door, not the door; one that does not repeat may
    shrink to fit, an ``opening`` (a window's or a door's width) to ``SQUEEZE`` of itself
    at most (``min``): where the layers' words cannot drop it, the walls and margins take
    what a narrower façade loses (each symbol's deviation costs once however often the
    word repeats it, so unbounded, the openings' widths took nearly all of it: CMP's
    windows at 0.7x were squeezed to slivers). A run's elements keep their size (``min``
    and ``max``), as its gaps do (``_gap``): a façade of another size gains or loses bays
    and floors at the input's pitch, and the layers sharing the run's counter keep their
    columns together.
    ``unoccludable`` for openings nothing covers in the input: each layer is its own
    alignment group, so it steers nothing until layers are grouped (SPEC 2.6), and then
    keeps what was clear clear. ``grounded``: an element of a word that starts at the
    ground with no margin (a door): it never grows, the margin over it takes the slack.
    ``kept``: an element of a layer left where drawn, off the bays (``Grid.apart``): it
    never shrinks below the least it was drawn (``min``), or the solver, which counts a
    symbol once however many layers share it, would squeeze one shared by many such
    layers to a sliver to spare all their margins at once."""
    extra = []
    if spread is not None and repeated:
        extra += [f"min: {_number(size)}", f"max: {_number(size)}"]
    elif spread is not None:
        if kept:
            extra.append(f"min: {_number(min(spread[0], size))}")
        elif opening:
            extra.append(f"min: {_number(SQUEEZE * size)}")
        extra.append(f"max: {_number(max(spread[1], size))}")
    elif grounded:
        extra.append(f"max: {_number(size)}")
    if unoccludable:
        extra.append("unoccludable: true")
    if not extra:
        return _number(size)
    return "{" + ", ".join([f"size: {_number(size)}", *extra]) + "}"


def layer_names(found: list[Grid]) -> list[str]:
    """A name for each grid's layer: its label, numbered from the second grid of a label
    on (``wall`` is the background's)."""
    taken: dict[str, int] = {"wall": 1}
    names = []
    for grid in found:
        base = ident(grid.label)
        taken[base] = taken.get(base, 0) + 1
        names.append(base if taken[base] == 1 else f"{base}_{taken[base]}")
    return names


def _number(value: float) -> str:
    text = f"{round(value, DECIMALS):.{DECIMALS}f}".rstrip("0").rstrip(".")
    return text if text not in ("", "-0") else "0"
