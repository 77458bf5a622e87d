"""Candidate generation (Ilčík et al. 2015, section 5.1; DESIGN.md).

A *candidate* picks one word for every pattern used on an axis: values for the named
counters (shared by all the axis' patterns), branches and anonymous counts. Candidates
are ranked by the tolerance mu they need to pass Eq. 7,

    l_i <= |w_i| <= L + mu,   l_i = L - mu - (opaque length of the layers above i),

and then by how far their words are from the canvas, so the solver tries them in the
order in which raising mu would admit them. Unsized placeholders are elastic: a word with
them only needs its fixed part to stay under L + mu.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field

from facadecli.patterns import CompiledPattern, Enumerated, enumerate_words
from facadecli.patterns.ast import Anonymous, Named, Repeat, symbols, walk
from facadecli.solver.budgets import (
    FINITE_LETTERS,
    MAX_LETTERS,
    OPTIONS_PER_CLUSTER,
    WORDS_PER_PATTERN,
)
from facadecli.spec.model import Spec


@dataclass(frozen=True)
class PatternUse:
    """A distinct pattern on one axis and the (layer, group) pairs that use it."""

    key: str  # the pattern's name, or the inline pattern text
    pattern: CompiledPattern
    layers: tuple[tuple[int, str], ...]  # (layer index, alignment group), back to front


@dataclass(frozen=True)
class Candidate:
    """One word per pattern of an axis."""

    words: Mapping[str, Enumerated]  # pattern key -> word with its choice and length
    counters: tuple[tuple[str, int], ...]
    need: float  # the least tolerance mu under which every word passes Eq. 7
    misfit: float  # sum of squared Eq. 7 violations at mu = 0
    shortfall: float  # how much the words below opaque letters rely on them making room
    slack: float  # how much placeholders must cover (elastic words short of the canvas)
    order: int = field(default=0, compare=False)

    @property
    def key(self) -> tuple[float, float, float, int]:
        """Tolerance needed, misfit, room relied on; then enumeration order (counts
        ascending, as the paper enumerates). How much placeholders cover is left to the
        comparison of solved layouts (SPEC 2.7)."""
        return (round(self.need, 9), round(self.misfit, 9), round(self.shortfall, 6), self.order)


def word_need(length: float, elastic: bool, canvas: float, made_room: float) -> float:
    """Least mu with ``canvas - mu - made_room <= length <= canvas + mu`` (Eq. 7); a
    length that misses the canvas by rounding only (a sum of many sizes) fits it."""
    over = length - canvas
    if abs(over) <= 1e-9 * max(1.0, canvas):
        over = 0.0
    if elastic:
        return max(0.0, over)
    under = canvas - made_room - length
    return max(0.0, over, under)


def placeholder_range(
    item: Enumerated, spec: Spec, canvas: float, mu: float, made_room: float = 0.0
) -> tuple[float, float] | None:
    """Sizes an elastic word's placeholders may take (all of them alike) under Eq. 7.

    The paper samples this range uniformly (Figure 7); the solver keeps it elastic.
    """
    count = sum(1 for letter in item.word if spec.size(letter.symbol) is None)
    if not count:
        return None
    low = max(0.0, (canvas - mu - made_room - item.length) / count)
    high = (canvas + mu - item.length) / count
    return (low, high) if high >= low else None


def pattern_uses(
    spec: Spec, axis_words: Sequence[tuple[int, str, str, CompiledPattern]]
) -> list[PatternUse]:
    """Group (layer, group, key, pattern) tuples by pattern key, in order of first use."""
    uses: dict[str, tuple[CompiledPattern, list[tuple[int, str]]]] = {}
    for layer, group, key, pattern in axis_words:
        uses.setdefault(key, (pattern, []))[1].append((layer, group))
    return [PatternUse(key, pattern, tuple(layers)) for key, (pattern, layers) in uses.items()]


def generate_candidates(
    spec: Spec, uses: Sequence[PatternUse], canvas: float, limit: int = 500
) -> list[Candidate]:
    """Up to ``limit`` candidates, best first (by needed mu, then misfit)."""
    space = CandidateSpace.of(spec, uses, canvas)
    return [] if space is None else space.best(limit)


@dataclass
class CandidateSpace:
    """Every pattern's words on one axis, joined into options per cluster of patterns that
    share counters; a candidate is one option per cluster."""

    canvas: float
    clusters: list[list[PatternUse]]
    options: list[list[dict[str, Enumerated]]]  # per cluster, best first
    above: list[tuple[str, tuple[str, ...]]]
    opaque: dict[int, float]
    truncated: bool  # a cap cut the words or options: some candidates are never made
    # a lower bound on the objective of every candidate with a word longer than twice the
    # canvas (never made; see of())
    beyond: float = math.inf
    # per pattern, its words, those that need least tolerance (Eq. 7) first
    words: dict[str, list[Enumerated]] = field(default_factory=dict)
    reach: float = 2.0  # words up to this many canvases long are made
    reached: frozenset[str] = frozenset()  # patterns whose words were cut at the reach
    made: int = 0  # candidates made so far (their order)

    @classmethod
    def of(
        cls, spec: Spec, uses: Sequence[PatternUse], canvas: float, reach: float = 2.0
    ) -> CandidateSpace | None:
        """The space of an axis, of words up to ``reach`` times the canvas (a space of
        reach 2 bounds every longer word by ``beyond``; one of less holds the words of
        layouts at objective 0 only); None when some pattern makes no word."""
        sizes = {name: symbol.size for name, symbol in spec.symbols.items()}
        transparent = frozenset(n for n in spec.symbols if spec.qualifiers(n).transparent)
        bounds = {name: counter.bounds for name, counter in spec.counters.items()}
        words: dict[str, list[Enumerated]] = {}
        truncated = False
        beyond = math.inf
        reached = set()
        for use in uses:
            # words up to twice the canvas: a longer one has sized letters whose preferred
            # sizes add up to more than twice the canvas, so laid on it they shrink by more
            # than half their length in all: its objective is at least (l - L)^2 / n >=
            # (smallest size)^2 / 4 (n letters, l >= n * smallest, l - L > l / 2)
            found = []
            if finite(use):  # all its words, if they are few
                found = _words(use, sizes, transparent, bounds, math.inf, FINITE_LETTERS)
                if len(found) > WORDS_PER_PATTERN or any(
                    len(item.word) >= FINITE_LETTERS for item in found
                ):
                    found = []
            if not found:
                smallest = min(
                    (size for size in (sizes.get(n) for n in _names(use)) if size), default=0.0
                )
                beyond = min(beyond, smallest * smallest / 4.0)
                reached.add(use.key)
                found = _words(use, sizes, transparent, bounds, reach * canvas)
            if not found:  # not one word that short: the shortest there are
                found = _words(use, sizes, transparent, bounds, math.inf)
            if len(found) > WORDS_PER_PATTERN:
                truncated = True
                del found[WORDS_PER_PATTERN:]
            if not found or any(len(item.word) >= MAX_LETTERS for item in found):
                truncated = True  # words of MAX_LETTERS letters or more are not made
            if not found:
                return None
            words[use.key] = found
            bounds.update(_seen_counters(use.pattern, words[use.key]))
        opaque_of = _opaque_sizes(spec)
        opaque = {
            id(item): sum(
                opaque_of.get(letter.symbol, 0.0) for letter in item.word if not letter.transparent
            )
            for found in words.values()
            for item in found
        }
        clusters = _clusters(uses)
        room = {use.key: _max_room_above(use, uses, words, opaque) for use in uses}
        needs = {
            id(item): word_need(item.length, item.elastic, canvas, room[key])
            for key, found in words.items()
            for item in found
        }
        options = []
        for cluster in clusters:
            cluster_options, cut = _options_by_need(cluster, words, needs)
            options.append(cluster_options)
            truncated = truncated or cut
        if any(not cluster_options for cluster_options in options):
            return None
        # rank each cluster's options by a context-free estimate
        ranked = []
        for cluster_options in options:
            scored = [
                (_estimate(spec, option, canvas, room), index, option)
                for index, option in enumerate(cluster_options)
            ]
            scored.sort(key=lambda item: (item[0], item[1]))
            ranked.append([option for _, _, option in scored])
        by_need = {
            key: sorted(found, key=lambda item: needs[id(item)]) for key, found in words.items()
        }
        return cls(
            canvas,
            clusters,
            ranked,
            _layers_above(uses),
            opaque,
            truncated,
            beyond,
            by_need,
            reach,
            frozenset(reached),
        )

    def candidate(self, choice: Sequence[dict[str, Enumerated]]) -> Candidate:
        """The candidate of one option per cluster (numbered in the order made)."""
        merged: dict[str, Enumerated] = {}
        for option in choice:
            merged.update(option)
        made = _candidate(self.above, merged, self.canvas, self.made, self.opaque)
        self.made += 1
        return made

    def best(self, limit: int) -> list[Candidate]:
        """Up to ``limit`` candidates, best first (by needed mu, then misfit): the
        combinations of options by increasing sum of ranks."""
        found = [self.candidate(c) for c in _best_combinations(self.options, limit)]
        found.sort(key=lambda candidate: candidate.key)
        return found

    def variants(self, candidate: Candidate, cluster: int, most: int) -> list[Candidate]:
        """The candidate with another option of one cluster (its first ``most``)."""
        keys = {use.key for use in self.clusters[cluster]}
        kept = {key: item for key, item in candidate.words.items() if key not in keys}
        return [
            self.candidate([kept, option])
            for option in self.options[cluster][:most]
            if any(option[key] is not candidate.words[key] for key in keys)
        ]


def _names(use: PatternUse) -> set[str]:
    """The symbols of a pattern, its contents' too."""
    roots = (use.pattern.root, *use.pattern.contents.values())
    return {symbol.name for root in roots for symbol in symbols(root)}


