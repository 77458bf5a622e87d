"""``make bench``: how long the stages take on the examples (benchmarks are not tests).

Prints one line per example and stage with the median of several runs.
"""

from __future__ import annotations

import itertools
import statistics
import time
from collections.abc import Callable
from pathlib import Path

from facadecli import compile_pattern, enumerate_words, load_spec
from facadecli.preview import preview_words

ROOT = Path(__file__).resolve().parents[2]


def median_ms(action: Callable[[], object], runs: int = 7) -> float:
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        action()
        times.append((time.perf_counter() - started) * 1000)
    return statistics.median(times)


def main() -> None:
    print(f"{'example':32} {'load+check':>11} {'words':>9}")
    for path in sorted((ROOT / "specs").glob("*.yaml")):
        spec = load_spec(path)
        load = median_ms(lambda path=path: load_spec(path))
        words = median_ms(lambda spec=spec: preview_words(spec))
        print(f"{path.name:32} {load:9.2f}ms {words:7.2f}ms")
    pattern = compile_pattern("(A | B C)^* (D (E F)^k G)^-m H^+")
    sizes = {name: 0.5 for name in "ABCDEFGH"}
    count = 10_000
    words = enumerate_words(pattern, sizes=sizes, max_length=1e6)
    enumerate_ms = median_ms(lambda: list(itertools.islice(words, count)), runs=1)
    print(f"enumerate {count} words of a nested pattern: {enumerate_ms:.1f} ms")


if __name__ == "__main__":
    main()
