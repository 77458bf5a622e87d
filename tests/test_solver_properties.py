"""Property test: every layout the solver returns for a random small spec meets SPEC 2.7."""

from __future__ import annotations

from unittest import mock

from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from facadecli import InfeasibleError, parse_spec, solve
from facadecli.errors import SearchLimitError
from facadecli.export.report import report
from facadecli.solver import axis as axis_module
from facadecli.solver.budgets import safety_clock
from tests.layout_checker import violations

X_PATTERNS = [
    '"A (B A)^k"',
    '"A B A"',
    '"(A B)^* A"',
    '"A C^+ A"',
    '{control: "c e c", where: {c: "C"}}',
    '{control: "y d y", where: {d: "D"}}',
    '{control: "e (d e)^j", where: {d: "D"}}',
    '"(A | B) C (A | B)^-1"',
]
Y_PATTERNS = ['"P Q"', '"P Q^n"', '{control: "g f", where: {g: "P"}}']


@st.composite
def specs(draw: st.DrawFn, bounded: bool = False) -> str:
    """A random small spec; ``bounded``: its symbols have hard ``min``/``max`` too."""
    sizes = {s: draw(st.integers(4, 25)) / 10 for s in "ABCDPQ"}
    lines = [
        "version: 1",
        "name: random",
        f"canvas: {{width: {draw(st.integers(30, 120)) / 10}, "
        f"height: {draw(st.integers(20, 80)) / 10}}}",
        "counters: {k: {min: 1}, j: {min: 1, max: 4}, n: {min: 1}}",
        "symbols:",
    ]
    for name, size in sizes.items():
        qualifiers = {
            "opaque": draw(st.booleans()) if name in "CD" else True,
            "attached": draw(st.booleans()) and draw(st.booleans()),
            "unoccludable": draw(st.booleans()) and draw(st.booleans()),
        }
        flags = ", ".join(f"{k}: {str(v).lower()}" for k, v in qualifiers.items())
        if bounded:
            low, high = draw(st.integers(50, 100)) / 100, draw(st.integers(100, 150)) / 100
            flags += f", min: {round(size * low, 3)}, max: {round(size * high, 3)}"
        lines.append(f"  {name}: {{size: {size}, {flags}}}")
    count = draw(st.integers(1, 3))
    lines.append("patterns:")
    lines.append('  base_x: "A (B A)^k"')
    for index in range(1, count):
        lines.append(f"  x{index}: {draw(st.sampled_from(X_PATTERNS))}")
    lines.append(f"  rows: {draw(st.sampled_from(Y_PATTERNS))}")
    lines.append("layers:")
    lines.append("  - {name: base, x: base_x, y: rows}")
    for index in range(1, count):
        lines.append(f"  - {{name: layer{index}, x: x{index}, y: rows, offset: {index / 10}}}")
    lines.append("solver: {time_limit: 120}")  # the work budget decides, never the clock
    return "\n".join(lines) + "\n"


# 24 letters C in one entry: laid out by rounded ends, their rounding added up to 12 µm
# on the last one, which then differed from its symbol's size (found by this test)
LONG_ENTRY = """version: 1
name: random
canvas: {width: 10.8, height: 2.0}
counters: {k: {min: 1}, j: {min: 1, max: 4}, n: {min: 1}}
symbols:
  A: {size: 0.4, opaque: true, attached: false, unoccludable: false}
  B: {size: 0.6, opaque: true, attached: false, unoccludable: false}
  C: {size: 0.4, opaque: false, attached: false, unoccludable: false}
  D: {size: 0.4, opaque: false, attached: false, unoccludable: false}
  P: {size: 0.4, opaque: true, attached: false, unoccludable: false}
  Q: {size: 0.4, opaque: true, attached: false, unoccludable: false}
patterns:
  base_x: "A (B A)^k"
  x1: "A C^+ A"
  rows: "P Q"
layers:
  - {name: base, x: base_x, y: rows}
  - {name: layer1, x: x1, y: rows, offset: 0.1}
solver: {time_limit: 120}  # the work budget decides, never the clock
"""


# the heuristic aligned layer1 and the base, then layer2 against their columns as one row
# cut at the base's letters: it made room between two cuts of a column, under layer2's C,
# and so split layer1's y around an empty column (its two parts 3.4 and 2.72 m long)
ROOM_INSIDE_A_COLUMN = """version: 1
name: random
canvas: {width: 6.8, height: 2.0}
counters: {k: {min: 1}, j: {min: 1, max: 4}, n: {min: 1}}
symbols:
  A: {size: 0.4, opaque: true, attached: false, unoccludable: false}
  B: {size: 0.5, opaque: true, attached: false, unoccludable: false}
  C: {size: 0.8, opaque: true, attached: false, unoccludable: false}
  D: {size: 0.4, opaque: false, attached: false, unoccludable: false}
  P: {size: 0.4, opaque: true, attached: false, unoccludable: false}
  Q: {size: 0.4, opaque: true, attached: false, unoccludable: false}
patterns:
  base_x: "A (B A)^k"
  x1: {control: "y d y", where: {d: "D"}}
  x2: "A C^+ A"
  rows: "P Q"
layers:
  - {name: base, x: base_x, y: rows}
  - {name: layer1, x: x1, y: rows, offset: 0.1}
  - {name: layer2, x: x2, y: rows, offset: 0.2}
solver: {time_limit: 120}  # the work budget decides, never the clock
"""


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(specs())
@example(LONG_ENTRY)
@example(ROOM_INSIDE_A_COLUMN)
def test_every_solved_layout_meets_the_rules(text: str) -> None:
    spec = parse_spec(text)
    try:
        layout = solve(spec)
    except (InfeasibleError, SearchLimitError):
        return
    assert violations(spec, report(layout)) == [], text


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(specs(bounded=True))
def test_the_length_bounds_reject_no_spec_that_has_a_layout(text: str) -> None:
    """The check before the search (a layer's words all shorter or all longer than the
    canvas) is a proof: on every spec it rejects, the search without it finds nothing."""
    spec = parse_spec(text)
    rejected = []
    for axis, canvas in (("x", spec.canvas.width), ("y", spec.canvas.height)):
        try:
            axis_module._check_lengths(spec, axis, canvas)
        except InfeasibleError:
            rejected.append(axis)
    if not rejected:
        return
    with mock.patch.object(axis_module, "_check_lengths", lambda *_: None):
        for axis in rejected:
            canvas = spec.canvas.width if axis == "x" else spec.canvas.height
            try:
                found = axis_module.solve_axis_alternatives(
                    spec,
                    axis,
                    canvas,
                    safety_clock() + 120,  # type: ignore[arg-type]
                )
            except (InfeasibleError, SearchLimitError):
                continue
            assert not found, text
