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

The search runs compiled (``_adp.c``) where the install built it (:mod:`facadecli.native`):
the actions of each region it visits, building grammars from them, their merged cost and the
value table. It computes what the Python here (``_make_actions`` and what it calls) and the
plain loop of :mod:`facadecli.grammar.plain` compute, to the bit (the tests compare them),
some 20 times faster. Python then makes again the ``Action``s of the rules chosen, from their
regions and cuts, for the grammar. Without ``_adp`` the plain loop runs instead.

The run's ``Deadline`` bounds the work: the greedy grammar checks its hard limit at every
region (exit 4 when it passes), ADP stops at the soft limit, even within an iteration.
"""

from __future__ import annotations

import bisect
import itertools
import math
import random
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from facadecli.errors import SpecError
from facadecli.grammar import plain, regions
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.regions import BUDGET_ERRORS, Grid, Region
from facadecli.grammar.split import DEFAULT_COSTS, Axis, Costs, Grammar, Op, Part, Rule, inlined
from facadecli.grammar.symmetry import Repeats, find_repeats
from facadecli.grammar.tiling import BACKGROUND, Tiling
from facadecli.limits import GRAMMAR_DEPTH_MAX
from facadecli.native import GRAMMAR_COMPILED, _adp

DEPTH_MAX = GRAMMAR_DEPTH_MAX  # rules nested in a grammar
GRID_CELLS = 48  # a gridsplit of more cells than this costs more than it can save
TOP_ACTIONS = 8  # actions per region the search chooses among (the heuristic's best)


Entry = tuple[int, int, int, int, int]  # a region to split and its content (``_entry``)
Rank = tuple[float, float, Axis, tuple[int, ...]]  # heuristic, cost, axis, bounds: least first


@dataclass(slots=True)  # not frozen, which makes them slower to make; never changed
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
    form_number: int = -1  # equal for equal forms (``Search._forms``)
    entries: tuple[Entry, ...] = ()  # the non-terminal written parts, to split next


@dataclass
class SearchResult:
    grammar: Grammar
    method: str
    iterations: int
    best_iteration: int
    greedy_cost: float
    regions: int  # distinct regions given actions
    repeats: int  # repeated regions found by hashing (kinds)
    repeats_stopped: str = ""  # what stopped their search early: "", "time" or "work"
    budget_spent: bool = False  # True when ``WORK_MAX`` stopped ADP


class Search:
    def __init__(
        self,
        tiling: Tiling,
        costs: Costs = DEFAULT_COSTS,
        extensions: tuple[str, ...] = (),
        background: str = BACKGROUND,
        deadline: Deadline | None = None,
        compiled: bool | None = None,
    ):
        """``compiled``: search with ``_adp.c`` (the default where it was built,
        :mod:`facadecli.native`) or with the plain loop (:mod:`facadecli.grammar.plain`)."""
        self.deadline = deadline or Deadline()
        self.compiled = GRAMMAR_COMPILED if compiled is None else compiled
        self.grid = Grid(tiling, background, self.compiled)
        self.costs = costs
        self.extensions = set(extensions)
        self.repeats: Repeats = find_repeats(self.grid, deadline=self.deadline)
        rep = self.repeats  # their occurrences as rows r0, r1, c0, c1, cells, by first row
        self._repeat_rows = np.stack([rep.r0, rep.r1, rep.c0, rep.c1, rep.cells], axis=1)
        self._repeat_first = rep.r0.tolist()
        self._actions: dict[Region, list[Action]] = {}
        self._greedy: dict[int, Action] | None = None
        self._forms: dict[tuple[object, ...], int] = {}
        self._actions_at: dict[Entry, list[Action]] = {}
        self._quanta: dict[tuple[str, int, int], int] = {}  # (axis, start, stop) -> size
        self.whole: Region = (0, self.grid.rows, 0, self.grid.columns)
        self._table = self._compiled() if self.compiled else None
        self._greedy_numbers: list[int] = []  # the greedy rules' actions in the table

    @property
    def regions_explored(self) -> int:
        """Regions that were offered actions."""
        return len(self._actions) if self._table is None else self._table.explored()

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
        halves: dict[tuple[object, ...], Rank] = {}  # cuts in two, ranked before they are made
        inside = self._repeats_inside(region)
        line_costs: dict[Axis, dict[int, float]] = {
            "x": self._line_costs(region, "x", inside),
            "y": self._line_costs(region, "y", inside),
        }
        for axis, lines in usable.items():
            lo, hi = (c0, c1) if axis == "x" else (r0, r1)
            cost_of_line = line_costs[axis]
            full = (lo, *lines, hi)
            options = [full, *self._runs(region, axis, full)]
            options += self._repeated(region, axis, full, inside)
            for bounds in options:
                action = self._action(region, axis, bounds, cost_of_line)
                if action is not None:
                    found.setdefault((action.axis, action.bounds), action)
            # cuts in two: only the lines the heuristic likes best are worth making rules of
            cheapest = sorted(lines, key=lambda ln: (cost_of_line.get(ln, 0.0), ln))
            for line in cheapest[:TOP_ACTIONS] if len(lines) > 1 else ():
                bounds = (lo, line, hi)
                if (axis, bounds) not in found:
                    halves[(axis, bounds)] = self._rank_in_two(region, axis, bounds, cost_of_line)
        if (
            "gridsplit" in self.extensions
            and "x" in usable
            and "y" in usable
            and (len(usable["x"]) + 1) * (len(usable["y"]) + 1) <= GRID_CELLS
        ):
            grid = self._gridsplit(region, usable["x"], usable["y"], line_costs)
            found[("xy", grid.bounds, grid.across)] = grid

        def rank(a: Action) -> Rank:
            return (a.heuristic, a.cost, a.axis, a.bounds)

        # every structural cut, and the heuristic's best cuts in two to fill up the choice
        kept = sorted(found.values(), key=rank)[:TOP_ACTIONS]
        best_halves = sorted(halves.values())[: max(TOP_ACTIONS - len(kept), TOP_ACTIONS // 2)]
        for _, _, axis, bounds in best_halves:
            action = self._action(region, axis, bounds, line_costs[axis])
            assert action is not None  # two parts
            kept.append(action)
        return sorted(kept, key=rank)

    def _rank_in_two(
        self, region: Region, axis: Axis, bounds: tuple[int, ...], cost_of_line: dict[int, float]
    ) -> Rank:
        """The rank ``_action`` would give the cut in two, without making the action: it is
        a repeat of one part when both parts read the same, else a split of two."""
        a, line, b = bounds
        first, second = self._part(region, axis, a, line), self._part(region, axis, line, b)
        same = self._may_read_same(axis, first, second, b - a) and (
            self.grid.content(first) == self.grid.content(second)
        )
        rule_cost = self.costs.repeat + 1 if same else self.costs.split + 2
        return (_heuristic(rule_cost, bounds, cost_of_line), rule_cost, axis, bounds)

    def _repeats_inside(self, region: Region) -> np.ndarray:
        """The occurrences of repeated regions inside the region: rows r0, r1, c0, c1, cells
        (in the order of ``Repeats``)."""
        r0, r1, c0, c1 = region
        first = self._repeat_first
        rows = self._repeat_rows[bisect.bisect_left(first, r0) : bisect.bisect_left(first, r1)]
        return rows[(rows[:, 1] <= r1) & (rows[:, 2] >= c0) & (rows[:, 3] <= c1)]

    def _line_costs(
        self, region: Region, axis: Axis, inside: np.ndarray | None = None
    ) -> dict[int, float]:
        """The heuristic's cost of each line of an axis inside the region (section 4.4);
        ``inside`` is ``_repeats_inside(region)`` when known."""
        r0, r1, c0, c1 = region
        if inside is None:
            inside = self._repeats_inside(region)
        lo, hi = (c0, c1) if axis == "x" else (r0, r1)
        if len(inside) == 0 or hi - lo < 2:
            return {}
        lines = np.arange(lo + 1, hi)
        start = inside[:, 2] if axis == "x" else inside[:, 0]
        stop = inside[:, 3] if axis == "x" else inside[:, 1]
        weights = inside[:, 4].astype(float)
        # a repeat's cells count for the lines strictly inside its span: summed as
        # differences (+ after its start, - at its end), linear in repeats plus lines
        size = hi - lo + 1
        steps = np.bincount(start + 1 - lo, weights, size) - np.bincount(stop - lo, weights, size)
        cells = (r1 - r0) * (c1 - c0)
        costs = np.cumsum(steps)[1 : hi - lo] / cells
        return {int(line): float(c) for line, c in zip(lines, costs, strict=True) if c > 0}

    def _runs(self, region: Region, axis: Axis, full: tuple[int, ...]) -> list[tuple[int, ...]]:
        """Bounds that keep each maximal periodic run of two or more parts as one part."""
        cids = self.grid.contents_of(
            [self._part(region, axis, a, b) for a, b in itertools.pairwise(full)]
        )
        n = len(cids)
        out = []
        for period in range(1, n // 2 + 1):
            # run[j]: how many parts from j on equal the part a period after them, so the
            # parts from i on hold 1 + run[i] // period copies of the first period
            run = [0] * (n - period + 1)
            for j in range(n - period - 1, -1, -1):
                if cids[j] == cids[j + period]:
                    run[j] = run[j + 1] + 1
            i = 0
            while i + 2 * period <= n:
                k = 1 + run[i] // period
                if k >= 2 and not (i == 0 and i + k * period == n):
                    end = i + k * period
                    out.append((*full[: i + 1], *full[end:]))
                    i = end
                else:
                    i += 1
        return out

    def _repeated(
        self, region: Region, axis: Axis, full: tuple[int, ...], inside: np.ndarray
    ) -> list[tuple[int, ...]]:
        """Bounds that keep whole the repeated regions spanning the region across the axis
        (``inside``: the repeated regions inside the region, ``_repeats_inside``)."""
        r0, r1, c0, c1 = region
        if axis == "x":
            spans = inside[(inside[:, 0] == r0) & (inside[:, 1] == r1)]
            start, stop = spans[:, 2], spans[:, 3]
        else:
            spans = inside[(inside[:, 2] == c0) & (inside[:, 3] == c1)]
            start, stop = spans[:, 0], spans[:, 1]
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
        n = len(bounds) - 1
        if n < 2:
            return None
        r0, r1, c0, c1 = region
        if axis == "x":
            parts = [(r0, r1, a, b) for a, b in itertools.pairwise(bounds)]
        else:
            parts = [(a, b, c0, c1) for a, b in itertools.pairwise(bounds)]
        cids = self.grid.contents_of(parts)
        op: Op = "split"
        written, count, centre = parts, 1, False
        # the least period p of the contents: the parts are n / p copies of the first p
        period = next((p for p in range(1, n // 2 + 1) if not n % p and cids[p:] == cids[:-p]), 0)
        if period:
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
        m = len(written)
        rule_cost = (self.costs.repeat if op in ("repeat", "repeatABA") else self.costs.split) + m
        heuristic = _heuristic(rule_cost, bounds, cost_of_line)
        quantum = self._quantum
        sizes = tuple(quantum(axis, p) for p in written)
        kept = cids[:m]
        form = (op, axis, count, centre, sizes)
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
            form=form,
            form_number=self._forms.setdefault(form, len(self._forms)),
            entries=self._entries(written, kept),
        )

    def _may_read_same(self, axis: Axis, first: Region, second: Region, cells: int) -> bool:
        """False when two parts of ``cells`` rows or columns along the axis together cannot
        have the same content (``Grid.content``) because their sizes differ: a content's
        size along the axis is a sum of at most ``cells`` rounded steps, each off by at
        most half a step (so the test needs no content, which takes time)."""
        return abs(self._quantum(axis, first) - self._quantum(axis, second)) <= cells + 2

    def _quantum(self, axis: Axis, part: Region) -> int:
        """A part's size along an axis in steps of the grid's size quantum."""
        a, b = (part[2], part[3]) if axis == "x" else (part[0], part[1])
        key = (axis, a, b)
        found = self._quanta.get(key)
        if found is None:
            step = self.grid.quantum_x if axis == "x" else self.grid.quantum_y
            found = self._quanta[key] = round(self.grid.size(axis, a, b) / step)
        return found

    def _needs(self, written: Sequence[Region], cids: Sequence[int]) -> tuple[int, ...]:
        """The non-terminal contents among the parts, once each, larger parts first."""
        terminal = self.grid.terminal
        inner = [(-_cells(part), i) for i, part in enumerate(written) if cids[i] not in terminal]
        if len(inner) < 2:
            return tuple(cids[i] for _, i in inner)
        inner.sort()  # by size, ties in order
        return tuple(dict.fromkeys(cids[i] for _, i in inner))

    def _entries(self, written: Sequence[Region], cids: Sequence[int]) -> tuple[Entry, ...]:
        """The written parts that are not terminals, in order, as heap entries
        (``_entry``)."""
        terminal = self.grid.terminal
        return tuple(
            (part[0], part[2], -part[1], -part[3], cid)
            for part, cid in zip(written, cids, strict=True)
            if cid not in terminal
        )

    def _gridsplit(
        self,
        region: Region,
        x_lines: Sequence[int],
        y_lines: Sequence[int],
        line_costs: dict[Axis, dict[int, float]],
    ) -> Action:
        r0, r1, c0, c1 = region
        rows = (r0, *y_lines, r1)
        columns = (c0, *x_lines, c1)
        cells = [
            (a, b, c, d)
            for a, b in itertools.pairwise(rows)
            for c, d in itertools.pairwise(columns)
        ]
        cids = [self.grid.content(cell) for cell in cells]
        cost = self.costs.split + len(cells)
        cost_x, cost_y = line_costs["x"], line_costs["y"]
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
            form_number=self._forms.setdefault(form, len(self._forms)),
            entries=self._entries(cells, cids),
        )

    # -- building grammars ---------------------------------------------------------------

    def _compiled(self) -> _adp.Table:
        """The compiled search over this tiling (``_adp.c``): the grid's table, readied with
        the repeated regions, the extensions and the costs."""
        extensions = {"repeatABA": 1, "symsplit": 2, "gridsplit": 4}
        table = self.grid.table
        assert table is not None, "a grid of the compiled search"
        table.prepare(
            self._repeat_rows.astype(np.int32).tobytes(),
            sum(bit for name, bit in extensions.items() if name in self.extensions),
            self.costs.split,
            self.costs.repeat,
        )
        return table

    def _rules(self, pairs: list[tuple[int, int]]) -> dict[int, Action]:
        """A grammar from the compiled search, its rules in the order chosen, each action
        made again here from its region and cuts."""
        assert self._table is not None, "the compiled search"
        rules: dict[int, Action] = {}
        for _, number in pairs:
            region, axis, bounds, across, heuristic = self._table.action(number)
            if across:
                action = self._gridsplit(region, across[1:-1], bounds[1:-1], {"x": {}, "y": {}})
            else:
                made = self._action(region, axis, bounds, {})
                assert made is not None  # two parts or more
                action = made
            action.heuristic = heuristic  # the line costs it needs are the compiled search's
            rules[self.grid.content(region)] = action
        return rules

    def _action_ids(self, rules: dict[int, Action]) -> list[int]:
        """The table's numbers of a grammar's actions, by their places in their regions'
        actions (equal lists, in one order)."""
        assert self._table is not None, "the compiled search"
        numbers = []
        for action in rules.values():
            region = _region_of(action)
            index = self.actions(region).index(action)
            numbers.append(self._table.action_id(self._table.entry(*region), index))
        return numbers

    def _start(self) -> int | None:
        """The whole façade's entry, None when it is one terminal."""
        if self.grid.content(self.whole) in self.grid.terminal:
            return None
        return 0 if self._table is None else self._table.entry(*self.whole)

    def actions_at(self, entry: Entry) -> list[Action]:
        """The actions of a heap entry's region."""
        found = self._actions_at.get(entry)
        if found is None:
            found = self._actions_at[entry] = self.actions(_region(entry))
        return found

    def canonical(self, rules: dict[int, Action]) -> dict[int, int]:
        """Each content's rule, merged with every other rule that reads the same (the same
        operation and sizes over the same symbols): regions of different sizes across the
        split axis can share a rule. Maps content -> the content whose rule stands for it."""
        same: dict[int, int] = {}
        seen: dict[tuple[object, ...], int] = {}
        terminal = self.grid.terminal
        for cid in rules:  # depth first, children before parents, with a stack of our own
            stack = [cid]
            while stack:
                top = stack[-1]
                if top in same:
                    stack.pop()
                    continue
                action = rules[top]
                waiting = [sub for sub in action.cids if sub not in terminal and sub not in same]
                if waiting:  # the leftmost on top: the order a recursive visit takes
                    stack.extend(reversed(waiting))
                    continue
                symbols = tuple(
                    terminal[sub] if sub in terminal else same[sub] for sub in action.cids
                )
                same[top] = seen.setdefault((action.form, symbols), top)
                stack.pop()
        return same

    def depth(self, rules: dict[int, Action]) -> int:
        """The most rules on one path from the start to a terminal."""
        terminal = self.grid.terminal
        height: dict[int, int] = {}
        for cid in rules:
            stack = [cid]
            while stack:
                top = stack[-1]
                if top in height:
                    stack.pop()
                    continue
                subs = [sub for sub in rules[top].cids if sub not in terminal and sub in rules]
                waiting = [sub for sub in subs if sub not in height]
                if waiting:
                    stack.extend(waiting)
                    continue
                height[top] = 1 + max((height[sub] for sub in subs), default=0)
                stack.pop()
        return max(height.values(), default=0)

    def cost(self, rules: dict[int, Action]) -> float:
        """Eq. 1 over the merged rules."""
        return self.survey(rules)[0]

    def survey(self, rules: dict[int, Action]) -> tuple[float, list[list[int]]]:
        """Eq. 1 over the merged rules, and for each rule (in order) the positions of the
        rules it reaches, itself included. Rules merge as in ``canonical``; a merged rule's
        cost counts once, for the rule met first with it (the same sum, to the bit, as over
        ``canonical``'s map)."""
        if not rules:
            return 0.0, []
        if self._table is None:
            cost, reach = plain.survey(self, rules)
            return cost, [sorted(reached) for reached in reach]
        return self._table.survey(self._action_ids(rules))

    def greedy(self) -> dict[int, Action]:
        """The greedy baseline's rules: every region takes its first action (built once:
        ADP starts from them too)."""
        if self._greedy is None:
            start = self._start()
            if start is None:
                self._greedy = {}
            else:
                deadline = self.deadline
                hard = deadline.start + deadline.hard
                if self._table is None:
                    rules = plain.greedy(self, hard)
                    pairs = None
                else:
                    pairs = self._table.greedy(start, _monotonic(hard))
                    rules = None if pairs is None else self._rules(pairs)
                if rules is None:
                    deadline.check("building the greedy grammar")
                    raise AssertionError("the hard time limit passed")  # check() raised
                self._greedy = rules
                self._greedy_numbers = [number for _, number in pairs or ()]
        return self._greedy

    def adp(self, iterations: int, seed: int) -> tuple[dict[int, Action], int, int]:
        """The cheapest grammar of ``iterations`` (see the module), the iteration it was
        found in (0 is the greedy one), and the iterations done: fewer when the deadline's
        soft limit passes first. The loop runs in ``_adp`` (compiled) or in
        :mod:`facadecli.grammar.plain`; its draws are ``random.Random(seed)``'s."""
        greedy = self.greedy()
        start = self._start()
        if start is None or iterations < 2:
            return greedy, 0, max(iterations, 1)
        if self._table is None:
            stop_at = self.deadline.start + self.deadline.seconds
            return plain.adp(self, iterations, seed, greedy, stop_at)
        optimistic = min(self.costs.split + 2, self.costs.repeat + 1)
        state = random.Random(seed).getstate()[1]
        stop = _monotonic(self.deadline.start + self.deadline.seconds)
        pairs, best_at, done = self._table.adp(
            start, self._greedy_numbers, iterations, state, optimistic, stop
        )
        return self._rules(pairs), best_at, done

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


