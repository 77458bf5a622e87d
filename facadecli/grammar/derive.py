"""Deriving, the fourth stage of ``facade grammar``: a grammar at a new size (Wu et al.
2014, section 5).

Size independence: a part thinner than ``THIN`` of the façade's extent along its axis keeps
its absolute size (frames, sills, slivers of wall); the other parts are weights. A repeat
lays as many copies as fit best (the nearest whole number, at least one) and stretches them
slightly. Within a split, parts that hold a repeat along the split's axis are *elastic*: they
take up the change in size while the others keep theirs, so a wider façade gets more window
bays rather than wider windows; without elastic parts, the weights share the change. Runs
of bays alike in a split (:func:`with_runs`) are laid as many as fit too.

The derivation is then tidied (:mod:`facadecli.grammar.align`), compared with whole bays
and floors copied (:mod:`facadecli.grammar.slabs`) and varied
(:mod:`facadecli.grammar.vary`); :mod:`facadecli.grammar.variations` picks what is written.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

from facadecli.grammar.model import Piece
from facadecli.grammar.split import Grammar, Part, Rule
from facadecli.grammar.tiling import BACKGROUND

THIN = 0.03  # of the source façade's extent: thinner parts keep their absolute size
MAX_PIECES = 200_000  # a derivation making more terminals than this is refused
REPEATS = ("repeat", "repeatABA", "run")  # rules whose count the derivation chooses
RUN_BAYS = 3  # bays of one size and kind side by side that a derivation may add to
RUN_LEAST = 0.05  # of the source's extent: a narrower part is no bay (a slat, a frame)
STRETCH = 0.5  # a varied repeat's copies stay within 1/(1 + this) to 1 + this of their size


class TooLarge(ValueError):
    """The new size would make too many pieces."""


def elastic_parts(grammar: Grammar) -> dict[tuple[str, str], bool]:
    memo: dict[tuple[str, str], bool] = {}

    def elastic(symbol: str, axis: str) -> bool:
        key = (symbol, axis)
        if key not in memo:
            rule = grammar.rules.get(symbol)
            memo[key] = (
                rule is not None
                and rule.axis == axis
                and rule.op != "gridsplit"
                and (rule.op in REPEATS or any(elastic(p.symbol, axis) for p in rule.parts))
            )
        return memo[key]

    for symbol in grammar.rules:
        for axis in ("x", "y"):
            elastic(symbol, axis)
    return memo


def distribute(
    sizes: list[float], absolute: list[bool], elastic: list[bool], extent: float
) -> list[float]:
    """New sizes of parts filling ``extent`` (see the module)."""
    total = sum(sizes)
    fixed = sum(s for s, a in zip(sizes, absolute, strict=True) if a)
    if fixed >= extent or fixed >= total:
        return [s * extent / total for s in sizes]
    free = [not a for a in absolute]
    stretch = [f and e for f, e in zip(free, elastic, strict=True)]
    rigid = sum(s for s, f, e in zip(sizes, free, stretch, strict=True) if f and not e)
    stretchy = sum(s for s, e in zip(sizes, stretch, strict=True) if e)
    if stretchy > 0 and extent - fixed - rigid >= stretchy / 2:
        scale = (extent - fixed - rigid) / stretchy
        return [s * scale if e else s for s, e in zip(sizes, stretch, strict=True)]
    scale = (extent - fixed) / (total - fixed)
    return [s * scale if f else s for s, f in zip(sizes, free, strict=True)]


def derive_at(
    grammar: Grammar,
    source: tuple[float, float],
    width: float,
    height: float,
    offsets: dict[str, int] | None = None,
    used: set[str] | None = None,
) -> list[Piece]:
    """The grammar applied to a façade of a new size (see the module). ``offsets`` adds to
    the best-fitting count of each repeat rule named (every region the rule makes gets the
    same offset, except where the count would be below one or stretch its copies beyond
    ``STRETCH``: there it keeps the best fit); ``used`` collects the repeat rules the
    derivation applies."""
    elastic = elastic_parts(grammar)
    thin = {"x": THIN * source[0], "y": THIN * source[1]}
    out: list[Piece] = []

    def expand(
        symbol: str, box: tuple[float, float, float, float], src: tuple[float, float]
    ) -> None:
        x0, y0, x1, y1 = box
        rule = grammar.rules.get(symbol)
        if rule is None:
            out.append(Piece(symbol, x0, y0, x1, y1, src[0], src[1]))
            if len(out) > MAX_PIECES:
                raise TooLarge(
                    f"{width:g}x{height:g} makes more than {MAX_PIECES:,} pieces; "
                    "choose a smaller size"
                )
            return
        if rule.op == "gridsplit":
            _grid(rule, box, expand)
            return
        axis = rule.axis
        extent = (x1 - x0) if axis == "x" else (y1 - y0)
        if used is not None and rule.op in REPEATS:
            used.add(symbol)
        sequence = _fit(rule, extent, (offsets or {}).get(symbol, 0))
        sizes = distribute(
            [p.size for p in sequence],
            [p.size < thin[axis] for p in sequence],
            [elastic.get((p.symbol, axis), False) for p in sequence],
            extent,
        )
        cursor = x0 if axis == "x" else y0
        for part, size in zip(sequence, sizes, strict=True):
            end = cursor + size
            if axis == "x":
                expand(part.symbol, (cursor, y0, end, y1), (part.size, src[1]))
            else:
                expand(part.symbol, (x0, cursor, x1, end), (src[0], part.size))
            cursor = end

    expand(grammar.start, (0.0, 0.0, width, height), source)
    return out


def _fit(rule: Rule, extent: float, offset: int = 0) -> tuple[Part, ...]:
    """The rule's parts in order, with as many repeats as fit best (plus ``offset``)."""
    period = sum(p.size for p in rule.parts)
    if rule.op == "repeat":
        count = _count(extent, period, offset)
        return rule.parts * count
    if rule.op == "repeatABA":
        a, b = rule.parts
        count = _count(extent - a.size, period, offset)
        return (a, *((b, a) * count))
    if rule.op == "run":
        a, b = rule.parts[:2]
        count = _count(extent - a.size, a.size + b.size, offset) + 1
        return _run_of(rule.parts, max(count, (len(rule.parts) + 1) // 2))
    return rule.sequence()


def _run_of(parts: tuple[Part, ...], count: int) -> tuple[Part, ...]:
    """A run's bays A B A B A made ``count`` bays long (never fewer than the source's):
    the source's bays as they are, and copies of the middle bay beside it (a symmetric run
    stays symmetric)."""
    bays, gap = list(parts[::2]), parts[1]
    middle = (len(bays) - 1) // 2
    bays = [*bays[: middle + 1], *[bays[middle]] * (count - len(bays)), *bays[middle + 1 :]]
    sequence: list[Part] = []
    for bay in bays:
        sequence += [gap, bay] if sequence else [bay]
    return tuple(sequence)


def with_runs(grammar: Grammar, source: tuple[float, float]) -> Grammar:
    """The grammar with every run of bays in a split (see :func:`_run_end`) made a rule of
    its own, a ``run``, that the derivation lays as many bays of as fit: windows of one size
    and kind drawn a little differently from bay to bay (a sill missing, a pillar thinner)
    are not one rule a repeat could copy, yet a wider façade should get more of them."""
    kinds: dict[str, frozenset[str]] = {}

    def kind(symbol: str) -> frozenset[str]:
        """The labels a symbol's region holds."""
        if symbol not in kinds:
            rule = grammar.rules.get(symbol)
            kinds[symbol] = (
                frozenset([symbol])
                if rule is None
                else frozenset().union(*(kind(p.symbol) for p in rule.parts))
            )
        return kinds[symbol]

    rules = dict(grammar.rules)
    for name, rule in grammar.rules.items():
        if rule.op != "split":
            continue
        least = RUN_LEAST * (source[0] if rule.axis == "x" else source[1])
        parts: list[Part] = []
        at = 0
        while at < len(rule.parts):
            end = _run_end(rule.parts, at, kind) if rule.parts[at].size >= least else at + 1
            if end - at < RUN_BAYS * 2 - 1:
                parts.append(rule.parts[at])
                at += 1
                continue
            symbol = f"{name}~run{at}"
            run = rule.parts[at:end]
            rules[symbol] = Rule("run", rule.axis, run)
            parts.append(Part(sum(p.size for p in run), symbol))
            at = end
        if len(parts) < len(rule.parts):
            rules[name] = replace(rule, parts=tuple(parts))
    return replace(grammar, rules=rules)


def _run_end(parts: Sequence[Part], at: int, kind: Callable[[str], frozenset[str]]) -> int:
    """Where a run of bays that starts at ``at`` ends (``at`` + 1 when none): bays of one
    size and the same kinds of element, not plain wall, between gaps of one symbol and size,
    A B A B A."""
    first = parts[at]
    if kind(first.symbol) <= {BACKGROUND}:
        return at + 1
    end = at + 1
    while end + 1 < len(parts):
        gap, bay = parts[end], parts[end + 1]
        same_gap = end == at + 1 or (
            gap.symbol == parts[at + 1].symbol and _alike(gap.size, parts[at + 1].size)
        )
        if not (
            same_gap
            and gap.symbol != first.symbol
            and _alike(bay.size, first.size)
            and kind(bay.symbol) == kind(first.symbol)
        ):
            break
        end += 2
    return end


def _alike(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-6 * max(abs(a), abs(b), 1e-12)


def _count(length: float, period: float, offset: int) -> int:
    best = max(1, round(length / period))
    if offset == 0:
        return best
    count = best + offset
    stretch = length / (count * period) if count >= 1 else 0.0
    if count < 1 or not 1 / (1 + STRETCH) <= stretch <= 1 + STRETCH:
        return best
    return count


def _grid(rule: Rule, box: tuple[float, float, float, float], expand: object) -> None:
    x0, y0, x1, y1 = box
    columns = len(rule.across)
    rows = [rule.parts[i * columns].size for i in range(len(rule.parts) // columns)]
    widths = [w * (x1 - x0) / sum(rule.across) for w in rule.across]
    heights = [h * (y1 - y0) / sum(rows) for h in rows]
    y = y0
    for i, h in enumerate(heights):
        x = x0
        for j, w in enumerate(widths):
            part = rule.parts[i * columns + j]
            expand(part.symbol, (x, y, x + w, y + h), (rule.across[j], rows[i]))  # type: ignore[operator]
            x += w
        y += h
