"""Split grammars from tilings (Wu et al. 2014, section 3): rules, cost, the greedy
baseline, and derivation back to a tiling.

A rule splits a region along one axis into parts (``split``), or repeats a pattern of
parts (``repeat``). Regions with the same content (labels and sizes) share a symbol, so a
grammar describes a façade by its distinct pieces; its cost is Eq. 1-2: per rule, 0.1 for a
split or 0.5 for a repeat, plus the number of successors.

The greedy baseline cuts each region along every useful line of one axis (a line that
separates different labels somewhere and crosses no element), the axis with the more
distinct boundaries first; the approximate dynamic programming search of section 4 is to
come and will be compared against it.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Literal

from facadecli.grammar.tiling import BACKGROUND, Tiling

SPLIT_COST = 0.1
REPEAT_COST = 0.5
Axis = Literal["x", "y"]


@dataclass(frozen=True)
class Part:
    size: float  # metres (or façade units) along the rule's axis
    symbol: str


@dataclass(frozen=True)
class Rule:
    op: Literal["split", "repeat"]
    axis: Axis
    parts: tuple[Part, ...]  # for a repeat, the pattern repeated ``count`` times
    count: int = 1

    @property
    def cost(self) -> float:
        return (REPEAT_COST if self.op == "repeat" else SPLIT_COST) + len(self.parts)

    def text(self, name: str) -> str:
        body = " | ".join(f"{p.size:.4g}: {p.symbol}" for p in self.parts)
        suffix = f"*{self.count}" if self.op == "repeat" else ""
        return f"{name} --> {self.op}({self.axis}) {{ {body} }}{suffix}"


@dataclass
class Grammar:
    start: str
    rules: dict[str, Rule] = field(default_factory=dict)
    terminals: set[str] = field(default_factory=set)

    @property
    def cost(self) -> float:
        return sum(rule.cost for rule in self.rules.values())

    def text(self) -> str:
        """One rule a line, CGA-like (the paper's section 4.6), the start symbol first."""
        names = [self.start, *(name for name in self.rules if name != self.start)]
        return "\n".join(self.rules[name].text(name) for name in names if name in self.rules) + "\n"


@dataclass(frozen=True)
class _Region:
    r0: int
    r1: int
    c0: int
    c1: int


class _Extractor:
    def __init__(self, tiling: Tiling, background: str):
        self.t = tiling
        self.background = background
        self.grammar = Grammar(start="")
        self.symbols: dict[tuple[object, ...], str] = {}

    def label(self, row: int, column: int) -> str:
        return self.t.labels[row][column]

    def content(self, region: _Region) -> tuple[object, ...]:
        rows = tuple(self.t.labels[r][region.c0 : region.c1] for r in range(region.r0, region.r1))
        widths = tuple(
            round(self.t.xs[c + 1] - self.t.xs[c], 6) for c in range(region.c0, region.c1)
        )
        heights = tuple(
            round(self.t.ys[r + 1] - self.t.ys[r], 6) for r in range(region.r0, region.r1)
        )
        return rows, widths, heights

    def symbol(self, region: _Region) -> str:
        labels = {
            self.label(r, c)
            for r in range(region.r0, region.r1)
            for c in range(region.c0, region.c1)
        }
        if len(labels) == 1:
            (label,) = labels
            self.grammar.terminals.add(label)
            return label
        key = self.content(region)
        if key in self.symbols:
            return self.symbols[key]
        name = f"N{len(self.symbols) + 1}"
        self.symbols[key] = name
        self.grammar.rules[name] = self.rule(region)
        return name

    def cuts(self, region: _Region, axis: Axis) -> list[int]:
        """Useful lines of an axis inside a region: they separate different labels in some
        place and cut through no element (the background may be cut anywhere)."""
        found = []
        if axis == "x":
            for c in range(region.c0 + 1, region.c1):
                pairs = [
                    (self.label(r, c - 1), self.label(r, c)) for r in range(region.r0, region.r1)
                ]
                if self.valid(pairs):
                    found.append(c)
        else:
            for r in range(region.r0 + 1, region.r1):
                pairs = [
                    (self.label(r - 1, c), self.label(r, c)) for c in range(region.c0, region.c1)
                ]
                if self.valid(pairs):
                    found.append(r)
        return found

    def valid(self, pairs: list[tuple[str, str]]) -> bool:
        changes = any(a != b for a, b in pairs)
        crosses = any(a == b != self.background for a, b in pairs)
        return changes and not crosses

    def rule(self, region: _Region) -> Rule:
        x, y = self.cuts(region, "x"), self.cuts(region, "y")
        axis: Axis = "y" if len(y) >= len(x) and y else "x"
        lines = y if axis == "y" else x
        if not lines:  # no clean line: cut where the fewest elements are crossed
            axis, lines = self.fallback(region)
        bounds = [
            region.r0 if axis == "y" else region.c0,
            *lines,
            region.r1 if axis == "y" else region.c1,
        ]
        parts = []
        for a, b in itertools.pairwise(bounds):
            sub = (
                _Region(a, b, region.c0, region.c1)
                if axis == "y"
                else _Region(region.r0, region.r1, a, b)
            )
            cuts = self.t.ys if axis == "y" else self.t.xs
            parts.append(Part(round(cuts[b] - cuts[a], 6), self.symbol(sub)))
        return self.compress(axis, parts)

    def compress(self, axis: Axis, parts: list[Part]) -> Rule:
        """A repeat when the parts are copies of a shorter pattern; else a head and a
        repeated rest (A B A B A: A, then (B A) twice), the repeat under a symbol of its own;
        else a plain split."""
        whole = _repeat(axis, parts)
        if whole is not None or len(parts) < 3:
            return whole or Rule("split", axis, tuple(parts))
        for head in (1, 2):
            rest = _repeat(axis, parts[head:])
            if rest is not None:
                key = ("repeat", axis, rest.parts, rest.count)
                if key not in self.symbols:
                    self.symbols[key] = f"N{len(self.symbols) + 1}"
                    self.grammar.rules[self.symbols[key]] = rest
                size = round(sum(p.size for p in rest.parts) * rest.count, 6)
                return Rule("split", axis, (*parts[:head], Part(size, self.symbols[key])))
        return Rule("split", axis, tuple(parts))

    def fallback(self, region: _Region) -> tuple[Axis, list[int]]:
        if region.c1 - region.c0 > 1:
            return "x", [(region.c0 + region.c1) // 2]
        return "y", [(region.r0 + region.r1) // 2]


def _repeat(axis: Axis, parts: list[Part]) -> Rule | None:
    """A repeat rule when the parts are two or more copies of a shorter pattern."""
    n = len(parts)
    for period in range(1, n // 2 + 1):
        if n % period == 0 and all(parts[i] == parts[i % period] for i in range(n)):
            return Rule("repeat", axis, tuple(parts[:period]), n // period)
    return None


def greedy_grammar(tiling: Tiling, background: str = BACKGROUND) -> Grammar:
    """The greedy baseline: every useful line of one axis at a time (see the module)."""
    extractor = _Extractor(tiling, background)
    whole = _Region(0, len(tiling.ys) - 1, 0, len(tiling.xs) - 1)
    start = extractor.symbol(whole)
    grammar = extractor.grammar
    grammar.start = start
    return grammar


def derive(
    grammar: Grammar, width: float, height: float
) -> list[tuple[str, float, float, float, float]]:
    """The terminal rectangles (label, x0, y0, x1, y1) the grammar derives."""
    out: list[tuple[str, float, float, float, float]] = []

    def expand(symbol: str, x0: float, y0: float, x1: float, y1: float) -> None:
        rule = grammar.rules.get(symbol)
        if rule is None:
            out.append((symbol, x0, y0, x1, y1))
            return
        cursor = y0 if rule.axis == "y" else x0
        for _ in range(rule.count):
            for part in rule.parts:
                end = cursor + part.size
                if rule.axis == "y":
                    expand(part.symbol, x0, cursor, x1, end)
                else:
                    expand(part.symbol, cursor, y0, end, y1)
                cursor = end

    expand(grammar.start, 0.0, 0.0, width, height)
    return out
