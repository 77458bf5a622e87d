"""The anytime solver: layouts by construction, a bound beside every answer, SPEC 2.7's ties.

Reproducers from the solver issue, each with the answer the SPEC requires, and a family
of generated façades whose perfect layout is known in advance (every symbol at its
preferred size), which the constructions must find with no search."""

from __future__ import annotations

import itertools
import random

import pytest

from facadecli import make_word, parse_spec, solve
from facadecli.export.report import report
from facadecli.solver import columns, construct
from facadecli.solver.alignment import _Row
from facadecli.solver.axis import _AxisProblem
from facadecli.solver.budgets import safety_clock
from facadecli.solver.rows import Row, make_rows
from facadecli.spec.resolve import layer_pattern
from tests.benchmarks.distinct import GRAND_HALL_PERIODS, distinct_palace, grand_hall
from tests.solving import letters, solve_text

THREE_LAYERS = """
version: 1
name: three-layers
canvas: {width: 27.85, height: 3.0}
symbol_defaults: {opaque: true}
symbols:
  E: 1.1
  E2: 0.7
  F: 0.3
  P: 1.15
  W: 2.25
  V1: 1.1
  V3: {size: 1.15, opaque: false}
  V43: 1.1
  T44: {size: 3.4, transparent: true}
  T45: {size: 2.95, transparent: true}
  H: 3.0
counters: {k: {min: 1}, k1: 7}
patterns:
  base: E (W P)^k W (E2 | F F)
  control: {control: s2 (W s4)^k1 W g5, where: {s2: V1, s4: V3}}
  third: V43 (T44)^k T45
layers:
  - {name: base, x: base, y: H}
  - {name: control, x: control, y: H}
  - {name: third, x: third, y: H}
"""


def test_a_perfect_layout_of_three_distinct_layers_is_found_and_proven() -> None:
    """It came out at 155 m2, unproven and unwarned, where a layout at 0 exists."""
    layout = solve_text(THREE_LAYERS)
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.counters["k"] == 7
    assert layout.x.proven and layout.y.proven
    assert report(layout)["proof"]["x"] == {"proven": True, "bound": layout.x.bound}
    assert not any("not proven" in warning for warning in layout.warnings)


FIG_4C = """
version: 1
name: fig-4c
canvas: {width: 93.4, height: 3.0}
symbol_defaults: {opaque: true}
symbols:
  A: 1.4
  D: {size: 0.6, unoccludable: true}
  B: {size: 1.2, attached: true}
  P: 0.4
  H: 3.0
counters: {m: {min: 1}, n: {min: 1}}
patterns:
  base: A (D B D A)^m
  pilasters: {control: a (d b d a)^n, where: {d: P}}
layers:
  - {name: base, x: base, y: H}
  - {name: pilasters, x: pilasters, y: H}
"""


def test_more_columns_break_ties_before_fewer_holes() -> None:
    """The paper's Fig. 4c: every pilaster pair at objective 0, so the one with the most
    columns wins (SPEC 2.7), not one pair (a "fewer holes" rule once came first)."""
    layout = solve_text(FIG_4C)
    assert layout.counters["m"] == 20
    assert layout.counters["n"] == 20
    assert [p.symbol for p in letters(layout, "pilasters", "x")].count("P") == 40


def test_an_exact_fit_beats_more_columns_with_every_size_a_little_off() -> None:
    """SPEC 2.7: objectives equal only up to numerical noise. A balcony layer whose floors
    must stretch with the base (Z tied to S) loses to the layout without it when the floors
    do not fill the canvas at preferred sizes; on a canvas they fill, it wins on columns."""
    text = """
    version: 1
    name: balconies
    canvas: {{width: 5.0, height: {height}}}
    symbol_defaults: {{opaque: true}}
    symbols: {{G: 4.0, S: 3.0, Z: 3.0, T: 2.0, W: 5.0}}
    counters: {{m: {{min: 1}}, p: {{min: 0}}}}
    patterns:
      floors: G S^m T
      balcony_y: {{control: G (z S)^p v, where: {{z: Z}}}}
    layers:
      - {{name: base, x: W, y: floors}}
      - {{name: balconies, x: W, y: balcony_y, offset: 1.0}}
    """
    exact = solve_text(text.format(height=15.0))
    assert exact.counters["m"] == 3 and exact.counters["p"] == 1
    off = solve_text(text.format(height=15.3))
    assert off.counters["p"] == 0


