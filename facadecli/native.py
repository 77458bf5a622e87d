"""The compiled inner loop, where this install has it: the one place that decides whether
the compiled module or its pure-Python twin runs.

- ``facadecli.grammar._adp`` (``_adp.c``): the grammar search (``facade grammar``); without
  it :mod:`facadecli.grammar.plain` runs the same search, giving the same grammars.

setup.py builds it when it can and installs without it when there is no C compiler; the
Python twin is some 10-20 times slower. The solver (``facade solve``) has no compiled part:
it is pure Python everywhere. This module imports nothing else.
"""

from __future__ import annotations

try:
    from facadecli.grammar import _adp
except ImportError:  # installed without a C compiler
    _adp = None  # type: ignore[assignment]

GRAMMAR_COMPILED: bool = _adp is not None


def describe() -> str:
    """One line on what runs compiled (for a bug report, or a doctor command)."""
    grammar = "compiled" if GRAMMAR_COMPILED else "pure Python (no C compiler at install)"
    return f"grammar search: {grammar}; solver: pure Python"


__all__ = ["GRAMMAR_COMPILED", "_adp", "describe"]
