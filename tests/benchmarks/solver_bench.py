"""``make bench``: the solver on façades with a known perfect layout (benchmarks, not tests).

1. Planted specs, when the project sits beside ``../shared/checks`` (the independent
   generator and layout checker; not part of the project): every seed solved in this
   process; a spec counts as exact when it solves at objective 0 (1e-9) with a layout the
   checker finds clean. Seeds: ``PLANTED=1-2000`` (the default) or ``PLANTED=1-200``.
   The specs' wall-clock safety net (``solver.time_limit``) is put out of reach: the work
   budgets alone decide, so the tally does not depend on the machine's load.
2. The grand hall of the solver issue with 4, 16 and 24 decoration layers.
3. A palace whose layers each have a pattern of their own, as layers and bays grow.

Times are CPU seconds of this process (``time.process_time``), warm (the least of three
solves after a first of the same spec), on whatever machine runs it: the figures in the
docs say which.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli import FacadeError, InfeasibleError, parse_spec, solve  # noqa: E402
from facadecli.errors import SearchLimitError  # noqa: E402
from facadecli.export.report import report  # noqa: E402
from facadecli.spec.model import Spec  # noqa: E402
from tests.benchmarks.distinct import distinct_palace, grand_hall  # noqa: E402

CHECKS = ROOT.parent / "shared" / "checks"
WARM_RUNS = 3


def seeds() -> list[int]:
    first, _, last = os.environ.get("PLANTED", "1-2000").partition("-")
    return list(range(int(first), int(last or first) + 1))


def _without_time_limit(spec: Spec) -> Spec:
    """The spec with its wall-clock safety net out of reach: the work budgets alone decide,
    so the tally is the same on an idle or a loaded machine."""
    return spec.model_copy(update={"solver": spec.solver.model_copy(update={"time_limit": 3600.0})})


def planted() -> None:
    if not (CHECKS / "planted.py").exists():
        print("planted specs: ../shared/checks is not beside the project; skipped")
        return
    sys.path.insert(0, str(CHECKS))
    from check_layout import check  # type: ignore[import-not-found]

    chosen = seeds()
    tally: Counter[str] = Counter()
    seen: dict[str, list[int]] = {}
    unproven = 0
    worst: list[tuple[float, int]] = []
    started = time.process_time()
    with tempfile.TemporaryDirectory() as folder:
        generate = [sys.executable, str(CHECKS / "planted.py"), "gen", folder]
        subprocess.run([*generate, *map(str, chosen)], check=True, capture_output=True)
        for seed in chosen:
            path = Path(folder) / f"planted-{seed}.yaml"
            text = path.read_text()
            at = time.process_time()
            try:
                layout = solve(_without_time_limit(parse_spec(text, str(path))))
            except SearchLimitError:
                tally["exit 4 (search budget)"] += 1
                seen.setdefault("exit 4 (search budget)", []).append(seed)
                continue
            except InfeasibleError:
                tally["exit 3 (infeasible: wrong)"] += 1
                continue
            except FacadeError as error:
                tally[f"error: {type(error).__name__}"] += 1
                continue
            except Exception as error:  # a crash is a finding, not the end of the bench
                tally[f"crash: {type(error).__name__}"] += 1
                seen.setdefault(f"crash: {type(error).__name__}", []).append(seed)
                continue
            worst.append((time.process_time() - at, seed))
            data = report(layout)
            problems = check(yaml.safe_load(text), json.loads(json.dumps(data)))
            objective = layout.x.objective + layout.y.objective
            unproven += not (layout.x.proven and layout.y.proven)
            if problems:
                tally["rules broken"] += 1
            elif objective <= 1e-9:
                tally["exact"] += 1
            else:
                tally["suboptimal"] += 1
                seen.setdefault("suboptimal", []).append(seed)
    total = time.process_time() - started
    worst.sort(reverse=True)
    print(f"planted specs, seeds {chosen[0]}-{chosen[-1]} ({len(chosen)}):")
    for outcome, count in sorted(tally.items(), key=lambda item: -item[1]):
        some = " ".join(map(str, seen.get(outcome, [])[:12]))
        print(f"  {outcome:34} {count:5}  {some}")
    print(f"  {'unproven answers':34} {unproven:5}")
    print(
        f"  CPU total {total:.1f} s; slowest: "
        + ", ".join(f"{s} ({t:.2f} s)" for t, s in worst[:5])
    )


def warm(text: str) -> tuple[str, float]:
    spec = parse_spec(text)
    try:
        solve(spec)
    except FacadeError as error:
        return f"{type(error).__name__}", 0.0
    spent = math.inf
    for _ in range(WARM_RUNS):  # the least of a few: what the solve costs, not the machine's noise
        started = time.process_time()
        layout = solve(spec)
        spent = min(spent, time.process_time() - started)
    proven = layout.x.proven and layout.y.proven
    objective = layout.x.objective + layout.y.objective
    return f"objective {objective:.3g}, {'proven' if proven else 'UNPROVEN'}", spent


def many_layers() -> None:
    print(f"{'grand hall (issue 32)':40} {'warm CPU':>10}  outcome")
    for decorations in (4, 16, 24):
        outcome, spent = warm(grand_hall(decorations))
        print(f"  {decorations + 4:3} layers{'':28} {spent * 1000:8.0f} ms  {outcome}")
    print(f"{'palace, every layer its own pattern':40} {'warm CPU':>10}  outcome")
    for layers in (8, 16, 24, 48):
        for bays in (20, 60, 150):
            outcome, spent = warm(distinct_palace(layers, bays))
            print(f"  {layers:3} layers, {bays:3} bays{'':20} {spent * 1000:8.0f} ms  {outcome}")


if __name__ == "__main__":
    many_layers()
    planted()
