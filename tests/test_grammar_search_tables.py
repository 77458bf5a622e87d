"""The search's fast tables give what the plain definitions give, to the bit: the compiled
inner loop (``_adp``) what the plain Python loop gives (``facadecli.grammar.plain``), the merged
cost what ``Search.canonical`` gives, the rank of a cut in two, and the size test that spares
computing contents."""

from __future__ import annotations

import itertools
import math
import random

import pytest

from facadecli.grammar import plain
from facadecli.grammar.search import Action, Entry, Search
from facadecli.grammar.split import Axis
from facadecli.grammar.tiling import LabelledLayout, Rect, tile
from facadecli.native import GRAMMAR_COMPILED

needs_adp = pytest.mark.skipif(
    not GRAMMAR_COMPILED, reason="compares _adp.c with Python: this install has no compiled _adp"
)


def _layout(seed: int) -> LabelledLayout:
    """Rectangles of a few labels on an 8 x 6 façade, on a coarse grid so that repeats
    occur, plus a row of equal windows."""
    rng = random.Random(seed)
    rects = [Rect("window", 1.0 + 2 * i, 4.0, 2.0 + 2 * i, 5.0, 0.5) for i in range(3)]
    for i in range(rng.randint(3, 12)):
        x0, y0 = rng.randint(0, 14) / 2, rng.randint(0, 6) / 2
        w, h = rng.randint(1, 4) / 2, rng.randint(1, 3) / 2
        label = rng.choice(["window", "door", "sill"])
        rects.append(Rect(label, x0, y0, min(x0 + w, 8.0), min(y0 + h, 3.5), rng.random() + i))
    return LabelledLayout(8.0, 6.0, tuple(rects))


def _grammars(search: Search, seed: int, count: int) -> list[dict[int, Action]]:
    """The greedy grammar and ``count`` grammars of random actions."""
    rng = random.Random(seed)

    def any_action(entry: Entry, rules: dict[int, Action], pending: set[int]) -> Action:
        return rng.choice(search.actions_at(entry))

    return [search.greedy(), *(plain.build(search, any_action) for _ in range(count))]


def _plain_cost(search: Search, rules: dict[int, Action]) -> float:
    same = search.canonical(rules)
    cost = 0.0
    for cid in rules:
        if same[cid] == cid:
            cost += rules[cid].cost
    return cost


EXTENSIONS: list[tuple[str, ...]] = [(), ("repeatABA", "symsplit", "gridsplit")]


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("extensions", EXTENSIONS)
def test_the_survey_gives_the_merged_cost_and_what_each_rule_reaches(
    seed: int, extensions: tuple[str, ...]
) -> None:
    search = Search(tile(_layout(seed), 0), extensions=extensions)
    for rules in _grammars(search, seed, 20):
        cost, reach = search.survey(rules)
        assert cost == _plain_cost(search, rules)  # the same sum, in the same order
        assert search.cost(rules) == cost
        plain_cost, plain_reach = plain.survey(search, rules)
        assert (cost, [set(r) for r in reach]) == (plain_cost, plain_reach)


def _described(search: Search, region: tuple[int, int, int, int]) -> list[tuple[object, ...]]:
    """A region's actions as the compiled search describes its own."""
    return [
        (a.op, a.axis, a.bounds, a.across, a.count, int(a.centre), a.cost, a.heuristic)
        for a in search.actions(region)
    ]


@needs_adp
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("extensions", EXTENSIONS)
def test_the_compiled_search_offers_each_region_the_actions_python_offers(
    seed: int, extensions: tuple[str, ...]
) -> None:
    # every region of the tiling with two labels or more, in a random order (contents are
    # numbered as met, and equal contents must be found equal whatever the order)
    search = Search(tile(_layout(seed), 0), extensions=extensions)
    grid = search.grid
    regions = [
        (r0, r1, c0, c1)
        for r0, r1 in itertools.combinations(range(grid.rows + 1), 2)
        for c0, c1 in itertools.combinations(range(grid.columns + 1), 2)
        if grid.content((r0, r1, c0, c1)) not in grid.terminal
    ]
    random.Random(seed).shuffle(regions)
    compared = 0
    for region in regions[:400]:
        assert search._table is not None
        compiled = search._table.describe(search._table.entry(*region))
        assert compiled == _described(search, region), region
        compared += len(compiled)
    assert compared > 400


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("extensions", EXTENSIONS)
def test_the_compiled_loop_builds_the_grammars_the_plain_loop_builds(
    seed: int, extensions: tuple[str, ...]
) -> None:
    layout = tile(_layout(seed), 0)
    fast = Search(layout, extensions=extensions)
    reference = Search(layout, extensions=extensions)
    greedy = plain.greedy(reference)
    assert greedy is not None  # no time limit
    assert _shape(fast.greedy()) == _shape(greedy)
    for iterations in (1, 2, 60):
        rules, best_at, done = fast.adp(iterations, seed)
        expected, expected_at, _ = plain.adp(reference, iterations, seed)
        assert (_shape(rules), best_at, done) == (_shape(expected), expected_at, iterations)
        assert fast.cost(rules) == reference.cost(expected)