def finite(use: PatternUse) -> bool:
    """Whether a pattern makes finitely many words: no counter, named or anonymous."""
    roots = (use.pattern.root, *use.pattern.contents.values())
    return not any(
        isinstance(node, Repeat) and isinstance(node.count, Named | Anonymous)
        for root in roots
        for node in walk(root)
    )


def _words(
    use: PatternUse,
    sizes: Mapping[str, float | None],
    transparent: frozenset[str],
    bounds: Mapping[str, tuple[int, int | None]],
    longest: float,
    letters: int = MAX_LETTERS,
) -> list[Enumerated]:
    """A pattern's words up to ``longest`` metres and ``letters`` letters,
    WORDS_PER_PATTERN + 1 at most."""
    enumerated = enumerate_words(
        use.pattern,
        sizes=sizes,
        max_length=longest,
        transparent=transparent,
        counters=bounds,
        max_letters=letters,
    )
    return list(itertools.islice(enumerated, WORDS_PER_PATTERN + 1))


def _seen_counters(
    pattern: CompiledPattern, found: Sequence[Enumerated]
) -> dict[str, tuple[int, int]]:
    """The range of each named counter over a pattern's words, for a counter that every
    word sets: words of the patterns after it that share the counter agree with one of
    them only within it (a pattern whose words leave a counter unset agrees with any)."""
    seen = {}
    for name in pattern.counter_names():
        values = [item.choice.counters.get(name) for item in found]
        known = [value for value in values if value is not None]
        if len(known) == len(values):
            seen[name] = (min(known), max(known))
    return seen


