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

The search's inner loop is :mod:`facadecli.grammar.adp`, compiled by Cython where the install
had a C compiler and interpreted where it had none (:mod:`facadecli.native`), with the same
grammars: the contents of regions, the actions of each region it visits, building grammars
from them, their merged cost and the value table. Python then makes the ``Action``s of the
rules chosen, for the grammar.

The run's ``Deadline`` (CPU seconds) bounds the work: the greedy grammar checks its hard
limit as it goes (exit 4 when it passes), ADP stops at the soft limit, even within an
iteration.
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from facadecli.errors import SpecError
from facadecli.grammar import regions
from facadecli.grammar.deadline import Deadline, clock
from facadecli.grammar.regions import BUDGET_ERRORS, Grid, Region
from facadecli.grammar.split import DEFAULT_COSTS, Axis, Costs, Grammar, Op, Part, Rule, inlined
from facadecli.grammar.symmetry import Repeats, find_repeats
from facadecli.grammar.tiling import BACKGROUND, Tiling
from facadecli.limits import GRAMMAR_DEPTH_MAX

DEPTH_MAX = GRAMMAR_DEPTH_MAX  # rules nested in a grammar
EXTENSIONS = {"repeatABA": 1, "symsplit": 2, "gridsplit": 4}  # as bits, for the table


@dataclass(slots=True, frozen=True)
class Action:
    """A rule the search chose for a region (one of the table's actions)."""

    op: Op
    axis: Axis
    bounds: tuple[int, ...]  # cut indices along the axis, the region's ends included
    written: tuple[Region, ...]  # the parts written in the rule
    cids: tuple[int, ...]  # their contents
    cost: float
    heuristic: float
    count: int = 1
    centre: bool = False
    across: tuple[int, ...] = ()  # gridsplit: the column bounds
    form: int = -1  # the rule without its symbols (op, axis, sizes): equal for equal forms
    number: int = -1  # the table's number of the action


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
    ):
        self.deadline = deadline or Deadline()
        self.grid = Grid(tiling, background)
        self.costs = costs
        self.extensions = set(extensions)
        self.repeats: Repeats = find_repeats(self.grid, deadline=self.deadline)
        rep = self.repeats  # their occurrences as rows r0, r1, c0, c1, cells, by first row
        rows = np.stack([rep.r0, rep.r1, rep.c0, rep.c1, rep.cells], axis=1)
        self.whole: Region = (0, self.grid.rows, 0, self.grid.columns)
        self._table = self.grid.table
        self._table.prepare(
            rows.astype(np.int32).tobytes(),
            sum(bit for name, bit in EXTENSIONS.items() if name in self.extensions),
            self.costs.split,
            self.costs.repeat,
        )
        self._greedy: dict[int, Action] | None = None
        self._greedy_numbers: list[int] = []  # the greedy rules' actions in the table

    @property
    def regions_explored(self) -> int:
        """Regions that were offered actions."""
        return int(self._table.explored())

    def actions(self, region: Region) -> list[Action]:
        """The actions the search offers for a region, best first (Eq. 5's heuristic)."""
        table = self._table
        return [self._made(number) for number in table.actions(table.entry(*region))]

    def _made(self, number: int) -> Action:
        """The table's action ``number`` as an ``Action``: its rule and its parts."""
        region, op, axis, bounds, across, count, centre, cost, heuristic, form = self._table.action(
            number
        )
        r0, r1, c0, c1 = region
        if op == "gridsplit":
            written = [
                (a, b, c, d)
                for a, b in itertools.pairwise(bounds)
                for c, d in itertools.pairwise(across)
            ]
        else:
            parts = len(bounds) - 1
            kept = {"repeat": parts // count, "repeatABA": 2, "symsplit": (parts + 1) // 2}
            spans = list(itertools.pairwise(bounds))[: kept.get(op, parts)]
            if axis == "x":
                written = [(r0, r1, a, b) for a, b in spans]
            else:
                written = [(a, b, c0, c1) for a, b in spans]
        return Action(
            op,
            axis,
            bounds,
            tuple(written),
            tuple(self.grid.contents_of(written)),
            cost,
            heuristic,
            count,
            centre,
            across,
            form,
            number,
        )

    # -- building grammars ---------------------------------------------------------------

    def _rules(self, pairs: list[tuple[int, int]]) -> dict[int, Action]:
        """A grammar from the table's search, its rules in the order chosen."""
        return {cid: self._made(number) for cid, number in pairs}

    def _start(self) -> int | None:
        """The whole façade's entry, None when it is one terminal."""
        if self.grid.content(self.whole) in self.grid.terminal:
            return None
        return int(self._table.entry(*self.whole))

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
        return self._table.cost([action.number for action in rules.values()])

    def greedy(self) -> dict[int, Action]:
        """The greedy baseline's rules: every region takes its first action (built once:
        ADP starts from them too)."""
        if self._greedy is None:
            start = self._start()
            if start is None:
                self._greedy = {}
            else:
                deadline = self.deadline
                pairs = self._table.greedy(start, deadline.start + deadline.hard, clock)
                if pairs is None:
                    deadline.check("building the greedy grammar")
                    raise AssertionError("the hard time limit passed")  # check() raised
                self._greedy = self._rules(pairs)
                self._greedy_numbers = [number for _, number in pairs]
        return self._greedy

    def adp(self, iterations: int, seed: int) -> tuple[dict[int, Action], int, int]:
        """The cheapest grammar of ``iterations`` (see the module), the iteration it was
        found in (0 is the greedy one), and the iterations done: fewer when the deadline's
        soft limit passes first. Its draws are ``random.Random(seed)``'s."""
        greedy = self.greedy()
        start = self._start()
        if start is None or iterations < 2:
            return greedy, 0, max(iterations, 1)
        optimistic = min(self.costs.split + 2, self.costs.repeat + 1)
        stop = self.deadline.start + self.deadline.seconds
        draw = random.Random(seed).random
        pairs, best_at, done = self._table.adp(
            start, self._greedy_numbers, iterations, draw, optimistic, stop, clock
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
