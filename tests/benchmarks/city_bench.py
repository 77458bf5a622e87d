"""Time `facade city` (make bench): the generated demo district, and OpenStreetMap's Kotka
(2,171 buildings) when ../shared/data/footprints/kotka.geojson is beside the project.

Prints buildings a second, wall clock, for -j 1 and -j 2, and on a Dask LocalCluster of
two single-threaded worker processes (--scheduler). Figures depend on the machine and its
load; they are for the README and notes, never asserted by the tests."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
KOTKA = ROOT.parent / "shared" / "data" / "footprints" / "kotka.geojson"
MANIFEST = """\
version: 1
name: kotka
footprints: {footprints}
defaults:
  facade: {specs}/townhouse.yaml
  height: 9.0
  floor_height: 3.0
  roof: {{type: gable, pitch: 30}}
  min_facade_width: 3.0
rules:
  - when: {{building: apartments}}
    facade: {specs}/terraced-house.yaml
    roof: {{type: flat, parapet: 0.5}}
"""


def run(manifest: Path, where: list[str], out: Path) -> tuple[int, float]:
    """``facade city`` with ``where`` (-j N, or --scheduler ADDRESS): buildings, seconds."""
    facade = Path(sys.executable).parent / "facade"
    started = time.perf_counter()
    done = subprocess.run(
        [str(facade), "city", str(manifest), "-o", str(out), *where],
        capture_output=True,
        text=True,
        check=True,
    )
    seconds = time.perf_counter() - started
    built = int(done.stdout.split(" of ", 1)[0].rsplit("\n", 1)[-1])
    return built, seconds


def main() -> None:
    from facadecli.city.demo import write_demo

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        cities = [("demo district (5 x 5 blocks)", write_demo(folder / "demo", ROOT / "specs", 5))]
        if KOTKA.is_file():
            kotka = folder / "kotka.yaml"
            kotka.write_text(MANIFEST.format(footprints=KOTKA, specs=ROOT / "specs"))
            cities.append(("Kotka, OSM (2,171 buildings)", kotka))
        else:
            print(f"({KOTKA} not found: Kotka skipped)")
        for name, manifest in cities:
            for jobs in (1, 2) if os.cpu_count() != 1 else (1,):
                built, seconds = run(manifest, ["-j", str(jobs)], folder / f"out-{jobs}")
                print(
                    f"city {name}, -j {jobs}: {built} buildings in {seconds:.1f} s "
                    f"({built / seconds:.0f} buildings/s)"
                )
            built, seconds = on_dask(manifest, folder / "out-dask")
            print(
                f"city {name}, Dask (2 workers): {built} buildings in {seconds:.1f} s "
                f"({built / seconds:.0f} buildings/s)"
            )


def on_dask(manifest: Path, out: Path) -> tuple[int, float]:
    """The city on a fresh LocalCluster (two worker processes of one thread): its workers
    start with empty caches, as a cluster's do for a new run."""
    sys.path.insert(0, str(ROOT))
    from tests.dask_cluster import two_workers

    with two_workers() as cluster:
        return run(manifest, ["--scheduler", cluster.scheduler_address], out)


if __name__ == "__main__":
    main()