def _planted(seed: int) -> tuple[str, dict[str, int]]:
    """A façade with a planted perfect layout: a base of bays (head, unit^k, tail) and
    layers that repeat every ``period`` bays over it: windows through placeholders (their
    spacers unsized), a transparent spacer pattern, and a reuse of the base."""
    rng = random.Random(seed)
    q = 0.05
    head, wall, pier, tail = (rng.randint(8, 30) * q for _ in range(4))
    k = rng.choice([2, 3, 4, 6, 8, 12])
    period = rng.choice([d for d in (1, 2, 3, 4) if k % d == 0])
    width = round(head + k * (wall + pier) + tail, 6)
    lines = [
        "version: 1",
        f"name: planted-{seed}",
        f"canvas: {{width: {width}, height: 3.0}}",
        "symbol_defaults: {opaque: true}",
        "symbols:",
        f"  E: {head}",
        f"  W: {wall}",
        f"  P: {pier}",
        f"  F: {tail}",
        "  H: 3.0",
        f"  V: {{size: {wall}, unoccludable: true}}",
        f"  T: {{size: {round(period * (wall + pier), 6)}, transparent: true}}",
        f"  N: {{size: {head}, opaque: false}}",
        "counters: {k: {min: 1}, j: {min: 1}, i: {min: 1}}",
        "patterns:",
        "  base: E (W P)^k F",
        "  windows: {control: s (v t)^j u, where: {v: V}}",
        "  spacers: {control: n (T)^i u2, where: {n: N}}",
        "layers:",
        "  - {name: base, x: base, y: H}",
        "  - {name: windows, x: windows, y: H, offset: 0.1}",
        "  - {name: spacers, x: spacers, y: H, offset: 0.2}",
    ]
    return "\n".join(lines) + "\n", {"k": k, "i": k // period}


@pytest.mark.parametrize("seed", range(12))
def test_planted_layouts_are_found_exactly_and_proven(seed: int) -> None:
    text, counters = _planted(seed)
    layout = solve(parse_spec(text, "planted.yaml"))
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9), text
    assert layout.x.proven
    assert layout.counters["k"] == counters["k"]
    windows = [p for p in letters(layout, "windows", "x") if p.symbol == "V"]
    walls = {(round(p.start, 6), round(p.end, 6)) for p in letters(layout, "base", "x")}
    assert windows and all((round(w.start, 6), round(w.end, 6)) in walls for w in windows)


def test_the_relaxation_bounds_every_layout_of_its_candidate() -> None:
    """Rows that fill the canvas alone cannot all keep their preferred sizes: the bound is
    the least squared deviation that lets each fill it, and the layout is no better."""
    layout = solve_text(
        """
        version: 1
        name: tight
        canvas: {width: 10.0, height: 3.0}
        symbol_defaults: {opaque: true}
        symbols: {A: 3.0, B: 2.0, H: 3.0}
        counters: {k: 3}
        patterns: {a: A^k, b: B^4}
        layers:
          - {name: a, x: a, y: H}
          - {name: b, x: b, y: H}
        """
    )
    # A: 3 a = 10, B: 4 b = 10 (they share no symbol): deviation (1/3)^2 + (0.5)^2
    assert layout.x.objective == pytest.approx((1 / 3) ** 2 + 0.5**2, rel=1e-6)
    assert layout.x.proven
    assert report(layout)["proof"]["x"]["bound"] == pytest.approx(layout.x.objective, rel=1e-6)


