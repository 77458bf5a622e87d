"""``make bench``: how long the stages take (benchmarks are not tests).

Prints, per example spec, the median time to load and check it and to solve it (warm: the
first solve of a process also pays for importing cvxpy), then the solve time of the
generated palace façade as layers and bays grow, with the stages of each axis, and the
layouts ``facade vary`` draws for each example.
"""

from __future__ import annotations

import itertools
import os
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli import (  # noqa: E402
    FacadeError,
    compile_pattern,
    enumerate_words,
    load_spec,
    parse_spec,
    solve,
)
from tests.benchmarks.generated import generated_spec  # noqa: E402


def median_ms(action: Callable[[], object], runs: int = 5) -> float:
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        action()
        times.append((time.perf_counter() - started) * 1000)
    return statistics.median(times)


def process_cpu_ms(*args: str) -> float:
    """CPU time (user + system) of one ``facade`` process, in ms: the median of three,
    after a first run that writes the bytecode caches (as an installed package has them:
    pip compiles them at install; PYTHONDONTWRITEBYTECODE, set on some CI machines, would
    make every run compile the sources again)."""
    facade = str(Path(sys.executable).parent / "facade")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run([facade, *args], cwd=ROOT, capture_output=True, check=False, env=env)
    times = []
    for _ in range(3):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([facade, *args], cwd=ROOT, capture_output=True, check=False, env=env)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append((after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime) * 1000)
    return statistics.median(times)


def processes() -> None:
    print(f"{'one facade process':44} {'CPU':>9}")
    for args in (
        ("--version",),
        ("validate", "specs/residential-house.yaml"),
        ("solve", "specs/residential-house.yaml", "-o", "out/bench", "--format", "json"),
        ("solve", "specs/townhouse.yaml", "-o", "out/bench", "--format", "json"),
    ):
        print(f"{' '.join(args)[:44]:44} {process_cpu_ms(*args):7.0f}ms")
    print()


def main() -> None:
    processes()
    solve(load_spec(ROOT / "specs" / "residential-house.yaml"))  # warm up (imports)
    print(f"{'example':28} {'load+check':>11} {'solve':>10}")
    for path in sorted((ROOT / "specs").glob("*.yaml")):
        spec = load_spec(path)
        load = median_ms(lambda path=path: load_spec(path))
        solved = median_ms(lambda spec=spec: solve(spec))
        print(f"{path.name:28} {load:9.2f}ms {solved:8.1f}ms")
    print()
    print(f"{'generated palace':28} {'solve':>10}   stages (ms)")
    for layers, bays in ((6, 7), (12, 7), (24, 7), (24, 14), (24, 28), (24, 40), (24, 60)):
        spec = parse_spec(generated_spec(layers, bays))
        label = f"{layers} layers, {bays} bays ({spec.canvas.width:g} m)"
        try:
            layout = solve(spec)
        except FacadeError as error:
            print(f"{label:28} no layout: exit {error.exit_code} ({str(error)[:60]}...)")
            continue
        solved = median_ms(lambda spec=spec: solve(spec), runs=3)
        layout = solve(spec)  # the stages of a warm solve (the first may load the QP solver)
        stages = " ".join(
            f"{axis.axis}:{'/'.join(f'{ms:.0f}' for ms in axis.timings.values())}"
            for axis in (layout.x, layout.y)
        )
        print(f"{label:28} {solved:8.1f}ms   {stages}  (candidates/alignment/sizing)")
    print()
    pattern = compile_pattern("(A | B C)^* (D (E F)^k G)^-m H^+")
    sizes = {name: 0.5 for name in "ABCDEFGH"}
    count = 10_000
    words = enumerate_words(pattern, sizes=sizes, max_length=1e6)
    enumerate_ms = median_ms(lambda: list(itertools.islice(words, count)), runs=1)
    print(f"enumerate {count} words of a nested pattern: {enumerate_ms:.1f} ms")
    print()
    vary_counts()


def vary_counts() -> None:
    """``facade vary --count 4`` at 10, 14 and 20 m: the layouts each example gets, and how
    many of them are near-best layouts (the rest are drawn proportions)."""
    from facadecli.solve import retarget, solve_variants

    print("vary, 4 asked at 10, 14 and 20 m      layouts  near-best")
    for path in sorted((ROOT / "specs").glob("*.yaml")):
        spec = load_spec(path)
        made = near = 0
        for width in (10.0, 14.0, 20.0):
            layouts = solve_variants(retarget(spec, width), 4)
            made += len(layouts)
            near += sum(layout.spec.symbols == layouts[0].spec.symbols for layout in layouts)
        print(f"{path.name:38} {made:7d} {near:10d}")


if __name__ == "__main__":
    main()
