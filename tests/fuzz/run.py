"""Fuzz every door of ``facade`` and print a tally: ``make fuzz`` (``--cases 1000`` a door).

The protocol, for whoever adds a door
-------------------------------------
A module ``tests/fuzz/<topic>_doors.py`` exposes::

    DOORS: dict[str, Callable[[int], FuzzCase]]

a door's name (unique across modules: ``city-osm-xml``, ``spec``, ``watch-http``) -> a
function that makes case number ``seed`` of that door. A case is a
:class:`tests.fuzz.FuzzCase`: files to write into a fresh folder, and the ``facade``
arguments to run on them (or a ``call`` for a door that is no command line), the exit
codes that are fine, the outputs a refusal must not leave. A door may instead be
``Callable[[int, Path], list[str]]``: it writes its files into the folder it is given and
returns ``facade``'s arguments, with the defaults of a FuzzCase (exit 0, 2 or 3; outputs
in ``<folder>/out``). The same seed must give the same case on every machine (seed a
``random.Random`` with it; no clock, no global state), so a failure is reproduced with
``--doors NAME --seed N --cases 1``. Keep a case small: thousands run in minutes.

How cases run
-------------
In a worker process (one a door; ``--jobs`` doors at once) that imports facadecli once and
runs case after case in-process (``facade``'s ``main``), each in its own temporary
folder. The runner waits ``--timeout`` seconds (wall clock, generous: the only place a
duration is judged) for each case; past it, the case is a hang and the worker is killed
and replaced. The worker's address space is capped (``--memory-mb``), so a memory bomb
ends as a MemoryError (an internal error) rather than taking the machine down. A case
fails on an exit code outside its ``codes``, "internal error" or a traceback on stderr, a
hang, files left by a refusal or temporary files by a success; the tally counts each by
door (with the worker's peak memory), the failing seeds are listed, and the exit status
is 1 if any.
"""

from __future__ import annotations

import argparse
import importlib
import multiprocessing
import multiprocessing.connection
import resource
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
if str(ROOT) not in sys.path:  # run as a script: tests.fuzz importable
    sys.path.insert(0, str(ROOT))

from tests.fuzz import Door, Outcome, make_case, run_case  # noqa: E402

Doors = dict[str, Door]


def discover(only: set[str] | None = None) -> dict[str, str]:
    """Door name -> its module's name, from every ``tests/fuzz/*_doors.py``. (A door that
    needs a server running, such as ``facade watch``'s HTTP, is in ``SERVER_DOORS`` instead:
    name -> ``run(cases, first_seed) -> exit status``, which prints its own tally.)"""
    found: dict[str, str] = {}
    for path in sorted(HERE.glob("*_doors.py")):
        name = f"tests.fuzz.{path.stem}"
        doors: Doors = getattr(importlib.import_module(name), "DOORS", {})
        for door in doors:
            if door in found:
                raise SystemExit(f"door '{door}' is in {found[door]} and {name}")
            if only is None or door in only:
                found[door] = name
    return found


def _worker(connection: multiprocessing.connection.Connection, memory_mb: int) -> None:
    """Run the cases the runner sends, one at a time: (module, door, seed) -> result."""
    if memory_mb > 0:
        limit = memory_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    while True:
        job = connection.recv()
        if job is None:
            return
        module, door, seed = job
        with tempfile.TemporaryDirectory(prefix="facade-fuzz-") as folder:
            case = make_case(importlib.import_module(module).DOORS[door], seed, Path(folder))
            try:
                outcome = run_case(case, Path(folder))
            except BaseException as error:  # the harness itself, or a case's own call
                outcome = Outcome(-1, True, [], f"harness: {type(error).__name__}: {error}")
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024  # MB (Linux: KB)
        ok = outcome.ok(case)
        connection.send((outcome.code, outcome.internal, outcome.partial, outcome.stderr, ok, peak))


class Worker:
    """A worker process and the pipe to it; replaced after a hang."""

    def __init__(self, memory_mb: int):
        context = multiprocessing.get_context("fork" if sys.platform == "linux" else "spawn")
        self.connection, child = context.Pipe()
        self.process = context.Process(target=_worker, args=(child, memory_mb), daemon=True)
        self.process.start()

    def run(self, job: tuple[str, str, int], timeout: float) -> tuple[Any, ...] | None:
        """The worker's result, or None when it hangs (or dies)."""
        self.connection.send(job)
        if not self.connection.poll(timeout):
            return None
        try:
            result: tuple[Any, ...] = self.connection.recv()
        except EOFError:  # the worker died (killed by the kernel?)
            return None
        return result

    def stop(self, kill: bool = False) -> None:
        if kill:
            self.process.kill()  # this runner's own child, by its handle
        else:
            self.connection.send(None)
        self.process.join(5)


