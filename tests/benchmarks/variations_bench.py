"""``make bench``: ``facade grammar --variations`` keeping the input's window sizes and
floor and bay pitch (issue 34, item 4).

On the CMP sample annotations beside the project (``../shared/data/cmp-sample/xml``; never
copied into it; skipped, saying so, when absent), the generated family
(``annotated_family``, seeds 1-24) and its hold-out (seeds 101-124, never tuned on), each
extracted at 15 x 15 m (ADP, 2,000 iterations, seed 0) and derived with ``--variations
3`` at 1x, 0.7x, 1.5x and 2x the width and 1.5x the height. A case is one variation of
one size of a façade whose style has the constraint; per set and per variation rank
(v0, the layout written, and v1-v2, the others):

- ``size``: the style's ``sizes`` constraint of windows kept (90% of windows within +-15%
  of an input window's width and height);
- ``floor``: its ``pitch`` constraint of windows kept (every vertical pitch between rows
  on shared columns within +-15% of one of the input's);
- ``bay``: every horizontal distance between neighbouring windows' centres in a row on
  shared columns within +-15% of one in the input's such rows, or twice one (a window
  left out: a door's bay);
- ``apart``: the least mean displacement between two variations of a size (of 15 m).

``-v`` prints each case that misses. ``--sets cmp,family,holdout`` picks the sets.
"""

from __future__ import annotations

import itertools
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli.grammar.extract import extract_grammar  # noqa: E402
from facadecli.grammar.model import Extraction, Options  # noqa: E402
from facadecli.grammar.pieces import displacement, elements_of  # noqa: E402
from facadecli.grammar.style import (  # noqa: E402
    SIZE_TOLERANCE,
    Constraint,
    Facade,
    facade_of,
    holds,
    shared_rows,
    shown_tiles,
    tiles_of,
)
from facadecli.grammar.tiling import BACKGROUND  # noqa: E402
from facadecli.grammar.variations import derive_variations  # noqa: E402
from tests.benchmarks.annotated_family import written_family  # noqa: E402
from tests.benchmarks.retarget_bench import DATA, SIZE, SIZES  # noqa: E402  (the same sizes)

COUNT = 3  # variations asked for at each size
LABEL = "window"
SETS = {"family": range(1, 25), "holdout": range(101, 125)}


@dataclass
class Tally:
    cases: dict[str, list[int]] = field(default_factory=dict)  # measure+rank -> [kept, of]
    least: list[float] = field(default_factory=list)
    made: int = 0
    asked: int = 0
    seconds: float = 0.0

    def add(self, key: str, kept: bool) -> None:
        counts = self.cases.setdefault(key, [0, 0])
        counts[0] += kept
        counts[1] += 1


def bay_pitches(facade: Facade) -> list[float]:
    """The horizontal distances between neighbouring windows' centres in the rows on shared
    columns (none when no two rows share them)."""
    return [
        (b.x0 + b.x1 - a.x0 - a.x1) / 2
        for row in shared_rows(facade, LABEL)
        for a, b in itertools.pairwise(row)
    ]


def bays_kept(found: Sequence[float], source: Sequence[float]) -> bool:
    return all(
        any(abs(p - k * q) <= SIZE_TOLERANCE * k * q for q in source for k in (1, 2)) for p in found
    )


def constraint(style: Sequence[Constraint], kind: str) -> Constraint | None:
    return next((c for c in style if c.kind == kind and c.label == LABEL), None)


