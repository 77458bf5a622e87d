"""The solver on the paper's examples (Ilčík et al. 2015) and the SPEC's semantics."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
import yaml

from facadecli import InfeasibleError, load_spec, make_word, parse_spec, retarget, solve
from facadecli.solver import candidates
from facadecli.solver.alignment import align, score_alignment
from facadecli.solver.axis import _check_lengths, axis_words, solve_axis_alternatives
from facadecli.solver.budgets import safety_clock
from facadecli.solver.candidates import (
    generate_candidates,
    pattern_uses,
    placeholder_range,
    placeholder_samples,
)
from facadecli.solver.rows import full_layers, make_rows
from facadecli.spec.resolve import layer_pattern
from tests.solving import letters, solve_text, spans

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))

FIG7 = """
version: 1
name: figure-7
canvas: {width: 10, height: 1}
solver: {tolerance: 1.0}
symbols: {A: 2, B: 3, C: 1.3, H: 1}
counters: {s: {min: 1}, t: {min: 1}}
patterns:
  lower: "A^s C^t A^s"
  upper: {control: "e b^s e", where: {b: "B"}}
layers:
  - {name: w2, x: lower, y: H}
  - {name: w1, x: upper, y: H}
"""


def test_figure_7_counting_and_sizing_candidates() -> None:
    spec = parse_spec(FIG7)
    uses = pattern_uses(
        spec,
        [
            (i, "default", layer.x, layer_pattern(spec, layer, "x"))
            for i, layer in enumerate(spec.layers)
        ],
    )
    mu = spec.solver.tolerance
    admitted = [c for c in generate_candidates(spec, uses, 10.0) if c.need <= mu + 1e-9]
    table = set()
    for candidate in admitted:
        values = dict(candidate.counters)
        upper = candidate.words["upper"]
        bounds = placeholder_range(upper, spec, 10.0, mu)
        assert bounds is not None
        for size in placeholder_samples(bounds, step=mu):
            table.add((values["s"], values["t"], size))
        assert 9.0 - 1e-9 <= candidate.words["lower"].length <= 11.0 + 1e-9
    # the paper's table: (s, t) and |e| of the six candidates for alignment
    assert table == {(1, 5, 4.0), (1, 5, 3.0), (1, 4, 4.0), (1, 4, 3.0), (2, 2, 2.0), (2, 1, 2.0)}


def _rows(spec_text: str, words: dict[str, dict[str, int]]):  # type: ignore[no-untyped-def]
    spec = parse_spec(textwrap.dedent(spec_text))
    members = []
    for index, layer in enumerate(spec.layers):
        word = make_word(layer_pattern(spec, layer, "x"), words.get(layer.name, {}))
        members.append((index, word))
    return spec, make_rows(spec, members, full_layers(spec, "x"))


EQ8 = """
version: 1
name: equation-8
canvas: {width: 6, height: 1}
symbol_defaults: {opaque: true}
symbols: {A: 1, B: 1.5, C: 1, H: 1}
patterns:
  base: "A B A B A"
  columns: {control: "c e c", where: {c: "C"}}
layers:
  - {name: base, x: base, y: H}
  - {name: columns, x: columns, y: H}
"""


def test_equation_8_alignments_and_the_winner() -> None:
    _, rows = _rows(EQ8, {})
    # rows back to front: A B A B A, then C e C
    # letter cuts per row (None = empty entry); positions count letters
    mixed = [[(0, 3), (3, 5)], [(0, 2), (2, 3)]]  # (ABA | BA) under (Ce | C)
    room = [[None, (0, 5), None], [(0, 1), (1, 2), (2, 3)]]  # (eps | ABABA | eps)
    snug = [[(0, 1), (1, 4), (4, 5)], [(0, 1), (1, 2), (2, 3)]]  # (A | BAB | A)
    canvas = 6.0
    assert score_alignment(rows, mixed, canvas, 0.0) is None  # C and e share an entry
    assert score_alignment(rows, room, canvas, 0.0) == pytest.approx(2.0)  # span 8 > 6
    assert score_alignment(rows, snug, canvas, 0.0) == pytest.approx(0.0)
    found = align(rows, canvas, 0.0, deadline=float("inf")).alignment
    assert found is not None
    cuts = [[(e.start // 2, e.end // 2) if e else None for e in column] for column in found.entries]
    assert [c[0] for c in cuts] == [(0, 1), (1, 4), (4, 5)]
    assert [c[1] for c in cuts] == [(0, 1), (1, 2), (2, 3)]


TRANSPARENT_SPLIT = """
version: 1
name: transparent-split
canvas: {width: 12, height: 3}
symbol_defaults: {opaque: true}
symbols: {A: 2, B: 3, C: 2, H: 3}
patterns:
  base: "A B A B A"
  columns: {control: "c e c", where: {c: "C"}}
  top: {control: "f a f", where: {a: "A"}}