def door_row(
    door: str, module: str, cases: int, first: int, timeout: float, memory_mb: int
) -> dict[str, Any]:
    """Run one door's cases in a worker of its own; its tally row."""
    worker = Worker(memory_mb)
    codes: Counter[int] = Counter()
    row: dict[str, Any] = {"door": door, "cases": 0, "internal": 0, "hangs": 0, "partial": 0}
    row.update(failures=[], peak_mb=0, seconds=0.0)
    started = time.perf_counter()
    for seed in range(first, first + cases):
        result = worker.run((module, door, seed), timeout)
        row["cases"] += 1
        if result is None:
            row["hangs"] += 1
            row["failures"].append((seed, "hang", f"no answer in {timeout:g} s"))
            worker.stop(kill=True)
            worker = Worker(memory_mb)
            continue
        code, internal, partial, stderr, ok, peak = result
        codes[code] += 1
        row["peak_mb"] = max(row["peak_mb"], peak)
        row["internal"] += int(internal)
        row["partial"] += int(bool(partial))
        if not ok:
            why = "internal error" if internal else "partial output" if partial else "exit"
            first_line = (stderr.strip().splitlines() or [""])[-1][:200]
            row["failures"].append((seed, f"{why} {code}", first_line))
    worker.stop()
    row["codes"] = dict(sorted(codes.items()))
    row["seconds"] = round(time.perf_counter() - started, 1)
    return row


def fuzz(
    doors: dict[str, str], cases: int, first: int, timeout: float, memory_mb: int, jobs: int
) -> list[dict[str, Any]]:
    """Run every door's cases, ``jobs`` doors at a time; one tally row a door, printed as
    each door ends."""
    with ThreadPoolExecutor(max(1, jobs)) as pool:
        futures = [
            pool.submit(door_row, door, module, cases, first, timeout, memory_mb)
            for door, module in doors.items()
        ]
        rows = []
        for future in futures:
            rows.append(future.result())
            print(_line(rows[-1]), flush=True)
    return rows


HEADER = (
    f"{'door':<16}{'cases':>7}  {'exit codes':<28}{'internal':>9}{'hangs':>7}{'partial':>9}"
    f"{'peak MB':>9}{'seconds':>9}"
)


def _line(row: dict[str, Any]) -> str:
    codes = " ".join(f"{code}:{count}" for code, count in row["codes"].items())
    return (
        f"{row['door']:<16}{row['cases']:>7}  {codes:<28}{row['internal']:>9}{row['hangs']:>7}"
        f"{row['partial']:>9}{row['peak_mb']:>9}{row['seconds']:>9}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", type=int, default=1000, help="cases a door")
    parser.add_argument("--seed", type=int, default=0, help="the first case's seed")
    parser.add_argument("--doors", default="", help="comma-separated doors (default: all)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds before a hang")
    parser.add_argument("--memory-mb", type=int, default=4000, help="a worker's address space")
    parser.add_argument("--jobs", type=int, default=1, help="doors fuzzed at once")
    parser.add_argument("--list", action="store_true", help="list the doors and stop")
    options = parser.parse_args()
    only = {d.strip() for d in options.doors.split(",") if d.strip()} or None
    doors = discover(only)
    servers = {
        door: run
        for path in sorted(HERE.glob("*_doors.py"))
        for door, run in getattr(
            importlib.import_module(f"tests.fuzz.{path.stem}"), "SERVER_DOORS", {}
        ).items()
        if only is None or door in only
    }
    if options.list:
        print("\n".join([*doors, *servers]) or "no door")
        return 0
    status = 0
    for door, run in servers.items():
        print(f"{door}: ", end="", flush=True)
        status |= run(options.cases, options.seed)
    if not doors:
        return status
    print(HEADER, flush=True)
    rows = fuzz(
        doors, options.cases, options.seed, options.timeout, options.memory_mb, options.jobs
    )
    failures = [(row["door"], *failure) for row in rows for failure in row["failures"]]
    for door, seed, why, line in failures[:50]:
        print(f"FAIL {door} seed {seed}: {why}: {line}")
    if len(failures) > 50:
        print(f"... and {len(failures) - 50} more failures")
    if failures:
        print("reproduce one: tests/fuzz/run.py --doors DOOR --seed SEED --cases 1")
    return 1 if failures or status else 0


if __name__ == "__main__":
    sys.exit(main())
