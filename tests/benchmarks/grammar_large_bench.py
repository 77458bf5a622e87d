"""``make bench-large``: ``facade grammar`` on large generated layouts, with a time limit.

Three layouts, drawn from fixed seeds (written to a temporary folder, never kept):
2,000 random rectangles of three labels in a unit square (snapped at the default 0.001);
a grid of 60 x 60 windows with sills (7,200 rectangles); and 10,000 unit cells of two
labels on a 1,000 x 1,000 lattice with ``--snap 0`` (a tiling of about 1,000,000 cells).
Prints, per layout, the wall time of the whole run (reading to writing), its exit code, the
tiling's cells, the rules and the cost (and the greedy grammar's), and whether the time limit
stopped the search.
"""

from __future__ import annotations

import json
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FACADE = Path(sys.executable).with_name("facade")
TIME_LIMIT = 60  # seconds, --time-limit


def random_rectangles() -> dict[str, object]:
    rng = random.Random(1)
    rects = []
    for _ in range(2000):
        x, y, w, h = rng.random(), rng.random(), rng.random() * 0.1, rng.random() * 0.1
        x1, y1 = min(1.0, x + w + 0.001), min(1.0, y + h + 0.001)
        rects.append({"label": rng.choice("abc"), "x0": x, "y0": y, "x1": x1, "y1": y1})
    return {"canvas": {"width": 1, "height": 1}, "rects": rects}


def window_grid() -> dict[str, object]:
    rects = []
    for i in range(60):
        for j in range(60):
            x, y = 1 + 2.0 * i, 1 + 3.0 * j
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.6})
            rects.append({"label": "sill", "x0": x - 0.1, "y0": y - 0.15, "x1": x + 1.3, "y1": y})
    return {"canvas": {"width": 122, "height": 182}, "rects": rects}


def lattice() -> dict[str, object]:
    rng = random.Random(2)
    rects = []
    for _ in range(10_000):
        i, j = rng.randrange(999), rng.randrange(999)
        x0, y0, x1, y1 = i / 1000, j / 1000, (i + 1) / 1000, (j + 1) / 1000  # on the lattice
        rects.append({"label": rng.choice("ab"), "x0": x0, "y0": y0, "x1": x1, "y1": y1})
    return {"canvas": {"width": 1, "height": 1}, "rects": rects}


CASES = [
    ("2,000 random rectangles", random_rectangles, []),
    ("60 x 60 windows with sills", window_grid, []),
    ("10,000 cells on a 1,000 x 1,000 lattice", lattice, ["--snap", "0"]),
]


def main() -> None:
    print(f"facade grammar on large layouts, --time-limit {TIME_LIMIT}")
    with tempfile.TemporaryDirectory() as folder:
        for name, make, options in CASES:
            path = Path(folder) / "layout.json"
            path.write_text(json.dumps(make()))
            out = Path(folder) / "out"
            started = time.perf_counter()
            command = [str(FACADE), "grammar", str(path), "-o", str(out)]
            run = subprocess.run(
                [*command, "--time-limit", str(TIME_LIMIT), *options],
                capture_output=True,
                text=True,
                cwd=ROOT,
            )
            seconds = time.perf_counter() - started
            report = out / "layout.grammar-report.json"
            found = json.loads(report.read_text()) if run.returncode == 0 else {}
            limited = any("time limit" in w for w in found.get("warnings", []))
            print(
                f"{name:40} {seconds:6.1f} s  exit {run.returncode}  "
                f"{found.get('cells', '-')} cells, {found.get('rules', '-')} rules, "
                f"cost {found.get('cost', '-')} (greedy {found.get('greedy_cost', '-')})"
                + ("; stopped by the time limit" if limited else "")
            )


if __name__ == "__main__":
    main()