layers:
  - {name: base, x: base, y: H}
  - {name: columns, x: columns, y: H}
  - {name: top, x: top, y: H}
"""


def test_transparent_split_keeps_every_preferred_size() -> None:
    layout = solve_text(TRANSPARENT_SPLIT)
    assert spans(layout, "top", "x", "A") == [(5.0, 7.0)]
    assert spans(layout, "columns", "x", "C") == [(0.0, 2.0), (10.0, 12.0)]
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9)
    # f is cut into pieces where C and e change: the columns of the paper's matrix
    assert layout.x.groups["default"].boundaries == (0.0, 2.0, 5.0, 7.0, 10.0, 12.0)


RESIDENTIAL = """
version: 1
name: residential-house
canvas: {width: 6.0, height: 3.0}
symbol_defaults: {opaque: true}
symbols:
  A: 0.6
  B: 1.0
  P: 1.6
  Q: 1.4
  C: {size: 0.4, opaque: false}
  D: {size: 1.0, label: door}
counters: {k: {min: 1}}
patterns:
  house_x: "A (B A)^k"
  house_y: "P Q"
  corner_columns: {control: "c e c", where: {c: "C"}}
  entrance: {control: "y d y", where: {d: "D"}}
layers:
  - {name: base, x: house_x, y: house_y}
  - {name: columns, x: corner_columns, y: house_y, visible: {y: [P]}, offset: 0.05}
  - {name: door, x: entrance, y: house_y, visible: {y: [P]}, offset: 0.02}
"""


def test_residential_house_of_section_4() -> None:
    layout = solve_text(RESIDENTIAL)
    # 0.6 + 1.6 k is 5.4 or 7.0: no integer k fits 6 m; the nearer one is taken and stretched
    assert layout.counters["k"] == 3
    base = letters(layout, "base", "x")
    assert base[0].start == 0.0 and base[-1].end == 6.0
    lengths = {round(p.end - p.start, 6) for p in base if p.symbol == "A"}
    assert len(lengths) == 1  # every A alike
    # corner columns on the ground floor only
    columns = [s for s in layout.shapes if s.layer == "columns"]
    assert {(s.x, s.y) for s in columns} == {("C", "P")}
    assert sorted((s.x0, s.x1) for s in columns)[0][0] == 0.0
    assert sorted((s.x0, s.x1) for s in columns)[-1][1] == 6.0
    # the door is centred by the two y placeholders
    y_sizes = {round(p.end - p.start, 6) for p in letters(layout, "door", "x") if p.symbol == "y"}
    assert len(y_sizes) == 1
    (door,) = spans(layout, "door", "x", "D")
    assert (door[0] + door[1]) / 2 == pytest.approx(3.0)


FIG4 = """
version: 1
name: figure-4
canvas: {{width: 8.9, height: 3}}
symbol_defaults: {{opaque: true}}
symbols:
  A: 1.5
  D: {{size: 0.5{d}}}
  B: {{size: 1.2{b}}}
  P: {{size: 0.5, opaque: {p}}}
  H: 3
counters: {{m: 2, n: {{min: 1}}}}
patterns:
  wall: "A (D B D A)^m"
  front: {{control: "a (d b d a)^n", where: {{d: "P"}}}}
layers:
  - {{name: L0, x: wall, y: H}}
  - {{name: L1, x: front, y: H}}