def _opaque_sizes(spec: Spec) -> dict[str, float]:
    """Preferred size of every sized, opaque, non-transparent symbol."""
    sizes = {}
    for name in spec.symbols:
        qualifiers = spec.qualifiers(name)
        size = spec.size(name)
        if size and qualifiers.opaque and not qualifiers.transparent:
            sizes[name] = size
    return sizes


def _clusters(uses: Sequence[PatternUse]) -> list[list[PatternUse]]:
    """Patterns connected by shared named counters (union-find over counter names)."""
    parent = list(range(len(uses)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[str, int] = {}
    for index, use in enumerate(uses):
        for name in use.pattern.counter_names():
            if name in owner:
                parent[find(index)] = find(owner[name])
            else:
                owner[name] = index
    clusters: dict[int, list[PatternUse]] = {}
    for index, use in enumerate(uses):
        clusters.setdefault(find(index), []).append(use)
    return list(clusters.values())


def _options_by_need(
    cluster: list[PatternUse], words: Mapping[str, list[Enumerated]], needs: Mapping[int, float]
) -> tuple[list[dict[str, Enumerated]], bool]:
    """A cluster's joint word choices, those whose words need least tolerance (Eq. 7)
    first: every option whose words all need at most some tolerance, for the largest
    tolerance whose options stay within OPTIONS_PER_CLUSTER, then options of the next
    tolerance up to that cap. With it, whether the cap left some out (then the candidate
    space is truncated: what is not made is not proven absent). Joining the words in the
    order they are enumerated, as a capped join would, keeps the first counts and loses
    a façade of many floors whose layers have alternatives."""
    tiers = sorted({needs[id(item)] for use in cluster for item in words[use.key]})

    def within(tier: int) -> list[dict[str, Enumerated]]:
        limit = tiers[tier] + 1e-12
        return _cluster_options(
            cluster,
            {use.key: [i for i in words[use.key] if needs[id(i)] <= limit] for use in cluster},
        )

    every = _cluster_options(cluster, words)
    if len(every) < OPTIONS_PER_CLUSTER:  # all of them, as a rule
        return every, False
    # the largest tier whose options all fit under the cap (their count grows with it)
    low, high = -1, len(tiers) - 2
    complete: list[dict[str, Enumerated]] = []
    while low < high:
        middle = (low + high + 1) // 2
        found = within(middle)
        if len(found) < OPTIONS_PER_CLUSTER:
            low, complete = middle, found
        else:
            high = middle - 1
    # and the next tier's first options, up to the cap
    seen = {tuple(id(item) for item in option.values()) for option in complete}
    more = [o for o in within(low + 1) if tuple(id(i) for i in o.values()) not in seen]
    return complete + more[: OPTIONS_PER_CLUSTER - len(complete)], True


def _cluster_options(
    cluster: list[PatternUse], words: Mapping[str, list[Enumerated]]
) -> list[dict[str, Enumerated]]:
    """Joint word choices of a cluster whose shared counters agree (OPTIONS_PER_CLUSTER
    at most, in the order the words are given)."""
    options: list[dict[str, Enumerated]] = []
    # each pattern's words with their counters, and filed by the values of the counters
    # that every one of them sets and a pattern before it names (the join's usual keys)
    filed = []
    named: set[str] = set()
    for use in cluster:
        items = [(item, item.choice.counters) for item in words[use.key]]
        keys = tuple(
            sorted(n for n in use.pattern.counter_names() & named if all(n in c for _, c in items))
        )
        index: dict[tuple[int, ...], list[tuple[Enumerated, dict[str, int]]]] = {}
        for item, values in items:
            index.setdefault(tuple(values[n] for n in keys), []).append((item, values))
        filed.append((items, keys, index))
        named |= use.pattern.counter_names()

    def extend(i: int, chosen: dict[str, Enumerated], counters: dict[str, int]) -> None:
        if len(options) >= OPTIONS_PER_CLUSTER:
            return
        if i == len(cluster):
            options.append(dict(chosen))
            return
        items, keys, index = filed[i]
        if all(n in counters for n in keys):
            items = index.get(tuple(counters[n] for n in keys), [])
        key = cluster[i].key
        for item, values in items:
            if any(counters.get(name, value) != value for name, value in values.items()):
                continue
            chosen[key] = item
            extend(i + 1, chosen, {**counters, **values})
            del chosen[key]

    extend(0, {}, {})
    return options


def _max_room_above(
    use: PatternUse,
    uses: Sequence[PatternUse],
    words: Mapping[str, list[Enumerated]],
    opaque: Mapping[int, float],
) -> float:
    """The most opaque length the layers above ``use`` (in its groups) could make room for."""
    best = 0.0
    for layer, group in use.layers:
        room = 0.0
        for other in uses:
            if any(g == group and i > layer for i, g in other.layers):
                room += max((opaque[id(item)] for item in words[other.key]), default=0.0)
        best = max(best, room)
    return best


def _estimate(
    spec: Spec, option: Mapping[str, Enumerated], canvas: float, room: Mapping[str, float]
) -> tuple[float, float, float]:
    """Tolerance needed, misfit; then how far the words are from the canvas (among words
    that layers in front could make room for, the ones that fill it come first)."""
    needs = [word_need(i.length, i.elastic, canvas, room[key]) for key, i in option.items()]
    gap = sum(abs(canvas - i.length) for i in option.values() if not i.elastic)
    return (max(needs, default=0.0), sum(n * n for n in needs), round(gap, 9))


def _best_combinations(
    ranked: list[list[dict[str, Enumerated]]], limit: int
) -> Iterator[tuple[dict[str, Enumerated], ...]]:
    """Combinations of one option per cluster, by increasing sum of ranks (a heap)."""
    start = (0,) * len(ranked)
    heap = [(0, start)]
    seen = {start}
    produced = 0
    while heap and produced < limit:
        _, indices = heapq.heappop(heap)
        yield tuple(options[i] for options, i in zip(ranked, indices, strict=True))
        produced += 1
        for position in range(len(indices)):
            if indices[position] + 1 < len(ranked[position]):
                successor = (*indices[:position], indices[position] + 1, *indices[position + 1 :])
                if successor not in seen:
                    seen.add(successor)
                    heapq.heappush(heap, (sum(successor), successor))


def _layers_above(uses: Sequence[PatternUse]) -> list[tuple[str, tuple[str, ...]]]:
    """Per layer using a pattern: (its pattern, the patterns of the layers above it in its
    group, one per layer)."""
    return [
        (
            use.key,
            tuple(
                other.key
                for other in uses
                if any(g == group and i > layer for i, g in other.layers)
            ),
        )
        for use in uses
        for layer, group in use.layers
    ]


def _candidate(
    above: Sequence[tuple[str, tuple[str, ...]]],
    words: Mapping[str, Enumerated],
    canvas: float,
    order: int,
    opaque_of: Mapping[int, float],
) -> Candidate:
    """A candidate with its exact Eq. 7 need (opaque room from the chosen words above)."""
    opaque = {key: opaque_of[id(item)] for key, item in words.items()}
    rooms: dict[tuple[str, ...], float] = {}  # layers of one pattern often share what is above
    need = misfit = shortfall = slack = 0.0
    for key, keys_above in above:
        item = words[key]
        room = rooms.get(keys_above)
        if room is None:
            room = rooms[keys_above] = sum(opaque[other] for other in keys_above)
        row_need = word_need(item.length, item.elastic, canvas, room)
        need = max(need, row_need)
        misfit += row_need * row_need
        if item.elastic:
            slack += max(0.0, canvas - item.length)
        else:
            shortfall += max(0.0, canvas - item.length - row_need)
    counters: dict[str, int] = {}
    for item in words.values():
        counters.update(item.choice.counters)
    return Candidate(
        dict(words), tuple(sorted(counters.items())), need, misfit, shortfall, slack, order
    )


def placeholder_samples(bounds: tuple[float, float], step: float) -> list[float]:
    """Sizes in ``bounds`` at multiples of ``step`` (zero left out), as the paper samples
    unsized symbols (section 5.1, Figure 7): a readable list of the options."""
    low, high = bounds
    first = max(1, math.ceil(low / step - 1e-9))
    last = math.floor(high / step + 1e-9)
    return [round(i * step, 9) for i in range(first, last + 1)]
