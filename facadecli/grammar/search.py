"""Finding a small split grammar for a tiling (Wu et al. 2014, sections 4.1-4.5).

A grammar is built top down: the non-terminal regions without a rule are taken bottom to
top, left to right, and each gets a rule (an *action*); only the first region of each content
is split, the others reuse its rule. The actions offered for a region are the reasonable
ones (section 4.4): along each axis, a cut at every clean line, a cut at one line, cuts that
keep a periodic run of parts or the repeated regions found by hashing (``symmetry``) whole,
and with the extensions a two-way grid. Each is written as the cheapest rule that fits its
parts (repeat, repeatABA, symsplit or split).

The splitting heuristic (Eq. 5) is the rule's cost plus, for each line it cuts, the cells of
the repeated regions that line cuts through over the cells of the region.

- ``greedy``: every region takes the action the heuristic likes best.
- ``adp``: approximate dynamic programming. Each iteration builds a whole grammar; at each
  region it explores with probability epsilon (an action drawn with probability
  proportional to ``exp(-H)``) and exploits otherwise (the action with the least rule cost
  plus the value table's estimate for the new regions it makes, Eq. 4). Epsilon falls
  linearly over the iterations. After each iteration the table keeps, per content, the
  least cost found for describing it (each rule below it counted once) and the contents
  those rules split, so that a part held inside another part is not paid for twice; a
  content not in the table yet is valued at the cheapest rule's cost. A grammar built before
  teaches nothing new and is skipped. The first iteration is the greedy one, so the result
  is never worse than greedy's; the cheapest grammar of all iterations is returned. A seed
  makes it reproducible; a time limit stops early with the best grammar so far.

The run's ``Deadline`` bounds the work: the greedy grammar checks its hard limit at every
region (exit 4 when it passes), ADP stops at the soft limit, even within an iteration.
"""

from __future__ import annotations

import heapq
import itertools
import math
import random
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from facadecli.grammar.deadline import Deadline
from facadecli.grammar.regions import Grid, Region
from facadecli.grammar.split import DEFAULT_COSTS, Axis, Costs, Grammar, Op, Part, Rule
from facadecli.grammar.symmetry import Repeats, find_repeats
from facadecli.grammar.tiling import BACKGROUND, Tiling

EMPTY: frozenset[int] = frozenset()
GRID_CELLS = 48  # a gridsplit of more cells than this costs more than it can save
TOP_ACTIONS = 8  # actions per region the search chooses among (the heuristic's best)


@dataclass(frozen=True)
class Action:
    op: Op
    axis: Axis
    bounds: tuple[int, ...]  # cut indices along the axis, the region's ends included
    written: tuple[Region, ...]  # the parts written in the rule
    cids: tuple[int, ...]  # their contents
    needs: tuple[int, ...]  # contents of the written parts that are not terminals, once each
    cost: float
    heuristic: float
    count: int = 1
    centre: bool = False
    across: tuple[int, ...] = ()  # gridsplit: the column bounds
    form: tuple[object, ...] = ()  # the rule without its symbols: op, axis, sizes


@dataclass
class SearchResult:
    grammar: Grammar
    method: str
    iterations: int
    best_iteration: int
    greedy_cost: float
    regions: int  # distinct regions given actions
    repeats: int  # repeated regions found by hashing (kinds)
    repeats_complete: bool = True  # False when the time limit stopped their search