@pytest.mark.parametrize("decorations", [4, 16, 24])
def test_the_grand_hall_is_perfect_and_proven(decorations: int) -> None:
    """The solver issue's 8-layer front (and with 16 decoration layers): it ended in exit 4
    although every symbol fits at its preferred size at k = 12."""
    layout = solve(parse_spec(grand_hall(decorations), "grand-hall.yaml"))
    assert layout.counters["k"] == 12
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.y.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.x.proven and layout.y.proven
    for i in range(decorations):  # each decoration on its own period of bays
        period = GRAND_HALL_PERIODS[i % len(GRAND_HALL_PERIODS)]
        assert layout.counters[f"kx{i}"] == 12 // period


def test_a_palace_of_distinct_layers_is_perfect_and_proven() -> None:
    layout = solve(parse_spec(distinct_palace(8, 20), "palace.yaml"))
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.y.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.x.proven and layout.y.proven


@pytest.mark.parametrize("bays", [8, 11, 14])
def test_an_alignment_skipping_letters_of_a_row_is_no_crash(bays: int) -> None:
    """A layer whose words end in letters of no length (placeholders the base leaves no
    room for) once crashed with a KeyError in the placing of letters."""
    width = round(1.15 + 4.55 * bays, 6)
    layout = solve_text(
        f"""
        version: 1
        name: skipped
        canvas: {{width: {width}, height: 3.0}}
        symbol_defaults: {{opaque: true}}
        symbols: {{E: 0.2, W: 0.75, P: 0.4, M: 0.7, V4: 1.1, V5: 2.0, V8: 0.2, S: 3.0}}
        counters: {{j: 3, k: {bays}}}
        patterns:
          base: E ((W P)^j M P)^k W E
          layer: {{control: E (g1 g2 g3 s6 g7)^k W s9, where: {{s6: V5 V5 | V4, s9: V8}}}}
        layers:
          - {{name: base, x: base, y: S}}
          - {{name: layer, x: layer, y: S}}
        """
    )
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9)
    placed = letters(layout, "layer", "x")
    assert placed[-1].end == pytest.approx(width)
    assert all(a.end == pytest.approx(b.start) for a, b in itertools.pairwise(placed))


def test_a_symmetric_facade_gets_a_window_over_every_bay() -> None:
    """Windows `e (q p)^j c (q p)^-j e` over `E (W P)^k C (W P)^-k E`: every j fits with
    its placeholders stretched, so the tie-breaks decide, and the layout whose placeholders
    cover least has a window over every one of the 18 bays (once j = 1, two windows)."""
    layout = solve_text(
        """
        version: 1
        name: symmetric
        canvas: {width: 45.6, height: 3.0}
        symbol_defaults: {opaque: true}
        symbols: {E: 0.6, W: 1.6, P: 0.8, C: 1.2, H: 3.0, Q: {size: 1.6, opaque: false}}
        counters: {k: {min: 1}, j: {min: 1}}
        patterns:
          base: E (W P)^k C (W P)^-k E
          windows: {control: e (q p)^j c (q p)^-j e, where: {q: Q}}
        layers:
          - {name: base, x: base, y: H}
          - {name: windows, x: windows, y: H, offset: 0.1}
        """
    )
    assert layout.counters["k"] == 9 and layout.counters["j"] == 9
    windows = [p for p in letters(layout, "windows", "x") if p.symbol == "Q"]
    walls = [p for p in letters(layout, "base", "x") if p.symbol == "W"]
    assert [(w.start, w.end) for w in windows] == [(w.start, w.end) for w in walls]


@pytest.mark.parametrize(
    ("pattern", "width", "counters"),
    [
        ("A^510", 306.0, {}),  # 510 letters: words were cut at 400, and "no layout" said
        ("A (B A)^n", 239.0, {"n": 199}),  # 200 bays: n = 198 was the answer
        ("A A A", 1.0, {}),  # longer than twice the canvas: "no layout" was said
    ],
)
def test_caps_on_words_never_make_no_layout(
    pattern: str, width: float, counters: dict[str, int]
) -> None:
    layout = solve_text(
        f"""
        version: 1
        name: capped
        canvas: {{width: {width}, height: 3.0}}
        symbol_defaults: {{opaque: true}}
        symbols: {{A: {0.6 if width > 1 else 1.0}, B: 0.6, H: 3.0}}
        counters: {{n: {{min: 1}}}}
        patterns: {{row: "{pattern}"}}
        layers: [{{name: base, x: row, y: H}}]
        """
    )
    for name, value in counters.items():
        assert layout.counters[name] == value
    assert layout.x.proven
    assert sum(p.end - p.start for p in letters(layout, "base", "x")) == pytest.approx(width)