def _monotonic(at: float) -> float:
    """A ``time.perf_counter()`` instant as the table's clock reads it (the same clock on
    Linux; elsewhere the offset is measured)."""
    if math.isinf(at):
        return at
    return at - time.perf_counter() + time.monotonic()


def _heuristic(rule_cost: float, bounds: tuple[int, ...], cost_of_line: dict[int, float]) -> float:
    """Eq. 5: the rule's cost plus the cost of each line it cuts."""
    return rule_cost + sum(cost_of_line.get(line, 0.0) for line in bounds[1:-1])


def _region_of(action: Action) -> Region:
    """The region an action splits."""
    first = action.written[0]
    if action.op == "gridsplit":
        return (action.bounds[0], action.bounds[-1], action.across[0], action.across[-1])
    if action.axis == "x":
        return (first[0], first[1], action.bounds[0], action.bounds[-1])
    return (action.bounds[0], action.bounds[-1], first[2], first[3])


def _entry(region: Region, cid: int) -> Entry:
    """A region to split as a heap entry: the heap gives regions bottom to top, then left to
    right, then the larger first."""
    r0, r1, c0, c1 = region
    return (r0, c0, -r1, -c1, cid)


def _region(entry: Entry) -> Region:
    r0, c0, neg_r1, neg_c1, _ = entry
    return (r0, -neg_r1, c0, -neg_c1)


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
    try:
        search = Search(tiling, costs, extensions, background, deadline)
        greedy_rules = search.greedy()
        _check_depth(search, greedy_rules, deadline.source)
        greedy = inlined(search.grammar(greedy_rules))
    except BUDGET_ERRORS:
        raise SpecError.at(
            deadline.source,
            None,
            None,
            f"the grammar search would do more than {regions.WORK_MAX:,} units of work before "
            "its first grammar (the limit of work a grammar search does): the layout's regions "
            "all differ, e.g. elements on a slant",
            "join nearby edges with a larger --snap, or give fewer rectangles",
        ) from None
    grammar, best_at, done = greedy, 0, 1
    if method != "greedy" and iterations > 1:
        rules, best_at, done = search.adp(iterations, seed)
        _check_depth(search, rules, deadline.source)
        grammar = inlined(search.grammar(rules))
        if greedy.cost < grammar.cost - 1e-9:  # inlining can favour the greedy grammar
            grammar, best_at = greedy, 0
    return SearchResult(
        grammar,
        method,
        done,
        best_at,
        greedy.cost,
        search.regions_explored,
        search.repeats.kinds,
        search.repeats.stopped,
        search.grid.spent,
    )


def _check_depth(search: Search, rules: dict[int, Action], source: str) -> None:
    """A grammar nests at most ``DEPTH_MAX`` rules (deriving it, writing it out and
    varying it go down the rules one level at a time)."""
    depth = search.depth(rules)
    if depth > DEPTH_MAX:
        raise SpecError.at(
            source,
            None,
            None,
            f"the grammar found nests {depth:,} rules deep, more than the limit of rules "
            f"nested in a grammar ({DEPTH_MAX})",
            "join nearby edges with a larger --snap, or give fewer rectangles",
        )


def greedy_grammar(tiling: Tiling, background: str = BACKGROUND) -> Grammar:
    """The greedy baseline's grammar."""
    return extract(tiling, "greedy", background=background).grammar