"""


def _figure_4(d: str = "", b: str = "", p: str = "false") -> tuple[list, list]:  # type: ignore[type-arg]
    layout = solve_text(FIG4.format(d=d, b=b, p=p))
    wall = [(x.symbol, round(x.start, 6), round(x.end, 6)) for x in letters(layout, "L0", "x")]
    pilasters = spans(layout, "L1", "x", "P")
    return wall, pilasters


def _under(wall: list, span: tuple[float, float]) -> list[str]:  # type: ignore[type-arg]
    return [s for s, a, b in wall if a < span[1] - 1e-6 and b > span[0] + 1e-6]


def test_figure_4a_by_default_p_occludes_d() -> None:
    wall, pilasters = _figure_4()
    assert pilasters and all(_under(wall, p) == ["D"] for p in pilasters)
    assert all(any((a, b) == p for s, a, b in wall if s == "D") for p in pilasters)


def test_figure_4b_unoccludable_d_sends_p_to_b() -> None:
    wall, pilasters = _figure_4(d=", unoccludable: true")
    assert pilasters and all(_under(wall, p) == ["B"] for p in pilasters)


def test_figure_4c_opaque_p_sits_between_elements() -> None:
    wall, pilasters = _figure_4(d=", unoccludable: true", p="true")
    assert pilasters and all(_under(wall, p) == [] for p in pilasters)  # L0 makes room


def test_figure_4d_attached_b_keeps_its_neighbours() -> None:
    wall, pilasters = _figure_4(d=", unoccludable: true", b=", attached: true", p="true")
    assert pilasters and all(_under(wall, p) == [] for p in pilasters)
    for index, (symbol, start, end) in enumerate(wall):
        if symbol == "B":  # no gap next to a B: its Ds touch it
            assert wall[index - 1][2] == start and wall[index + 1][1] == end


TERRACED = """
version: 1
name: terraced-house
canvas: {{width: 20.0, height: 22.4}}
symbol_defaults: {{opaque: true}}
symbols:
  W: 2.6
  B: 3.2
  Q: 0.4
  L: 5.8
  G: 4.0
  X: 0.3
  S: 3.0
  Z: 3.0
  Y: 0.3
  T: 2.8
counters: {{m: {{min: 1}}, n: {{min: 1}}, p: {{min: 0}}, b: {{min: 0, max: 1}}}}
patterns:
  floors: "G X S^m Y T"
  bays: "{bays}"
  balcony_x: {{control: "W l h", where: {{l: "L"}}}}
  balcony_y: {{control: "G X (z S)^p z^b v", where: {{z: "Z"}}}}
layers:
  - {{name: base, x: bays, y: floors}}
  - {{name: balconies, x: balcony_x, y: balcony_y, offset: 1.2}}
"""


def test_section_6_1_terraced_house_balconies_on_odd_floors() -> None:
    layout = solve_text(TERRACED.format(bays="W (B W)^n"))
    floors = [p for p in letters(layout, "base", "y") if p.symbol == "S"]
    assert layout.counters["m"] == 5 == len(floors)  # 4.3 + 3 m + 3.1 = 22.4
    balconies = spans(layout, "balconies", "y", "Z")
    with_balcony = [
        i + 1 for i, f in enumerate(floors) if (round(f.start, 6), round(f.end, 6)) in balconies
    ]
    assert with_balcony == [1, 3, 5]
    (large,) = spans(layout, "balconies", "x", "L")
    firsts = [p for p in letters(layout, "base", "x")][1:3]  # the first B W
    assert large == (round(firsts[0].start, 6), round(firsts[1].end, 6))


def test_section_6_1_delimiters() -> None:
    layout = solve_text(TERRACED.format(bays="W (Q B W)^n"))
    word = [p.symbol for p in letters(layout, "base", "x")]
    assert word[:4] == ["W", "Q", "B", "W"] and word.count("Q") == layout.counters["n"]


GROUPS = """
version: 1
name: groups
canvas: {width: 12.0, height: 7.0}
symbol_defaults: {opaque: true}
symbols: {E: 1.0, W: 1.2, S: 2.6, D: 1.2, G: 3.5, U: 3.5}
counters: {n: {min: 1}, k: {min: 1}}
patterns:
  upper_x: "E (W E)^n"
  ground_x: "S (D S)^k"
  storeys: "G U"
layers:
  - {name: wall, x: upper_x, y: storeys, visible: {y: [U]}}
  - {name: shops, x: ground_x, y: storeys, visible: {y: [G]}, groups: {x: ground}}
  - {name: frames, x: upper_x, y: storeys, visible: {y: [U]}, offset: 0.05}