def test_a_column_cut_keeps_letters_of_no_length_at_its_end() -> None:
    """An entry `[T] [g]` whose placeholder g has no length, cut inside T: the last part
    ends where the entry does (g kept). Cutting by coordinates alone named the first
    position at the entry's end and dropped g (a KeyError in the placing of letters)."""
    spec = parse_spec(
        """
        version: 1
        name: cut
        canvas: {width: 2.5, height: 3.0}
        symbols: {T: 1.5, H: {size: 3.0, opaque: true}, U: 1.0}
        patterns: {row: {control: T g u, where: {u: U}}}
        layers: [{name: base, x: row, y: H}]
        """,
        "cut.yaml",
    )
    word = make_word(layer_pattern(spec, spec.layers[0], "x"), {})
    (row,) = make_rows(spec, [(0, word)])
    prepared = _Row(row)
    whole = prepared.spanning(0, 4)  # [T] [g], both transparent (control letters)
    assert whole is not None
    parts = columns._cut((whole,), {0: [(0.0, 0), (1.5, 2), (1.5, 4)]}, [prepared], [0, 0.75, 1.5])
    assert [(part[0].start, part[0].end) for part in parts] == [(0, 1), (1, 4)]


def _rows_of(text: str) -> list[Row]:
    """The x rows of a spec's layers, in layer order (one row each)."""
    spec = parse_spec(text, "rows.yaml")
    found = []
    for index, layer in enumerate(spec.layers):
        word = make_word(layer_pattern(spec, layer, "x"), {})
        (row,) = make_rows(spec, [(index, word)])
        found.append(row)
    return found


def test_a_placeholder_reaches_any_boundary_of_the_rows_laid() -> None:
    """`h V h2` over twenty bays and an end bay: V fits only over the end bay, the 21st
    boundary on (the fit once tried a placeholder's twelve nearest ends only)."""
    base, row = _rows_of(
        """
        version: 1
        name: reach
        canvas: {width: 23.5, height: 3.0}
        symbols: {S: 1.0, T: 2.5, E: 1.0, H: {size: 3.0, opaque: true}, V: 2.5, h: {}, h2: {}}
        patterns:
          bays: S S S S S S S S S S S S S S S S S S S S T E
          sign: {control: h v h2, where: {v: V}}
        layers: [{name: base, x: bays, y: H}, {name: sign, x: sign, y: H}]
        """
    )
    sizes = {"S": 1.0, "T": 2.5, "E": 1.0, "V": 2.5}
    fit = construct.fit(row, sizes, construct.boundaries(base, sizes), 23.5)
    assert fit == pytest.approx({"h": 20.0, "h2": 1.0})


def test_a_visible_letter_is_not_fitted_over_an_unoccludable_one_below() -> None:
    """SPEC 2.4: a window of the upper layer skips the bay whose pier is unoccludable."""
    base, pier, window = _rows_of(
        """
        version: 1
        name: unoccludable
        canvas: {width: 4.0, height: 3.0}
        symbols: {S: 1.0, H: {size: 3.0, opaque: true}, U: {size: 1.0, unoccludable: true},
                  V: 1.0, g: {}, g2: {}, h: {}, h2: {}}
        patterns:
          bays: S S S S
          pier: {control: g u g2, where: {u: U}}
          window: {control: h v h2, where: {v: V}}
        layers: [{name: base, x: bays, y: H}, {name: pier, x: pier, y: H},
                 {name: window, x: window, y: H}]
        """
    )
    sizes = {"S": 1.0, "U": 1.0, "V": 1.0}
    points = construct.boundaries(base, sizes)
    laid_pier = {**sizes, "g": 1.0, "g2": 2.0}
    free = construct.fit(window, sizes, points, 4.0)
    assert free == pytest.approx({"h": 1.0, "h2": 2.0})  # nearest: over the pier
    among = construct.laid_for(window, [(base, sizes), (pier, laid_pier)])
    fit = construct.fit(window, sizes, points, 4.0, among)
    assert fit == pytest.approx({"h": 2.0, "h2": 1.0})


