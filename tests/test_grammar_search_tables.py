"""The grammar search's tables (:mod:`facadecli.grammar.adp`) against plain definitions: the
merged cost against ``Search.canonical``'s merging, what each rule reaches against the
rules' parts, a time limit of nothing, and the search run interpreted (Cython not
installed) against the installed build: the same grammars."""

from __future__ import annotations

import json
import math
import random
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from facadecli.grammar import adp
from facadecli.grammar import search as search_module
from facadecli.grammar.search import Action, Search
from facadecli.grammar.tiling import LabelledLayout, Rect, tile


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


def _random_grammar(search: Search, rng: random.Random) -> dict[int, Action]:
    """A grammar of random actions: regions top down, each content's first region taking
    one of its actions at random."""
    grid = search.grid
    rules: dict[int, Action] = {}
    waiting = [search.whole]
    while waiting:
        region = waiting.pop(0)
        cid = grid.content(region)
        if cid in rules or cid in grid.terminal:
            continue
        action = rules[cid] = rng.choice(search.actions(region))
        waiting.extend(action.written)
    return rules


def _grammars(search: Search, seed: int, count: int) -> list[dict[int, Action]]:
    """The greedy grammar and ``count`` grammars of random actions."""
    rng = random.Random(seed)
    return [search.greedy(), *(_random_grammar(search, rng) for _ in range(count))]


def _plain_cost(search: Search, rules: dict[int, Action]) -> float:
    same = search.canonical(rules)
    cost = 0.0
    for cid in rules:
        if same[cid] == cid:
            cost += rules[cid].cost
    return cost


def _plain_reach(search: Search, rules: dict[int, Action]) -> list[set[int]]:
    """Per rule, the positions of the rules below it, itself included (by its parts)."""
    position = {cid: i for i, cid in enumerate(rules)}
    found: dict[int, set[int]] = {}

    def below(cid: int) -> set[int]:
        if cid not in found:
            reached = {position[cid]}
            for sub in rules[cid].cids:
                if sub in rules:
                    reached |= below(sub)
            found[cid] = reached
        return found[cid]

    return [below(cid) for cid in rules]


def _region_of(action: Action) -> tuple[int, int, int, int]:
    """The region an action splits."""
    (r0, r1, c0, c1), (lo, hi) = action.written[0], (action.bounds[0], action.bounds[-1])
    if action.op == "gridsplit":
        return (lo, hi, action.across[0], action.across[-1])
    return (r0, r1, lo, hi) if action.axis == "x" else (lo, hi, c0, c1)


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
        assert [set(r) for r in reach] == _plain_reach(search, rules)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("extensions", EXTENSIONS)
def test_each_region_is_offered_its_best_actions_in_order(
    seed: int, extensions: tuple[str, ...]
) -> None:
    """At most twelve actions (eight structural cuts, then cuts in two), ranked by
    (heuristic, cost, axis, bounds), each a rule whose cost is Eq. 2's."""
    search = Search(tile(_layout(seed), 0), extensions=extensions)
    costs = search.costs
    for rules in _grammars(search, seed, 5):
        for action in rules.values():
            region = _region_of(action)
            ranked = search.actions(region)
            assert 1 <= len(ranked) <= 12 and action in ranked
            assert ranked == sorted(ranked, key=lambda a: (a.heuristic, a.cost, a.axis, a.bounds))
            for a in ranked:
                repeat = a.op in ("repeat", "repeatABA")
                assert a.cost == (costs.repeat if repeat else costs.split) + len(a.written)
                assert a.heuristic >= a.cost


def test_a_time_limit_of_nothing_stops_adp_after_the_greedy_grammar() -> None:
    search = Search(tile(_layout(3), 0))
    search.deadline.seconds = 0.0
    rules, best_at, done = search.adp(50, 0)
    assert (rules, best_at) == (search.greedy(), 0) and done == 1
    assert math.isfinite(search.cost(rules))


def _grammars_found(seeds: list[int]) -> list[list[object]]:
    """Greedy's and ADP's grammars (60 iterations, each extension set) of the layouts of
    these seeds, as text (the terminals sorted: a set's order varies between processes)."""
    found = []
    for seed in seeds:
        for extensions in EXTENSIONS:
            tiling = tile(_layout(seed), 0)
            result = search_module.extract(tiling, "adp", 60, 3, extensions=extensions)
            grammar = result.grammar
            text = [grammar.start, repr(grammar.rules), sorted(grammar.terminals)]
            found.append([*text, grammar.cost, result.best_iteration, result.regions])
    return found


def test_the_search_interpreted_gives_the_installed_builds_grammars() -> None:
    """Where there is no C compiler ``adp.py`` runs interpreted (and Cython, a build
    requirement only, may be missing): the same grammars as this install's search."""
    source = Path(adp.__file__).with_name("adp.py")
    script = textwrap.dedent(
        f"""
        import json, sys
        sys.modules["cython"] = None  # as if it were not installed
        from facadecli import native
        adp = native._interpreted(native.GRAMMAR_SEARCH, native.Path({str(source)!r}))
        assert adp.cython.compiled is False
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from test_grammar_search_tables import _grammars_found
        print(json.dumps(_grammars_found([0, 1, 2])))
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == _grammars_found([0, 1, 2])