class Search:
    def __init__(
        self,
        tiling: Tiling,
        costs: Costs = DEFAULT_COSTS,
        extensions: tuple[str, ...] = (),
        background: str = BACKGROUND,
        deadline: Deadline | None = None,
    ):
        self.deadline = deadline or Deadline()
        self.grid = Grid(tiling, background)
        self.costs = costs
        self.extensions = set(extensions)
        self.repeats: Repeats = find_repeats(self.grid, deadline=self.deadline)
        self._actions: dict[Region, list[Action]] = {}
        self._greedy: dict[int, Action] | None = None
        self.whole: Region = (0, self.grid.rows, 0, self.grid.columns)

    @property
    def regions_explored(self) -> int:
        """Regions that were offered actions."""
        return len(self._actions)

    # -- actions ------------------------------------------------------------------------

    def actions(self, region: Region) -> list[Action]:
        found = self._actions.get(region)
        if found is None:
            found = self._make_actions(region)
            self._actions[region] = found
        return found

    def _make_actions(self, region: Region) -> list[Action]:
        r0, r1, c0, c1 = region
        usable: dict[Axis, list[int]] = {}
        fallback: dict[Axis, tuple[int, list[int]]] = {}
        for axis in ("x", "y"):
            lines, crosses = self.grid.lines(region, axis)
            clean = [line for line, k in zip(lines, crosses, strict=True) if k == 0]
            if clean:
                usable[axis] = clean
            elif lines:
                least = min(crosses)
                fallback[axis] = (
                    least,
                    [ln for ln, k in zip(lines, crosses, strict=True) if k == least],
                )
        if not usable:  # every line cuts an element: cut where the fewest element cells are
            if not fallback:
                raise ValueError(f"region {region} has one label and no rule")
            axis = min(fallback, key=lambda a: (fallback[a][0], a))
            usable[axis] = fallback[axis][1]
        found: dict[tuple[object, ...], Action] = {}  # cuts that keep structure whole
        halves: dict[tuple[object, ...], Action] = {}  # cuts in two
        for axis, lines in usable.items():
            lo, hi = (c0, c1) if axis == "x" else (r0, r1)
            cost_of_line = self._line_costs(region, axis)
            full = (lo, *lines, hi)
            options = [full, *self._runs(region, axis, full), *self._repeated(region, axis, full)]
            for bounds in options:
                action = self._action(region, axis, bounds, cost_of_line)
                if action is not None:
                    found.setdefault((action.axis, action.bounds), action)
            # cuts in two: only the lines the heuristic likes best are worth making rules of
            cheapest = sorted(lines, key=lambda ln: (cost_of_line.get(ln, 0.0), ln))
            for line in cheapest[:TOP_ACTIONS] if len(lines) > 1 else ():
                action = self._action(region, axis, (lo, line, hi), cost_of_line)
                if action is not None and (axis, action.bounds) not in found:
                    halves[(axis, action.bounds)] = action
        if (
            "gridsplit" in self.extensions
            and "x" in usable
            and "y" in usable
            and (len(usable["x"]) + 1) * (len(usable["y"]) + 1) <= GRID_CELLS
        ):
            grid = self._gridsplit(region, usable)
            if grid is not None:
                found[("xy", grid.bounds, grid.across)] = grid

        def rank(a: Action) -> tuple[object, ...]:
            return (a.heuristic, a.cost, a.axis, a.bounds)

        # every structural cut, and the heuristic's best cuts in two to fill up the choice
        kept = sorted(found.values(), key=rank)[:TOP_ACTIONS]
        kept += sorted(halves.values(), key=rank)[: max(TOP_ACTIONS - len(kept), TOP_ACTIONS // 2)]
        return sorted(kept, key=rank)

    def _line_costs(self, region: Region, axis: Axis) -> dict[int, float]:
        """The heuristic's cost of each line of an axis inside the region (section 4.4)."""
        r0, r1, c0, c1 = region
        rep = self.repeats.starting_in(r0, r1)
        inside = (rep.r0 >= r0) & (rep.r1 <= r1) & (rep.c0 >= c0) & (rep.c1 <= c1)
        lo, hi = (c0, c1) if axis == "x" else (r0, r1)
        lines = np.arange(lo + 1, hi)
        if not inside.any() or lines.size == 0:
            return {}
        start = (rep.c0 if axis == "x" else rep.r0)[inside]
        stop = (rep.c1 if axis == "x" else rep.r1)[inside]
        weights = rep.cells[inside].astype(float)
        # a repeat's cells count for the lines strictly inside its span: summed as
        # differences (+ after its start, - at its end), linear in repeats plus lines
        size = hi - lo + 1
        steps = np.bincount(start + 1 - lo, weights, size) - np.bincount(stop - lo, weights, size)
        cells = (r1 - r0) * (c1 - c0)
        costs = np.cumsum(steps)[1 : hi - lo] / cells
        return {int(line): float(c) for line, c in zip(lines, costs, strict=True) if c > 0}

    def _runs(self, region: Region, axis: Axis, full: tuple[int, ...]) -> list[tuple[int, ...]]:
        """Bounds that keep each maximal periodic run of two or more parts as one part."""
        cids = [
            self.grid.content(self._part(region, axis, a, b)) for a, b in itertools.pairwise(full)
        ]
        n = len(cids)
        out = []
        for period in range(1, n // 2 + 1):
            i = 0
            while i + 2 * period <= n:
                k = 1
                while (
                    i + (k + 1) * period <= n
                    and cids[i + k * period : i + (k + 1) * period] == cids[i : i + period]
                ):
                    k += 1
                if k >= 2 and not (i == 0 and i + k * period == n):
                    end = i + k * period
                    out.append((*full[: i + 1], *full[end:]))
                    i = end
                else:
                    i += 1
        return out

    def _repeated(self, region: Region, axis: Axis, full: tuple[int, ...]) -> list[tuple[int, ...]]:
        """Bounds that keep whole the repeated regions spanning the region across the axis."""
        r0, r1, c0, c1 = region
        rep = self.repeats.starting_in(r0, r1)
        if axis == "x":
            spans = (rep.r0 == r0) & (rep.r1 == r1) & (rep.c0 >= c0) & (rep.c1 <= c1)
            start, stop = rep.c0[spans], rep.c1[spans]
        else:
            spans = (rep.c0 == c0) & (rep.c1 == c1) & (rep.r0 >= r0) & (rep.r1 <= r1)
            start, stop = rep.r0[spans], rep.r1[spans]
        lo, hi = full[0], full[-1]
        blocks: list[tuple[int, int]] = []
        for a, b in sorted(
            zip(start.tolist(), stop.tolist(), strict=True), key=lambda s: (s[0] - s[1], s)
        ):
            if (a, b) != (lo, hi) and all(b <= x or y <= a for x, y in blocks):
                blocks.append((a, b))
        if not blocks:
            return []
        bounds = {lo, hi, *(v for block in blocks for v in block)}
        bounds |= {line for line in full if not any(a < line < b for a, b in blocks)}
        return [tuple(sorted(bounds))]

    def _part(self, region: Region, axis: Axis, a: int, b: int) -> Region:
        r0, r1, c0, c1 = region
        return (r0, r1, a, b) if axis == "x" else (a, b, c0, c1)

    def _action(
        self, region: Region, axis: Axis, bounds: tuple[int, ...], cost_of_line: dict[int, float]
    ) -> Action | None:
        parts = [self._part(region, axis, a, b) for a, b in itertools.pairwise(bounds)]
        n = len(parts)
        if n < 2:
            return None
        cids = [self.grid.content(p) for p in parts]
        op: Op = "split"
        written, count, centre = parts, 1, False
        period = next(
            (
                p
                for p in range(1, n // 2 + 1)
                if n % p == 0 and all(cids[i] == cids[i % p] for i in range(n))
            ),
            None,
        )
        if period is not None:
            op, written, count = "repeat", parts[:period], n // period
        elif (
            "repeatABA" in self.extensions
            and n >= 5
            and n % 2 == 1
            and len(set(cids[0::2])) == 1
            and len(set(cids[1::2])) == 1
        ):
            op, written, count = "repeatABA", parts[:2], n // 2
        elif "symsplit" in self.extensions and n >= 3 and cids == cids[::-1]:
            op, written, centre = "symsplit", parts[: (n + 1) // 2], n % 2 == 1
        rule_cost = (
            self.costs.repeat if op in ("repeat", "repeatABA") else self.costs.split
        ) + len(written)
        heuristic = rule_cost + sum(cost_of_line.get(line, 0.0) for line in bounds[1:-1])
        sizes = tuple(self._quantum(axis, p) for p in written)
        kept = cids[: len(written)]
        return Action(
            op,
            axis,
            bounds,
            tuple(written),
            tuple(kept),
            self._needs(written, kept),
            rule_cost,
            heuristic,
            count,
            centre,
            form=(op, axis, count, centre, sizes),
        )

    def _quantum(self, axis: Axis, part: Region) -> int:
        """A part's size along an axis in steps of the grid's size quantum."""
        a, b = (part[2], part[3]) if axis == "x" else (part[0], part[1])
        step = self.grid.quantum_x if axis == "x" else self.grid.quantum_y
        return round(self.grid.size(axis, a, b) / step)

    def _needs(self, written: Sequence[Region], cids: Sequence[int]) -> tuple[int, ...]:
        """The non-terminal contents among the parts, once each, larger parts first."""
        terminal = self.grid.terminal
        pairs = sorted(zip(written, cids, strict=True), key=lambda pc: -_cells(pc[0]))
        return tuple(dict.fromkeys(c for _, c in pairs if c not in terminal))

    def _gridsplit(self, region: Region, usable: dict[Axis, list[int]]) -> Action | None:
        r0, r1, c0, c1 = region
        rows = (r0, *usable["y"], r1)
        columns = (c0, *usable["x"], c1)
        cells = [
            (a, b, c, d)
            for a, b in itertools.pairwise(rows)
            for c, d in itertools.pairwise(columns)
        ]
        cids = [self.grid.content(cell) for cell in cells]
        cost = self.costs.split + len(cells)
        cost_x, cost_y = self._line_costs(region, "x"), self._line_costs(region, "y")
        heuristic = cost + sum(cost_x.get(v, 0.0) for v in columns[1:-1])
        heuristic += sum(cost_y.get(v, 0.0) for v in rows[1:-1])
        form = (
            "gridsplit",
            tuple(self._quantum("y", (a, b, c0, c1)) for a, b in itertools.pairwise(rows)),
            tuple(self._quantum("x", (r0, r1, a, b)) for a, b in itertools.pairwise(columns)),
        )
        return Action(
            "gridsplit",
            "y",
            rows,
            tuple(cells),
            tuple(cids),
            self._needs(cells, cids),
            cost,
            heuristic,
            across=columns,
            form=form,
        )

    # -- building grammars ---------------------------------------------------------------

    def build(
        self, choose: Callable[[Region, int, dict[int, Action], set[int]], Action]
    ) -> dict[int, Action]:
        """One grammar: regions bottom to top, left to right, each content split once."""
        grid = self.grid
        terminal = grid.terminal
        rules: dict[int, Action] = {}
        start = grid.content(self.whole)
        if start in grid.terminal:
            return rules
        pending = {start}
        r0, r1, c0, c1 = self.whole
        heap = [(r0, c0, -r1, -c1, start)]
        while heap:
            r0, c0, neg_r1, neg_c1, cid = heapq.heappop(heap)
            region = (r0, -neg_r1, c0, -neg_c1)
            pending.discard(cid)
            action = choose(region, cid, rules, pending)
            rules[cid] = action
            for part, sub in zip(action.written, action.cids, strict=True):
                if sub in terminal or sub in rules or sub in pending:
                    continue
                pending.add(sub)
                heapq.heappush(heap, (part[0], part[2], -part[1], -part[3], sub))
        return rules

    def canonical(self, rules: dict[int, Action]) -> dict[int, int]:
        """Each content's rule, merged with every other rule that reads the same (the same
        operation and sizes over the same symbols): regions of different sizes across the
        split axis can share a rule. Maps content -> the content whose rule stands for it."""
        grid = self.grid
        same: dict[int, int] = {}
        seen: dict[tuple[object, ...], int] = {}

        terminal = grid.terminal

        def visit(cid: int) -> object:
            found = same.get(cid)
            if found is None:
                action = rules[cid]
                symbols = tuple(
                    terminal[sub] if sub in terminal else visit(sub) for sub in action.cids
                )
                found = same[cid] = seen.setdefault((action.form, symbols), cid)
            return found

        for cid in rules:
            visit(cid)
        return same

    def cost(self, rules: dict[int, Action]) -> float:
        """Eq. 1 over the merged rules."""
        same = self.canonical(rules)
        return sum(rules[cid].cost for cid in rules if same[cid] == cid)

    def greedy(self) -> dict[int, Action]:
        """The greedy baseline's rules (built once: ADP starts from them too)."""
        if self._greedy is None:

            def best(
                region: Region, cid: int, rules: dict[int, Action], pending: set[int]
            ) -> Action:
                self.deadline.check("building the greedy grammar")
                return self.actions(region)[0]

            self._greedy = self.build(best)
        return self._greedy

    def adp(self, iterations: int, seed: int) -> tuple[dict[int, Action], int, int]:
        """The cheapest grammar of ``iterations`` (see the module), the iteration it was
        found in (0 is the greedy one), and the iterations done: fewer when the deadline's
        soft limit passes first."""
        rng = random.Random(seed)
        values: dict[int, float] = {}
        below: dict[int, frozenset[int]] = {}  # content -> the contents its best rules split
        optimistic = min(self.costs.split + 2, self.costs.repeat + 1)
        best = self.greedy()
        best_cost, best_at = self.cost(best), 0
        self._learn(best, values, below)
        epsilon = 1.0

        odds: dict[Region, list[float]] = {}  # cumulative exp(-H) of a region's actions
        get_value, get_below, draw = values.get, below.get, rng.random

        def choose(region: Region, cid: int, rules: dict[int, Action], pending: set[int]) -> Action:
            if self.deadline.passed():
                raise _TimeUp
            actions = self.actions(region)
            if len(actions) == 1:
                return actions[0]
            if draw() < epsilon:  # exploration: the heuristic's odds
                weights = odds.get(region)
                if weights is None:
                    low = actions[0].heuristic
                    weights = list(
                        itertools.accumulate(math.exp(low - a.heuristic) for a in actions)
                    )
                    odds[region] = weights
                return rng.choices(actions, cum_weights=weights)[0]
            chosen, least = actions[0], math.inf
            for action in actions:  # exploitation: Eq. 4 with the value table
                score, covered = action.cost, EMPTY
                for need in action.needs:  # larger parts first: theirs hold the smaller
                    if score >= least:
                        break  # values only add up
                    if need in rules or need in pending or need in covered:
                        continue
                    score += get_value(need, optimistic)
                    held = get_below(need)
                    if held:
                        covered = covered | held
                if score < least:
                    chosen, least = action, score
            return chosen

        seen: set[tuple[tuple[int, int], ...]] = set()  # grammars built already: nothing new
        done = iterations
        for t in range(1, iterations):
            epsilon = 1.0 - t / iterations
            try:
                rules = self.build(choose)
            except _TimeUp:
                done = t
                break
            signature = tuple((cid, id(action)) for cid, action in rules.items())
            if signature in seen:
                continue
            seen.add(signature)
            cost = self.cost(rules)
            self._learn(rules, values, below)
            if cost < best_cost - 1e-9:
                best, best_cost, best_at = rules, cost, t
        return best, best_at, done

    def _learn(
        self,
        rules: dict[int, Action],
        values: dict[int, float],
        below: dict[int, frozenset[int]],
    ) -> None:
        """Each content's cost to describe, with the rules below it counted once each, kept
        in the value table when it is the least yet, with the contents it took."""
        order = list(rules)
        position = {cid: i for i, cid in enumerate(order)}
        by_cost: dict[float, int] = {}  # rule cost -> the rules with it, as bits
        for i, cid in enumerate(order):
            cost = rules[cid].cost
            by_cost[cost] = by_cost.get(cost, 0) | 1 << i
        reach: dict[int, int] = {}

        def within(cid: int) -> int:
            found = reach.get(cid)
            if found is None:
                found = 1 << position[cid]
                for need in rules[cid].needs:
                    if need in rules:
                        found |= within(need)
                reach[cid] = found
            return found

        for cid in order:
            bits = within(cid)
            total = sum(cost * (bits & mask).bit_count() for cost, mask in by_cost.items())
            if total < values.get(cid, math.inf) - 1e-12:
                values[cid] = total
                contents = []
                while bits:
                    low = bits & -bits
                    contents.append(order[low.bit_length() - 1])
                    bits ^= low
                below[cid] = frozenset(contents)

    # -- the grammar ---------------------------------------------------------------------

    def grammar(self, rules: dict[int, Action]) -> Grammar:
        grid = self.grid
        names: dict[int, str] = {}
        start = grid.content(self.whole)
        grammar = Grammar(start="", costs=self.costs)
        same = self.canonical(rules)

        def name(cid: int) -> str:
            if cid in grid.terminal:
                grammar.terminals.add(grid.terminal[cid])
                return grid.terminal[cid]
            cid = same[cid]
            if cid not in names:
                names[cid] = f"N{len(names) + 1}"
            return names[cid]

        grammar.start = name(start)
        order = [start]
        seen = {start}
        while order:  # breadth first from the start, so names read top down
            cid = order.pop(0)
            if cid not in rules:
                continue
            action = rules[same[cid]]
            grammar.rules[name(cid)] = self._rule(action, name)
            for part in action.written:
                sub = same.get(grid.content(part), grid.content(part))
                if sub not in seen:
                    seen.add(sub)
                    order.append(sub)
        return grammar

    def _rule(self, action: Action, name: Callable[[int], str]) -> Rule:
        grid = self.grid
        if action.op == "gridsplit":
            heights = [grid.size("y", a, b) for a, b in itertools.pairwise(action.bounds)]
            widths = tuple(grid.size("x", a, b) for a, b in itertools.pairwise(action.across))
            columns = len(widths)
            cells = tuple(
                Part(heights[i // columns], name(grid.content(cell)))
                for i, cell in enumerate(action.written)
            )
            return Rule("gridsplit", "y", cells, across=widths)
        parts = []
        for part in action.written:
            a, b = (part[2], part[3]) if action.axis == "x" else (part[0], part[1])
            parts.append(Part(grid.size(action.axis, a, b), name(grid.content(part))))
        return Rule(action.op, action.axis, tuple(parts), action.count, action.centre)


class _TimeUp(Exception):
    """The soft time limit passed during an ADP iteration: the iteration is dropped."""


def _cells(region: Region) -> int:
    return (region[1] - region[0]) * (region[3] - region[2])


def extract(
    tiling: Tiling,
    method: str = "adp",
    iterations: int = 2000,
    seed: int = 0,
    costs: Costs = DEFAULT_COSTS,
    extensions: tuple[str, ...] = (),
    background: str = BACKGROUND,
    *,
    time_limit: float = math.inf,
    deadline: Deadline | None = None,
) -> SearchResult:
    """A split grammar for the tiling, by ``greedy`` or ``adp`` (see the module), within
    the run's deadline (else one of ``time_limit`` seconds from now)."""
    deadline = deadline or Deadline(time_limit)
    search = Search(tiling, costs, extensions, background, deadline)
    greedy = search.greedy()
    greedy_cost = search.cost(greedy)
    if method == "greedy" or iterations <= 1:
        rules, best_at, done = greedy, 0, 1
    else:
        rules, best_at, done = search.adp(iterations, seed)
    return SearchResult(
        search.grammar(rules),
        method,
        done,
        best_at,
        greedy_cost,
        search.regions_explored,
        search.repeats.kinds,
        search.repeats.complete,
    )


def greedy_grammar(tiling: Tiling, background: str = BACKGROUND) -> Grammar:
    """The greedy baseline's grammar."""
    return extract(tiling, "greedy", background=background).grammar