def test_a_fitted_placeholder_has_a_length() -> None:
    """`g (h V)^2 E` over bays: the only fit of four bays gives h no length, so that the
    transparent h and the visible V would share a column entry, which no cut can make: no
    fit. With a fifth bay, h takes one."""
    for width, expected in ((5.0, None), (6.0, {"g": 1.0, "h": 1.0})):
        base, row = _rows_of(
            f"""
            version: 1
            name: lengths
            canvas: {{width: {width}, height: 3.0}}
            symbols: {{S: 1.0, E: 1.0, H: {{size: 3.0, opaque: true}}, V: 1.0, g: {{}}, h: {{}}}}
            patterns:
              bays: {"S " * int(width - 1)}E
              windows: {{control: g (h v)^2 e, where: {{v: V, e: E}}}}
            layers: [{{name: base, x: bays, y: H}}, {{name: windows, x: windows, y: H}}]
            """
        )
        sizes = {"S": 1.0, "E": 1.0, "V": 1.0}
        fit = construct.fit(row, sizes, construct.boundaries(base, sizes), width)
        assert fit == (None if expected is None else pytest.approx(expected))


def test_letters_that_touch_within_rounding_leave_their_boundary_free() -> None:
    """Three 0.1 m letters end at 0.30000000000000004, where a letter of another row starts
    at 0.3: the letters touch, so a row may turn from transparent to visible there (joining
    them as overlapping once shut such points, and the fit went on to 0.6)."""
    base, over, row = _rows_of(
        """
        version: 1
        name: rounding
        canvas: {width: 1.0, height: 3.0}
        symbols: {A: 0.1, C: 0.3, D: 0.4, H: {size: 3.0, opaque: true}, V: 0.3,
                  u: {}, w: {}, g: {}, h: {}}
        patterns:
          bays: A A A C D
          over: {control: u c w, where: {c: C}}
          window: {control: g v h, where: {v: V}}
        layers: [{name: base, x: bays, y: H}, {name: over, x: over, y: H},
                 {name: window, x: window, y: H}]
        """
    )
    sizes = {"A": 0.1, "C": 0.3, "D": 0.4, "V": 0.3}
    points = construct.boundaries(base, sizes)
    among = construct.laid_for(row, [(base, sizes), (over, {**sizes, "u": 0.3, "w": 0.4})])
    assert construct.fit(row, sizes, points, 1.0, among) == pytest.approx({"g": 0.3, "h": 0.4})


def _floors_with_alternatives(seed: int, layers: int = 12) -> tuple[str, int]:
    """Floors (ground, storey^f, top) under ``layers`` layers that share the floors'
    counter and each end in an alternative: two short letters (the first, and wrong: they
    end inside the top floor) or one the top floor's height. Every layer's words fit the
    canvas for any count (a placeholder takes the rest), so there are 2^layers options per
    count: joined in the order they are enumerated, the cap on a cluster's options keeps
    only the first count's."""
    rng = random.Random(seed)
    q = 0.05
    ground, storey, top = (rng.randint(a, b) * q for a, b in ((60, 90), (56, 80), (16, 40)))
    floors = rng.randint(3, 9)
    lines = [
        "version: 1",
        f"name: alternatives-{seed}",
        f"canvas: {{width: 6.0, height: {round(ground + floors * storey + top, 6)}}}",
        "symbol_defaults: {opaque: true}",
        "symbols:",
        f"  G: {ground}",
        f"  S: {storey}",
        f"  T: {top}",
        "  X: 6.0",
    ]
    for i in range(layers):
        short = round(top * rng.choice([0.55, 0.6, 0.65, 0.7]), 6)
        lines += [
            f"  A{i}: {{size: {short}, opaque: false}}",
            f"  B{i}: {{size: {top}, opaque: false}}",
        ]
    lines += ["counters: {f: {min: 1}}", "patterns:", "  floors: G (S)^f T"]
    lines += [
        f"  p{i}: {{control: h{i} (S)^f v{i}, where: {{v{i}: A{i} A{i} | B{i}}}}}"
        for i in range(layers)
    ]
    lines += ["layers:", "  - {name: base, x: X, y: floors}"]
    lines += [
        f"  - {{name: l{i}, x: X, y: p{i}, offset: {0.01 * (i + 1):.2f}}}" for i in range(layers)
    ]
    return "\n".join(lines) + "\n", floors