def measure(name: str, extraction: Extraction, tally: Tally, verbose: bool) -> None:
    style = extraction.style
    tiling = extraction.tiling
    sizes = constraint(style, "sizes")
    pitch = constraint(style, "pitch")
    source_bays = bay_pitches(_drawn(extraction))
    for size, (across, up) in SIZES.items():
        width, height = SIZE * across, SIZE * up
        started = time.process_time()
        drawn, _ = derive_variations(
            extraction.grammar, tiling, width, height, "bench", COUNT, 0, style
        )
        tally.seconds += time.process_time() - started
        tally.made += len(drawn)
        tally.asked += COUNT
        moved = [
            displacement(a.pieces, b.pieces) / SIZE for a, b in itertools.combinations(drawn, 2)
        ]
        tally.least += [min(moved)] if moved else []
        for k, variation in enumerate(drawn):
            rank = "v0" if k == 0 else "v1+"
            facade = elements_of(list(variation.pieces), width, height)
            misses = []
            for measure_name, held in (
                ("size", None if sizes is None else holds(sizes, facade)),
                ("floor", None if pitch is None else holds(pitch, facade)),
                ("bay", bays_kept(bay_pitches(facade), source_bays) if source_bays else None),
            ):
                if held is None:
                    continue
                tally.add(f"{measure_name} {rank}", held)
                if not held:
                    misses.append(measure_name)
            if misses and verbose:
                print(
                    f"  {name} {size} v{k} ({variation.retarget or 'grammar'}): "
                    f"misses {', '.join(misses)}; offsets {variation.offsets} "
                    f"shuffle {variation.shuffle} proportions {bool(variation.proportions)}"
                )


def _drawn(extraction: Extraction) -> Facade:
    """The input's elements as its style is found on them: the annotation as drawn."""
    drawn, tiling = extraction.drawn, extraction.tiling
    if drawn is None:
        return facade_of(tiles_of(tiling), tiling.xs[-1], tiling.ys[-1], BACKGROUND)
    tiles = shown_tiles(drawn.rects, drawn.width, drawn.height)
    return facade_of(tiles, drawn.width, drawn.height, BACKGROUND)


def report(title: str, tally: Tally) -> None:
    print(
        f"{title}: {tally.made} of {tally.asked} variations made, "
        f"CPU {tally.seconds / max(tally.asked // COUNT, 1):.2f} s a size"
    )
    for key in sorted(tally.cases):
        kept, of = tally.cases[key]
        print(f"  {key:10} kept {kept} of {of} ({kept / of:.1%})")
    for measure_name in ("size", "floor", "bay"):
        kept = sum(v[0] for k, v in tally.cases.items() if k.startswith(measure_name + " "))
        of = sum(v[1] for k, v in tally.cases.items() if k.startswith(measure_name + " "))
        if of:
            print(f"  {measure_name:10} all ranks: {kept} of {of} ({kept / of:.1%})")
    if tally.least:
        print(
            f"  least displacement between two variations of a size: "
            f"min {min(tally.least):.2%}, median {statistics.median(tally.least):.2%} of 15 m"
        )


def run(paths: list[Path], title: str, verbose: bool) -> None:
    tally = Tally()
    for path in paths:
        extraction = extract_grammar(path, Options(size=(SIZE, SIZE)))
        measure(path.stem, extraction, tally, verbose)
        if verbose:  # the tallies so far, a line a façade
            so_far = ", ".join(f"{k} {v[0]}/{v[1]}" for k, v in sorted(tally.cases.items()))
            print(f"  after {path.stem}: {so_far}", flush=True)
    report(title, tally)


def main() -> None:
    verbose = "-v" in sys.argv
    sets = ["cmp", "family", "holdout"]
    if "--sets" in sys.argv:
        sets = sys.argv[sys.argv.index("--sets") + 1].split(",")
    seeds = dict(SETS)
    if "--seeds" in sys.argv:  # A-B: the generated sets' seeds limited to these
        first, _, last = sys.argv[sys.argv.index("--seeds") + 1].partition("-")
        wanted = range(int(first), int(last or first) + 1)
        seeds = {
            k: range(max(v[0], wanted[0]), min(v[-1], wanted[-1]) + 1) for k, v in SETS.items()
        }
    if "cmp" in sets:
        files = sorted(DATA.glob("*.xml")) if DATA.is_dir() else []
        if files:
            run(files, "CMP samples", verbose)
        else:
            print(f"variations on CMP skipped: no CMP annotations in {DATA}")
    with tempfile.TemporaryDirectory() as folder:
        for name in (s for s in sets if s in SETS and seeds[s]):
            chosen = seeds[name]
            paths = written_family(Path(folder), chosen)
            run(paths, f"generated {name} (seeds {chosen[0]}-{chosen[-1]})", verbose)


if __name__ == "__main__":
    main()