"""


def test_alignment_groups_keep_their_own_rhythm_and_share_sizes() -> None:
    layout = solve_text(GROUPS)
    upper = set(layout.x.groups["default"].boundaries)
    ground = set(layout.x.groups["ground"].boundaries)
    assert ground - upper  # the ground floor does not follow the upper windows
    assert letters(layout, "wall", "x") == letters(layout, "frames", "x")
    sizes = {
        round(p.end - p.start, 6)
        for layer in ("wall", "shops")
        for p in letters(layout, layer, "x")
        if p.symbol in "E"
    }
    assert len(sizes) == 1


def test_infeasible_spec_exits_with_the_reason() -> None:
    text = EQ8.replace("A: 1, B: 1.5", "A: {size: 1, max: 1.1}, B: {size: 1.5, max: 1.6}")
    text = text.replace("C: 1,", "C: {size: 1, opaque: false},")  # so A B A B A cannot make room
    text = text.replace("canvas: {width: 6", "canvas: {width: 8")  # A B A B A is 6.5 at most
    with pytest.raises(InfeasibleError, match=r"x axis: .*cannot all hold"):
        solve(parse_spec(text))


def test_a_fixed_counter_too_long_for_the_canvas_shrinks_its_letters() -> None:
    """A^40 far longer than the canvas is no proof that nothing fits (SPEC 4: exit 3 only
    when proven): every A shrinks to a fortieth of the canvas, and the user is warned."""
    text = EQ8.replace('base: "A B A B A"', 'base: "A^n"').replace(
        "symbols:", "counters: {n: 40}\nsymbols:"
    )
    layout = solve(parse_spec(text))
    (size,) = {round(p.end - p.start, 6) for p in letters(layout, "base", "x")}
    assert size == pytest.approx(layout.width / 40, abs=1e-6)
    assert any("'A'" in warning and "off its preferred" in warning for warning in layout.warnings)


def test_same_spec_same_layout() -> None:
    first = solve_text(TERRACED.format(bays="W (B W)^n"))
    second = solve_text(TERRACED.format(bays="W (B W)^n"))
    assert first.shapes == second.shapes


def test_the_safety_time_limit_is_reported_as_such_never_as_no_layout() -> None:
    from facadecli.errors import SearchLimitError
    from tests.benchmarks.generated import generated_spec

    text = generated_spec(24, 28).replace("counters:", "solver: {time_limit: 0.000001}\ncounters:")
    with pytest.raises(SearchLimitError, match="time limit") as raised:
        solve(parse_spec(text))
    assert raised.value.exit_code == 4


def test_many_alignment_groups_of_long_words_do_not_exhaust_the_stack() -> None:
    """The exact search recurses a column at a time through every group in turn: 40
    groups of 31-letter words are a path of some 2,500 columns (an internal error before)."""
    letters = " ".join(["A", "B"] * 15 + ["A"])
    layers = "\n".join(f"  - {{name: L{k}, x: row, y: V, groups: {{x: g{k}}}}}" for k in range(40))
    spec = parse_spec(
        f"""
version: 1
name: many-groups
canvas: {{width: 46.0, height: 3}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1.0, B: 2.0, V: 3}}
patterns: {{row: "{letters}"}}
layers:
{layers}
"""
    )
    layout = solve(spec)
    assert layout.x.objective < 1e-9
    assert len([s for s in layout.shapes if s.layer == "L39"]) == 31


def test_a_far_larger_canvas_is_not_called_infeasible() -> None:
    """Two groups sharing a symbol, stretched to three times their words: the closed-form
    sizing misses its equalities by rounding there (sized symbols weigh 10^8 times the
    columns), which once read as a conflict: 'no layout exists'."""
    spec = parse_spec(
        """
version: 1
name: stretched
canvas: {width: 18, height: 3}
symbol_defaults: {opaque: true}
symbols: {a1: 1.0, a2: 2.0, b1: 1.0, b2: 2.0, S: 1.3, T: 1.0, V: 3}
patterns: {p: "a1 S a2 T a1", q: "b1 T b2 T b1"}
layers:
  - {name: P, x: p, y: V, groups: {x: gp}}
  - {name: Q, x: q, y: V, groups: {x: gq}}