@pytest.mark.parametrize("seed", range(6))
def test_options_of_least_tolerance_are_made_before_any_cap(seed: int) -> None:
    """The planted count is found, exactly, by construction: each layer's right branch
    chosen given the floors' count (before: the first count only, a layout 14-52 m² off
    and unproven)."""
    text, floors = _floors_with_alternatives(seed)
    spec = parse_spec(text, "alternatives.yaml")
    layout = solve(spec)
    assert layout.counters["f"] == floors
    assert layout.y.objective == pytest.approx(0.0, abs=1e-9)
    assert layout.y.proven
    problem = _AxisProblem(spec, "y", spec.canvas.height, safety_clock() + 60, 1)
    assert problem.perfect_built  # no search needed


CONFLICT = """
version: 1
name: cluster-conflict
canvas: {width: 22.65, height: 3.5}
symbol_defaults: {opaque: true}
symbols:
  {symbols}
  E: 1.1
  P: 1.15
  W: 1.55
  S: 3.5
  V2: {size: 1.55, opaque: false}
  V49: {size: 1.55, opaque: false}
  V50: {size: 2.7, opaque: false}
counters: {k: {min: 1}}
patterns:
  base: E (W P)^k W E
  window: {control: g1 (W P)^k s4 g5, where: {s4: V2}}
  # the first branch fits the base alone, not with the window: V50 V50 would cross the
  # window's boundary between its spacer P and its V2
  pair: {control: g47 (g48)^k s51 E, where: {s51: V50 V50 | V49}}
  {patterns}
layers:
  - {name: base, x: base, y: S}
  - {name: window, x: window, y: S, offset: 0.1}
  - {name: pair, x: pair, y: S, offset: 0.2}
  {layers}
"""


def test_words_of_one_cluster_are_fitted_to_each_other_too() -> None:
    """Five layers of two equal alternatives after the pair keep its wrong branch in the
    first 32 options; the fit to the base must see that it crosses the window's row
    (before: exit 4, no layout within the search budget)."""
    extra = range(5)
    text = (
        CONFLICT.replace(
            "{symbols}",
            "\n  ".join(
                f"C{i}: {{size: 1.1, opaque: false}}\n  D{i}: {{size: 1.1, opaque: false}}"
                for i in extra
            ),
        )
        .replace(
            "{patterns}",
            "\n  ".join(
                f"m{i}: {{control: q{i} (W P)^k W r{i}, where: {{r{i}: C{i} | D{i}}}}}"
                for i in extra
            ),
        )
        .replace(
            "{layers}",
            "\n  ".join(
                f"- {{name: m{i}, x: m{i}, y: S, offset: {0.3 + 0.01 * i:.2f}}}" for i in extra
            ),
        )
    )
    spec = parse_spec(text, "conflict.yaml")
    layout = solve(spec)
    assert layout.counters["k"] == 7
    assert layout.x.objective == pytest.approx(0.0, abs=1e-9) and layout.x.proven
    assert [p.symbol for p in letters(layout, "pair", "x") if p.symbol.startswith("V")] == ["V49"]
