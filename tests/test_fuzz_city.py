"""A few seeded cases of every door of ``facade city`` (``tests/fuzz/city_doors.py``) in
the suite: exit 0 or 2, no internal error, nothing written on a refusal. ``make fuzz``
runs a thousand a door."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.fuzz import run_case
from tests.fuzz.city_doors import DOORS

CASES = 6  # a door, in the suite


@pytest.mark.parametrize("door", sorted(DOORS))
def test_mutated_city_inputs_build_or_are_refused_with_nothing_written(
    tmp_path: Path, door: str
) -> None:
    codes = set()
    for seed in range(CASES):
        case = DOORS[door](seed)
        folder = tmp_path / str(seed)
        folder.mkdir()
        outcome = run_case(case, folder)
        assert outcome.ok(case), (door, seed, outcome)
        codes.add(outcome.code)
    assert codes <= {0, 2, 3}
