"""Property tests of the pattern language (hypothesis), checked by an independent acceptor."""

from __future__ import annotations

import itertools

from hypothesis import given, settings
from hypothesis import strategies as st

from facadecli.patterns import (
    Letter,
    compile_pattern,
    enumerate_words,
    make_word,
    mirror,
    parse_pattern,
)
from facadecli.patterns.ast import to_text
from tests.acceptor import accepts

SYMBOLS = ["A", "B", "C"]
SIZES: dict[str, float | None] = {"A": 1.0, "B": 1.5, "C": 0.5, "y": None}
COUNTS = ["2", "0", "-1", "-2", "k", "-k", "m", "*", "+"]


def patterns(leaves: list[str]) -> st.SearchStrategy[str]:
    """Pattern texts over ``leaves`` with grouping, alternation, counts and reflection."""
    atom = st.sampled_from(leaves)

    def extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        seq = st.lists(inner, min_size=1, max_size=3).map(" ".join)
        alt = st.lists(seq, min_size=2, max_size=3).map(lambda bs: "(" + " | ".join(bs) + ")")
        rep = st.tuples(st.one_of(atom, seq.map(lambda s: f"({s})")), st.sampled_from(COUNTS))
        return st.one_of(seq.map(lambda s: f"({s})"), alt, rep.map(lambda t: f"{t[0]}^{t[1]}"))

    return st.recursive(atom, extend, max_leaves=6).map(lambda t: t)


def first_words(text: str, where: dict[str, str] | None = None, limit: int = 40):  # type: ignore[no-untyped-def]
    pattern = compile_pattern(text, where)
    found = enumerate_words(
        pattern, sizes=SIZES, max_length=6.0, counters={"k": (0, None), "m": (1, 3)}, max_letters=24
    )
    return pattern, list(itertools.islice(found, limit))


@settings(max_examples=150, deadline=None)
@given(patterns(SYMBOLS))
def test_every_enumerated_word_is_accepted_and_remade(text: str) -> None:
    pattern, found = first_words(text)
    assert len({item.choice for item in found}) == len(found)  # no choice twice
    for item in found:
        assert accepts(pattern.root, item.word), (text, item)
        assert make_word(pattern, item.choice) == item.word
        assert item.length <= 6.0 + 1e-9
        assert 1 <= item.choice.as_dict().get("m", 1) <= 3


@settings(max_examples=100, deadline=None)
@given(patterns(SYMBOLS))
def test_canonical_text_parses_to_the_same_pattern(text: str) -> None:
    once = to_text(parse_pattern(text))
    assert to_text(parse_pattern(once)) == once


@settings(max_examples=100, deadline=None)
@given(patterns(SYMBOLS))
def test_reflection_reverses(text: str) -> None:
    # the same tree shape on both sides, so choice keys (pre-order indices) agree
    _, found = first_words(f"({text})^1", limit=10)
    reflected = compile_pattern(f"({text})^-1")
    for item in found:
        assert make_word(reflected, item.choice) == mirror(item.word)


@settings(max_examples=100, deadline=None)
@given(patterns(SYMBOLS), st.integers(0, 3))
def test_a_fixed_counter_is_never_changed(text: str, value: int) -> None:
    pattern = compile_pattern(f"{text} B^n")
    found = enumerate_words(
        pattern, sizes=SIZES, max_length=20.0, counters={"n": (value, value)}, max_letters=30
    )
    for item in itertools.islice(found, 30):
        assert item.choice.counters["n"] == value
        trailing = list(
            itertools.takewhile(lambda letter: letter.symbol == "B", reversed(item.word))
        )
        assert len(trailing) >= value


@settings(max_examples=100, deadline=None)
@given(
    patterns(SYMBOLS),
    st.lists(st.sampled_from(["x", "w", "w^-1"]), min_size=2, max_size=5),
)
def test_substitution_puts_one_content_word_everywhere(content: str, control: list[str]) -> None:
    # occurrences of the placeholder w are separated by the control letter x
    text = " x ".join(control)
    pattern, found = first_words(text, {"w": content}, limit=20)
    for item in found:
        assert accepts(pattern.root, item.word, dict(pattern.contents))
        runs = [
            tuple(group)
            for is_content, group in itertools.groupby(
                item.word, key=lambda lt: lt.placeholder == "w"
            )
            if is_content
        ]
        if not runs:
            continue
        first = runs[0]
        assert all(run in (first, mirror(first)) for run in runs)
        assert all(not lt.transparent for run in runs for lt in run)
        assert all(lt.transparent for lt in item.word if lt.placeholder is None)


@settings(max_examples=40, deadline=None)
@given(patterns(SYMBOLS))
def test_every_word_the_pattern_accepts_is_enumerated(text: str) -> None:
    """Completeness: every word of up to three letters (each symbol plain or reflected) that
    the independent acceptor takes, the enumerator yields (and nothing else)."""
    pattern = compile_pattern(text)
    found = enumerate_words(
        pattern,
        sizes=SIZES,
        max_length=100.0,
        counters={"k": (0, None), "m": (0, None)},  # the acceptor's: from 0, unbounded
        max_letters=3,
    )
    enumerated = {item.word for item in itertools.islice(found, 5000)}
    letters = [Letter(symbol, reflected) for symbol in SYMBOLS for reflected in (False, True)]
    accepted = {
        word
        for size in range(4)
        for word in itertools.product(letters, repeat=size)
        if accepts(pattern.root, word)
    }
    assert enumerated == accepted
