"""Fuzzing ``facade`` at its doors: the case type every door module makes, and how one case
is run in this process. ``tests/fuzz/run.py`` explains the protocol and runs the doors."""

from __future__ import annotations

import contextlib
import inspect
import io
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

Code = int  # a process exit code


@dataclass(frozen=True)
class FuzzCase:
    """One input at a door. ``files`` (relative path -> bytes) are written into a fresh
    folder, then either ``facade`` runs in-process with ``argv`` (``{dir}`` in an argument
    is replaced by the folder), or ``call(folder)`` runs and returns (exit code, stdout,
    stderr) for a door that is no command line (a server). Exit codes outside ``codes``
    fail the case; with a code outside ``whole`` (a refusal), each of ``outputs`` (paths
    in the folder) must be absent or an empty folder: nothing half-written; after a
    success they hold no temporary file (a name starting with '.' or ending in '.tmp')."""

    files: dict[str, bytes]
    argv: tuple[str, ...] = ()
    call: Callable[[Path], tuple[Code, str, str]] | None = None
    outputs: tuple[str, ...] = ()
    codes: frozenset[Code] = frozenset({0, 2, 3})
    whole: frozenset[Code] = frozenset({0})
    note: str = ""  # what the case is, for a person reading a failure


@dataclass(frozen=True)
class Outcome:
    """What one case did."""

    code: Code
    internal: bool  # "internal error" or a traceback on stderr
    partial: list[str] = field(default_factory=list)  # output files left by a refusal
    stderr: str = ""

    def ok(self, case: FuzzCase) -> bool:
        return self.code in case.codes and not self.internal and not self.partial


Door = Callable[[int], FuzzCase] | Callable[[int, Path], list[str]]


def make_case(door: Door, seed: int, folder: Path) -> FuzzCase:
    """Case ``seed`` of a door: a door of one parameter returns its FuzzCase; a door of two
    writes its files into ``folder`` itself and returns ``facade``'s arguments, its
    outputs under ``folder / "out"``."""
    if len(inspect.signature(door).parameters) >= 2:
        argv = door(seed, folder)  # type: ignore[call-arg]
        return FuzzCase(files={}, argv=tuple(str(a) for a in argv), outputs=("out",))
    return door(seed)  # type: ignore[call-arg,return-value]


def write(case: FuzzCase, folder: Path) -> None:
    for name, content in case.files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)


def facade_in_process(argv: list[str]) -> tuple[Code, str, str]:
    """(exit code, stdout, stderr) of ``facade`` run in this process with ``argv``."""
    from facadecli.cli import main

    out, err = io.StringIO(), io.StringIO()
    saved = sys.argv
    sys.argv = ["facade", *argv]
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            main()
        code = 0
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    finally:
        sys.argv = saved
    return code, out.getvalue(), err.getvalue()


def run_case(case: FuzzCase, folder: Path) -> Outcome:
    """Write the case's files into ``folder`` (fresh) and run it."""
    write(case, folder)
    if case.call is not None:
        code, _, err = case.call(folder)
    else:
        code, _, err = facade_in_process([a.replace("{dir}", str(folder)) for a in case.argv])
    internal = "internal error" in err or "Traceback" in err
    partial = []
    for name in case.outputs:
        path = folder / name
        found = sorted(path.rglob("*")) if path.is_dir() else [path] if path.exists() else []
        if code not in case.whole:  # a refusal writes nothing
            partial += [str(p.relative_to(folder)) for p in found]
        else:  # a success leaves no temporary file
            partial += [
                str(p.relative_to(folder))
                for p in found
                if p.name.startswith(".") or p.name.endswith(".tmp")
            ]
    return Outcome(code, internal, partial, err)
