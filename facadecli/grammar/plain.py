"""The grammar search's inner loop in plain Python: what ``_adp.c`` computes, to the bit.

It runs where the install has no compiled ``_adp`` (:mod:`facadecli.native`), some ten times
slower, and it is the reference the tests compare the compiled loop with
(tests/test_grammar_search_tables.py).

It builds grammars region by region (bottom to top, left to right, each content split
once), greedily or by ADP's choice (explore with probability epsilon by the heuristic's odds,
else exploit the value table, Eq. 4), and values a grammar by Eq. 1 over its merged rules.
Sums are written as loops, in the order the compiled loop adds them. ``stop_at`` is a
``time.perf_counter()`` instant: like the compiled loop, a grammar being built stops before
its next region once it has passed.
"""

from __future__ import annotations

import bisect
import heapq
import itertools
import math
import random
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

from facadecli.grammar.regions import BUDGET_ERRORS

if TYPE_CHECKING:
    from facadecli.grammar.search import Action, Entry, Search

Choose = Callable[["Entry", dict[int, "Action"], set[int]], "Action"]
Learned = dict[int, tuple[float, frozenset[int]]]


def build(search: Search, choose: Choose, stop_at: float = math.inf) -> dict[int, Action] | None:
    """One grammar: regions bottom to top, left to right, each content split once; None
    when the clock passes ``stop_at`` first."""
    grid = search.grid
    rules: dict[int, Action] = {}
    start = grid.content(search.whole)
    if start in grid.terminal:
        return rules
    pending = {start}
    r0, r1, c0, c1 = search.whole
    heap: list[Entry] = [(r0, c0, -r1, -c1, start)]
    timed = not math.isinf(stop_at)
    while heap:
        if timed and time.perf_counter() > stop_at:
            return None
        entry = heapq.heappop(heap)
        cid = entry[4]
        pending.discard(cid)
        action = rules[cid] = choose(entry, rules, pending)
        for part in action.entries:
            if part[4] not in rules and part[4] not in pending:
                pending.add(part[4])
                heapq.heappush(heap, part)
    return rules


def survey(search: Search, rules: dict[int, Action]) -> tuple[float, list[set[int]]]:
    """Eq. 1 over the merged rules (a kind's cost counts for the rule met first with it),
    and per rule the positions of the rules it reaches, itself included."""
    terminal = search.grid.terminal
    position = {cid: i for i, cid in enumerate(rules)}
    kinds: dict[tuple[object, ...], int] = {}
    kind_of: dict[int, int] = {}
    reach: dict[int, set[int]] = {}
    first: dict[int, int] = {}

    def visit(cid: int) -> int:
        if cid not in kind_of:
            action = rules[cid]
            reached = {position[cid]}
            symbols: list[object] = []
            for sub in action.cids:
                if sub in terminal:
                    symbols.append(terminal[sub])
                else:
                    symbols.append(visit(sub))
                    reached |= reach[sub]
            kind = kinds.setdefault((action.form_number, tuple(symbols)), len(kinds))
            kind_of[cid], reach[cid] = kind, reached
            first.setdefault(kind, cid)
        return kind_of[cid]

    for cid in rules:
        visit(cid)
    cost = 0.0
    for cid in rules:
        if first[kind_of[cid]] == cid:
            cost += rules[cid].cost
    return cost, [reach[cid] for cid in rules]


def learn(rules: dict[int, Action], reach: list[set[int]], learned: Learned) -> None:
    """Each content's cost with every rule below it counted once (summed per distinct rule
    cost, in the order met), kept when the least yet, with the contents it took."""
    order = list(rules)
    costs = [rules[cid].cost for cid in order]
    distinct = list(dict.fromkeys(costs))
    for cid, reached in zip(order, reach, strict=True):
        total = 0.0
        for cost in distinct:
            total += cost * sum(costs[p] == cost for p in reached)
        if total < learned.get(cid, (math.inf, frozenset()))[0] - 1e-12:
            learned[cid] = (total, frozenset(order[p] for p in reached))


def greedy(search: Search, stop_at: float = math.inf) -> dict[int, Action] | None:
    """Every region takes its first action; None when the clock passes ``stop_at`` first."""
    return build(search, lambda entry, rules, pending: search.actions_at(entry)[0], stop_at)


def adp(
    search: Search,
    iterations: int,
    seed: int,
    greedy_rules: dict[int, Action] | None = None,
    stop_at: float = math.inf,
) -> tuple[dict[int, Action], int, int]:
    """``Search.adp``: the cheapest grammar of ``iterations``, the iteration it was found in
    and the iterations done (fewer when the clock passes ``stop_at``, even within one).
    ``greedy_rules``: the greedy grammar when it is known."""
    rng = random.Random(seed)
    learned: Learned = {}
    optimistic = min(search.costs.split + 2, search.costs.repeat + 1)
    best = greedy_rules if greedy_rules is not None else greedy(search)
    assert best is not None  # no time limit
    best_cost, reach = survey(search, best)
    learn(best, reach, learned)
    best_at, epsilon = 0, 1.0
    odds: dict[Entry, list[float]] = {}

    def choose(entry: Entry, rules: dict[int, Action], pending: set[int]) -> Action:
        actions = search.actions_at(entry)
        if len(actions) == 1:
            return actions[0]
        if rng.random() < epsilon:
            if entry not in odds:
                low = actions[0].heuristic
                odds[entry] = list(
                    itertools.accumulate(math.exp(low - a.heuristic) for a in actions)
                )
            weights = odds[entry]
            x = rng.random() * (weights[-1] + 0.0)
            return actions[bisect.bisect(weights, x, 0, len(actions) - 1)]
        chosen, least = actions[0], math.inf
        for action in actions:
            score, covered = action.cost, frozenset[int]()
            for need in action.needs:
                if score >= least:
                    break
                if need in rules or need in pending or need in covered:
                    continue
                if need in learned:
                    score += learned[need][0]
                    covered = covered | learned[need][1]
                else:
                    score += optimistic
            if score < least:
                chosen, least = action, score
        return chosen

    seen: set[tuple[int, ...]] = set()
    if not best:
        return best, 0, iterations
    for t in range(1, iterations):
        epsilon = 1.0 - t / iterations
        try:
            rules = build(search, choose, stop_at)
        except BUDGET_ERRORS:  # stops as the time limit does: the best grammar so far
            return best, best_at, t
        if rules is None:
            return best, best_at, t
        signature = tuple(map(id, rules.values()))
        if signature in seen:
            continue
        seen.add(signature)
        cost, reach = survey(search, rules)
        learn(rules, reach, learned)
        if cost < best_cost - 1e-9:
            best, best_cost, best_at = rules, cost, t
    return best, best_at, iterations
