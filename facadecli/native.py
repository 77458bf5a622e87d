"""The compiled inner loops, where this install has them: the one place that decides, per
extension, whether the compiled module or its pure-Python twin runs.

- ``facadecli.grammar._adp`` (``_adp.c``): the grammar search (``facade grammar``); without
  it :mod:`facadecli.grammar.plain` runs the same search, giving the same grammars.
- ``facadecli.solver._exact`` (``_exact.c``): the exact alignment search and the elimination
  of the sizing equalities (every ``facade solve``); without it ``exact._Search`` and
  ``sizing._parametrized_in_python`` run, giving the same layouts.

setup.py builds both when it can and installs without them when there is no C compiler;
the Python twins are some 10-20 times slower. This module imports nothing else.
"""

from __future__ import annotations

try:
    from facadecli.grammar import _adp
except ImportError:  # installed without a C compiler
    _adp = None  # type: ignore[assignment]

try:
    from facadecli.solver import _exact
except ImportError:  # installed without a C compiler
    _exact = None  # type: ignore[assignment]

GRAMMAR_COMPILED: bool = _adp is not None
EXACT_COMPILED: bool = _exact is not None


def describe() -> str:
    """One line on which searches run compiled (for a bug report, or a doctor command)."""

    def which(compiled: bool) -> str:
        return "compiled" if compiled else "pure Python (no C compiler at install)"

    return f"grammar search: {which(GRAMMAR_COMPILED)}; exact search: {which(EXACT_COMPILED)}"


__all__ = ["EXACT_COMPILED", "GRAMMAR_COMPILED", "_adp", "_exact", "describe"]
