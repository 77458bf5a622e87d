"""The grammar search's inner loop in plain Python: what ``facadecli/grammar/_adp.c`` must
compute, to the bit (tests/test_grammar_search_tables.py compares them).

It builds grammars region by region (bottom to top, left to right, each content split
once), greedily or by ADP's choice (explore with probability epsilon by the heuristic's odds,
else exploit the value table, Eq. 4), and values a grammar by Eq. 1 over its merged rules.
Sums are written as loops, in the order the compiled loop adds them.
"""

from __future__ import annotations

import bisect
import heapq
import itertools
import math
import random
from collections.abc import Callable

from facadecli.grammar.search import Action, Entry, Search, _entry

Choose = Callable[[Entry, dict[int, Action], set[int]], Action]
Learned = dict[int, tuple[float, frozenset[int]]]


def build(search: Search, choose: Choose) -> dict[int, Action]:
    """One grammar: regions bottom to top, left to right, each content split once."""
    grid = search.grid
    rules: dict[int, Action] = {}
    start = grid.content(search.whole)
    if start in grid.terminal:
        return rules
    pending = {start}
    heap = [_entry(search.whole, start)]
    while heap:
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


def greedy(search: Search) -> dict[int, Action]:
    return build(search, lambda entry, rules, pending: search.actions_at(entry)[0])


def adp(search: Search, iterations: int, seed: int) -> tuple[dict[int, Action], int, int]:
    """``Search.adp`` without a time limit."""
    rng = random.Random(seed)
    learned: Learned = {}
    optimistic = min(search.costs.split + 2, search.costs.repeat + 1)
    best = greedy(search)
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
        rules = build(search, choose)
        signature = tuple(map(id, rules.values()))
        if signature in seen:
            continue
        seen.add(signature)
        cost, reach = survey(search, rules)
        learn(rules, reach, learned)
        if cost < best_cost - 1e-9:
            best, best_cost, best_at = rules, cost, t
    return best, best_at, iterations
