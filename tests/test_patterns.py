"""The pattern language: parsing (with error offsets), words, reflection, substitution."""

from __future__ import annotations

import pytest

from facadecli.patterns import (
    PatternSyntaxError,
    compile_pattern,
    enumerate_words,
    format_word,
    make_word,
    mirror,
    parse_pattern,
)
from facadecli.patterns.ast import Alt, Anonymous, Fixed, Named, Repeat, Seq, Sym, to_text
from tests.acceptor import accepts

SIZES = {name: 1.0 for name in "ABCDEFGPQSTWXYZ"}


def text_of(pattern: str, choice: dict[str, int], where: dict[str, str] | None = None) -> str:
    return format_word(make_word(compile_pattern(pattern, where), choice))


@pytest.mark.parametrize(
    ("text", "tree"),
    [
        ("A", Sym("A", 0)),
        ("A B", Seq((Sym("A", 0), Sym("B", 2)), 0)),
        ("A^3", Repeat(Sym("A", 0), Fixed(3), 0)),
        ("A^-1", Repeat(Sym("A", 0), Fixed(-1), 0)),
        ("A^k", Repeat(Sym("A", 0), Named("k", False, 2), 0)),
        ("A^-k", Repeat(Sym("A", 0), Named("k", True, 3), 0)),
        ("A^*", Repeat(Sym("A", 0), Anonymous(0), 0)),
        ("A^+", Repeat(Sym("A", 0), Anonymous(1), 0)),
        ("A|B", Alt((Sym("A", 0), Sym("B", 2)), 0)),
        ("(A|)", Alt((Sym("A", 1), Seq((), 3)), 0)),
        (
            "A (B A)^k",
            Seq(
                (Sym("A", 0), Repeat(Seq((Sym("B", 3), Sym("A", 5)), 2), Named("k", False, 8), 2)),
                0,
            ),
        ),
    ],
)
def test_parse(text: str, tree: object) -> None:
    assert parse_pattern(text) == tree


@pytest.mark.parametrize(
    "text",
    ["A", "A B C", "A (B A)^k", "(A | B C)^* D^-2", "G X (z S)^p z^b v", "((A^2)^-3 | B)^+"],
)
def test_canonical_text_round_trips(text: str) -> None:
    tree = parse_pattern(text)
    assert to_text(parse_pattern(to_text(tree))) == to_text(tree)


@pytest.mark.parametrize(
    ("text", "offset", "fragment"),
    [
        ("", 0, "empty"),
        ("   ", 0, "empty"),
        ("A (B A", 2, "unbalanced '('"),
        ("A B) C", 3, "unbalanced ')'"),
        ("A ^", 2, "needs a count"),
        ("A^", 1, "needs a count"),
        ("A^ B", 1, "needs a count"),
        ("A^- 1", 1, "needs a count"),
        ("A^(2)", 1, "needs a count"),
        ("^3 A", 0, "nothing to repeat"),
        ("A (^2)", 3, "nothing to repeat"),
        ("A^2^3", 3, "cannot be repeated again"),
        ("A $ B", 2, "unexpected character '$'"),
        ("A 3", 2, "unexpected '3'"),
        ("A^99999999", 2, "too large"),
    ],
)
def test_syntax_errors_point_at_the_mistake(text: str, offset: int, fragment: str) -> None:
    with pytest.raises(PatternSyntaxError) as caught:
        parse_pattern(text)
    assert caught.value.offset == offset
    assert fragment in caught.value.message
    assert caught.value.hint


def test_deep_nesting_is_refused_not_overflowed() -> None:
    with pytest.raises(PatternSyntaxError, match="nested deeper"):
        parse_pattern("(" * 1000 + "A" + ")" * 1000)


def test_counting_and_fixed_counts() -> None:
    assert text_of("A (B A)^k", {"k": 2}) == "A B A B A"
    assert text_of("A (B A)^k", {"k": 0}) == "A"
    assert text_of("A^3 B^0", {}) == "A A A"


