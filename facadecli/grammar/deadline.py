"""The time limit of one ``facade grammar`` run, shared by its stages.

``--time-limit`` counts this process's CPU seconds (``clock``: the solver's safety clock,
:func:`facadecli.solver.budgets.safety_clock`) from the start of the extraction (reading
included), not the wall's: a loaded machine does not make it pass sooner. At that
*soft* limit the ADP search stops with the best grammar so far; the search for repeated
regions stops at half of it with those found so far (the grammar then depends on the
machine's speed, and a warning says so). The greedy grammar is always finished, unless the
*hard* limit passes first: ``HARD`` times the limit plus ``GRACE`` seconds (start-up costs,
such as loading the QP solver, do not shrink with the limit). Every stage before the first
grammar (tiling, regularising, building the greedy grammar) checks the hard limit between
steps of its work, and ends the run with exit 4 when it has passed.
"""

from __future__ import annotations

import math

from facadecli.errors import SearchLimitError
from facadecli.solver import budgets

clock = budgets.safety_clock  # the clock of the time limit: this process's CPU seconds
HARD = 2.0  # x the time limit: the run ends (exit 4) when no grammar exists by then
GRACE = 5.0  # seconds added to the hard limit


class Deadline:
    def __init__(self, seconds: float = math.inf, source: str = "layout"):
        self.seconds = seconds
        self.source = source
        self.start = clock()  # CPU seconds
        self.hard = HARD * seconds + GRACE

    def elapsed(self) -> float:
        return clock() - self.start

    def passed(self, share: float = 1.0) -> bool:
        """Whether ``share`` of the time limit has passed (the soft limit at 1)."""
        return self.elapsed() > share * self.seconds

    def check(self, stage: str) -> None:
        """End the run (exit 4) when the hard limit has passed while ``stage`` runs."""
        if self.elapsed() > self.hard:
            raise SearchLimitError(
                f"{self.source}: error: time limit of {self.seconds:g} s passed "
                f"({self.hard:g} s with the grace for a first grammar) while {stage}, before "
                "any grammar was found (give a larger --time-limit, or join nearby edges with "
                "a larger --snap)"
            )
