"""Errors a user can act on: where it went wrong, what, and how to fix it.

Every error that reaches the command line is a :class:`FacadeError`; its ``exit_code`` is the
process exit code (SPEC section 4). Nothing else may escape to the user as a traceback.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass


class FacadeError(Exception):
    """Base of every error facadecli reports to a user."""

    exit_code: int = 1


@dataclass(frozen=True)
class Problem:
    """One problem found in an input file, with its position (1-based line and column)."""

    file: str
    line: int | None
    col: int | None
    message: str
    hint: str = ""
    severity: str = "error"  # or "warning": the input is used as it is, but reads wrong

    def __str__(self) -> str:
        where = self.file
        if self.line is not None:
            where += f":{self.line}:{self.col if self.col is not None else 1}"
        text = f"{where}: {self.severity}: {self.message}"
        if self.hint:
            text += f" ({self.hint})"
        return text

    @property
    def sort_key(self) -> tuple[str, int, int]:
        return (self.file, self.line or 0, self.col or 0)


class SpecError(FacadeError):
    """The input is invalid: bad YAML, a bad spec, a bad option (exit code 2).

    Holds every problem found, sorted by position, so a user fixes them in one pass.
    """

    exit_code = 2

    def __init__(self, problems: Iterable[Problem]):
        self.problems: Sequence[Problem] = tuple(
            sorted(dict.fromkeys(problems), key=lambda p: p.sort_key)
        )
        super().__init__("\n".join(str(p) for p in self.problems))

    @classmethod
    def at(
        cls,
        file: str,
        line: int | None,
        col: int | None,
        message: str,
        hint: str = "",
    ) -> SpecError:
        return cls([Problem(file, line, col, message, hint)])


class InfeasibleError(FacadeError):
    """No layout exists for the spec (exit code 3); the message says why."""

    exit_code = 3


class SearchLimitError(FacadeError):
    """The solver stopped before it found any layout (exit code 4): its deterministic work
    budget or the safety time limit ran out. Not a statement about the spec: a layout may
    exist."""

    exit_code = 4


class OutputError(FacadeError):
    """The outputs could not be written (a full disk, a folder removed meanwhile): exit
    code 1, and nothing of the run is left behind."""

    exit_code = 1


class MissingExtraError(FacadeError):
    """A command or option needs an optional part of facadecli that is not installed
    (exit code 2, as for any input the installation cannot take); the message names the
    extra and the command that installs it."""

    exit_code = 2


class FacadeWarning(UserWarning):
    """Something a user should know that stops nothing (``warnings.warn`` from a stage;
    the command line prints it as a warning line, each once a run)."""