def test_reflection_reverses_and_marks_letters() -> None:
    assert text_of("(A B C)^-1", {}) == "C' B' A'"
    assert text_of("(A B)^-k", {"k": 2}) == "B' A' B' A'"
    assert text_of("((A B)^-1)^-1", {}) == "A B"  # two reflections cancel
    word = make_word(compile_pattern("A B C"), {})
    assert make_word(compile_pattern("(A B C)^-1"), {}) == mirror(word)


def test_alternation_is_chosen_once_per_node() -> None:
    pattern = compile_pattern("(A | B C)^3")
    assert text_of("(A | B C)^3", {"alt#1": 1}) == "B C B C B C"
    with pytest.raises(KeyError, match="alt#1"):
        make_word(pattern, {})


def test_substitution_uses_one_content_word_and_mirrors_it() -> None:
    # the paper's Eq. 4-6: y B m A m^-1 B y with m := (A B)^k
    word = make_word(compile_pattern("y B m A m^-1 B y", {"m": "(A B)^k"}), {"k": 2})
    assert format_word(word) == "[y] [B] A B A B [A] B' A' B' A' [B] [y]"
    assert [letter.placeholder for letter in word if not letter.transparent] == ["m"] * 8


def test_control_letters_are_transparent_and_symbols_can_be_too() -> None:
    word = make_word(compile_pattern("c e c", {"c": "C"}), {})
    assert format_word(word) == "C [e] C"
    assert (
        format_word(make_word(compile_pattern("A T A"), {}, transparent=frozenset("T")))
        == "A [T] A"
    )


def test_enumeration_stays_within_the_budget_and_is_lazy() -> None:
    pattern = compile_pattern("A (B A)^k")
    sizes = {"A": 0.6, "B": 1.0}
    words = list(enumerate_words(pattern, sizes=sizes, max_length=6.0, counters={"k": (1, None)}))
    assert [w.choice.counters["k"] for w in words] == [1, 2, 3]
    assert [round(w.length, 6) for w in words] == [2.2, 3.8, 5.4]
    # an unbounded space is walked lazily: the first word comes at once
    huge = enumerate_words(compile_pattern("(A | B)^* (C^* | D^+)^*"), sizes=SIZES, max_length=1e9)
    assert next(iter(huge)).word == ()


def test_enumeration_lower_bound_and_elastic_words() -> None:
    pattern = compile_pattern("A^k")
    found = enumerate_words(pattern, sizes={"A": 1.0}, min_length=3.0, max_length=4.0)
    assert [w.choice.counters["k"] for w in found] == [3, 4]
    control = compile_pattern("y B y", {"B": "B"})
    elastic = list(enumerate_words(control, sizes={"B": 1.0}, min_length=5, max_length=9))
    assert len(elastic) == 1 and elastic[0].elastic and elastic[0].length == 1.0


def test_fixed_counter_is_never_changed() -> None:
    pattern = compile_pattern("A^n B^n")
    found = list(enumerate_words(pattern, sizes=SIZES, max_length=100, counters={"n": (3, 3)}))
    assert [format_word(w.word) for w in found] == ["A A A B B B"]


def test_shared_counter_takes_one_value() -> None:
    found = enumerate_words(compile_pattern("A^k B A^k"), sizes=SIZES, max_length=5)
    assert [format_word(w.word) for w in found] == ["B", "A B A", "A A B A A"]


def test_pinned_decisions() -> None:
    found = enumerate_words(compile_pattern("A^k | B"), sizes=SIZES, max_length=9, fixed={"k": 2})
    assert [format_word(w.word) for w in found] == ["A A", "B"]


def test_acceptor_agrees_on_examples() -> None:
    pattern = compile_pattern("y B m A m^-1 B y", {"m": "(A B)^k"})
    word = make_word(pattern, {"k": 1})
    assert accepts(pattern.root, word, dict(pattern.contents))
    broken = word[:3] + word[4:]
    assert not accepts(pattern.root, broken, dict(pattern.contents))
