"""Property test: every layout the solver returns for a random small spec meets SPEC 2.7."""

from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from facadecli import InfeasibleError, parse_spec, solve
from facadecli.errors import SearchLimitError
from facadecli.export.report import report
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
def specs(draw: st.DrawFn) -> str:
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
    lines.append("solver: {time_limit: 5}")
    return "\n".join(lines) + "\n"


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(specs())
def test_every_solved_layout_meets_the_rules(text: str) -> None:
    spec = parse_spec(text)
    try:
        layout = solve(spec)
    except (InfeasibleError, SearchLimitError):
        return
    assert violations(spec, report(layout)) == [], text