@needs_adp
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("extensions", EXTENSIONS)
def test_the_search_without_adp_gives_the_compiled_searchs_grammars(
    seed: int, extensions: tuple[str, ...]
) -> None:
    """Where the install has no compiled ``_adp`` the plain loop runs: the same contents
    (each numbered as met), the same regions explored, the same grammars."""
    layout = tile(_layout(seed), 0)
    fast = Search(layout, extensions=extensions, compiled=True)
    python = Search(layout, extensions=extensions, compiled=False)
    assert python._table is None and python.grid.table is None
    assert _shape(fast.greedy()) == _shape(python.greedy())
    rules, best_at, done = fast.adp(60, seed)
    found, found_at, found_done = python.adp(60, seed)
    assert (_shape(found), found_at, found_done) == (_shape(rules), best_at, done)
    assert python.survey(found) == fast.survey(rules)
    assert python.grammar(found) == fast.grammar(rules)
    assert python.regions_explored == fast.regions_explored


def _shape(rules: dict[int, Action]) -> list[tuple[object, ...]]:
    """A grammar's rules in order, without content numbers (each search numbers its own)."""
    return [
        (a.op, a.axis, a.bounds, a.across, a.written, a.count, a.centre, a.cost, a.heuristic)
        for a in rules.values()
    ]


@pytest.mark.parametrize("compiled", [pytest.param(True, marks=needs_adp), False])
def test_a_time_limit_of_nothing_stops_adp_after_the_greedy_grammar(compiled: bool) -> None:
    search = Search(tile(_layout(3), 0), compiled=compiled)
    search.deadline.seconds = 0.0
    rules, best_at, done = search.adp(50, 0)
    assert (rules, best_at) == (search.greedy(), 0) and done == 1
    assert math.isfinite(search.cost(rules))


@pytest.mark.parametrize("seed", range(8))
def test_a_cut_in_two_is_ranked_as_its_action_would_be(seed: int) -> None:
    search = Search(tile(_layout(seed), 0), extensions=("repeatABA", "symsplit"))
    _grammars(search, seed, 5)  # to visit regions
    for region in [search.whole, *search._actions]:
        r0, r1, c0, c1 = region
        spans: tuple[tuple[Axis, int, int], ...] = (("x", c0, c1), ("y", r0, r1))
        for axis, lo, hi in spans:
            costs = search._line_costs(region, axis)
            for line in range(lo + 1, hi):
                bounds = (lo, line, hi)
                action = search._action(region, axis, bounds, costs)
                assert action is not None
                rank = (action.heuristic, action.cost, action.axis, action.bounds)
                assert search._rank_in_two(region, axis, bounds, costs) == rank


@pytest.mark.parametrize("seed", range(8))
def test_parts_of_one_content_are_never_told_apart_by_size(seed: int) -> None:
    search = Search(tile(_layout(seed), 0))
    grid = search.grid
    axes: tuple[tuple[Axis, int], ...] = (("x", grid.columns), ("y", grid.rows))
    for axis, cells in axes:
        spans = list(itertools.combinations(range(cells + 1), 2))
        for (a, b), (c, d) in itertools.product(spans, spans):
            first = (0, grid.rows, a, b) if axis == "x" else (a, b, 0, grid.columns)
            second = (0, grid.rows, c, d) if axis == "x" else (c, d, 0, grid.columns)
            if grid.content(first) == grid.content(second):
                assert search._may_read_same(axis, first, second, (b - a) + (d - c))