"""
    )
    for width in (6.3, 18.0, 40.0):
        layout = solve(retarget(spec, width, 3.0))
        assert abs(max(s.x1 for s in layout.shapes if s.layer == "P") - width) < 1e-6


def test_a_facade_drawn_at_one_tenth_solves_as_at_full_size() -> None:
    """Objectives are in m^2, so "equally good" (SPEC 2.7) is measured against the canvas:
    the terraced house at 1:10 still puts balconies on every odd floor, and its layout is
    the full-size one scaled (an absolute window once made CMP façades on a unit square
    pick worse layouts by their tie-breaks)."""
    full = load_spec(ROOT / "specs" / "terraced-house.yaml")
    data = yaml.safe_load((ROOT / "specs" / "terraced-house.yaml").read_text())
    data["canvas"] = {k: v / 10 for k, v in data["canvas"].items()}
    for name, symbol in data["symbols"].items():
        if isinstance(symbol, dict):
            data["symbols"][name] = {
                k: v / 10 if k in ("size", "min", "max") else v for k, v in symbol.items()
            }
        else:
            data["symbols"][name] = symbol / 10
    small = solve(parse_spec(yaml.safe_dump(data)))
    large = solve(full)
    assert small.y.counters == large.y.counters
    floors = [p for p in letters(large, "base", "y") if p.symbol == "S"]
    balconies = spans(large, "balconies", "y", "Z")
    on = [i + 1 for i, f in enumerate(floors) if (round(f.start, 6), round(f.end, 6)) in balconies]
    assert len(floors) == 5 and on == [1, 3, 5]
    assert small.x.counters == large.x.counters
    for axis in ("x", "y"):
        for name, (_, size) in getattr(large, axis).symbols.items():
            assert getattr(small, axis).symbols[name][1] == pytest.approx(size / 10, abs=1e-5)


@pytest.mark.parametrize("scale", [1.0, 0.1, 0.01])
def test_the_better_layout_wins_at_any_scale(scale: float) -> None:
    """Ten A of 1.03 m deviate less than eleven of 0.936 m (more columns only breaks
    ties); drawn at 1:10 or 1:100 the objectives shrink by the square, and the choice
    must not change."""
    spec = parse_spec(
        textwrap.dedent(
            f"""
            version: 1
            name: scaled
            canvas: {{width: {10.3 * scale:g}, height: {scale:g}}}
            symbol_defaults: {{opaque: true}}
            symbols: {{A: {scale:g}, H: {scale:g}}}
            counters: {{n: {{min: 1}}}}
            patterns: {{row: "A^n"}}
            layers: [{{name: wall, x: row, y: H}}]
            """
        )
    )
    assert solve(spec).x.counters == {"n": 10}


SHARED_COUNTER = """
version: 1
name: shared
canvas: {{width: 12, height: 1}}
symbols: {{A: 1, B: 1.5, C: 2, H: 1}}
counters: {{n: {{min: 1}}}}
patterns: {{first: "{first}", second: "{second}"}}
layers:
  - {{name: a, x: first, y: H}}
  - {{name: b, x: second, y: H}}
"""


@pytest.mark.parametrize(
    ("first", "second"),
    [
        ("A (B A)^n", "C^n A"),  # every word of the first sets n: the second's range narrows
        ("(B^n | C C C)", "A^n"),  # a branch without n agrees with any n: nothing narrows
        ("A^n B^n", "(A | B)^n C"),
    ],
)
def test_candidates_are_those_of_patterns_enumerated_on_their_own(
    first: str, second: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Enumerating a pattern within the range of a counter that the patterns before it have
    fixed leaves the candidates as they were."""
    spec = parse_spec(SHARED_COUNTER.format(first=first, second=second))
    uses = pattern_uses(spec, axis_words(spec, "x"))

    def described() -> list[tuple[object, ...]]:
        return [
            (c.key, c.counters, tuple(e.word for e in c.words.values()))
            for c in generate_candidates(spec, uses, 12.0, 500)
        ]

    narrowed = described()
    monkeypatch.setattr(candidates, "_seen_counters", lambda pattern, found: {})
    assert narrowed and narrowed == described()


def test_a_canvas_shorter_than_every_word_is_proven_infeasible_at_once() -> None:
    """The townhouse's wall (``Z G (K U)^f A``, G at least 3.4 m, U 2.7 m, f >= 1) on a
    1.5 m wall: no word fits, which is proven from the pattern before any search (it
    spent the whole work budget and ended 'a layout may still exist' before)."""
    spec = load_spec(ROOT / "specs" / "townhouse.yaml")
    with pytest.raises(InfeasibleError, match=r"y axis: .*layer wall needs at least 6\.10 m"):
        solve_axis_alternatives(spec, "y", 1.5, safety_clock() + 3600)


def test_a_canvas_longer_than_every_word_is_proven_infeasible_at_once() -> None:
    text = """
version: 1
name: capped
symbol_defaults: {opaque: true}
canvas: {width: 9, height: 3}
symbols: {A: {size: 1, max: 1.5}, B: {size: 1, max: 2}, H: 3}
counters: {k: {min: 1, max: 2}}
patterns: {row: "A (B A)^k | B"}
layers: [{name: wall, x: row, y: H}]
"""
    with pytest.raises(InfeasibleError, match=r"x axis: .*layer wall reaches at most 8\.50 m"):
        solve(parse_spec(text))
    assert solve(retarget(parse_spec(text), 8.5, 3.0)).width == 8.5  # the longest word fits


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_the_length_bounds_admit_every_example(path: Path) -> None:
    """Every example solves at its canvas (the golden tests), so the bounds must admit it."""
    spec = load_spec(path)
    for axis, canvas in (("x", spec.canvas.width), ("y", spec.canvas.height)):
        _check_lengths(spec, axis, canvas)  # raises if it were rejected
