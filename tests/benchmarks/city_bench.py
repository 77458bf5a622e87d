"""Time `facade city` (make bench): the generated demo district, and OpenStreetMap's Kotka
(2,171 buildings) when ../shared/data/footprints/kotka.geojson is beside the project.

First, CPU seconds a building (``facade city -j 2``, the client's and its workers' CPU,
``getrusage`` of the children: not the machine's load) on two generated towns of
FACADE_BENCH_N buildings each (default 400): a Kotka-like one of detached houses on their
own plots (gabled and hipped, one or two levels, no party walls), and a Helsinki-like one
of dense terraces (:func:`facadecli.city.demo.terraces`: blocks of houses back to back,
party walls on three sides, two to four levels). ``--cpu`` stops there.

Then buildings a second, wall clock, for -j 1 and -j 2, and on a Dask LocalCluster of
two single-threaded worker processes (--scheduler). Figures depend on the machine and its
load; they are for the README and notes, never asserted by the tests."""

from __future__ import annotations

import json
import os
import random
import resource
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


def detached(folder: Path, count: int, seed: int = 1) -> Path:
    """A Kotka-like town: ``count`` detached houses, 8-14 m by 7-10 m, on plots of a
    jittered 25 m grid, one or two levels, gabled or hipped; the demo's manifest."""
    from facadecli.city.demo import MANIFEST as DEMO

    rng = random.Random(seed)
    side = max(1, round(count**0.5))
    features = []
    for k in range(count):
        x, y = 25.0 * (k % side) + rng.uniform(0, 5), 25.0 * (k // side) + rng.uniform(0, 5)
        w, d = rng.uniform(8, 14), rng.uniform(7, 10)
        ring = [[x, y], [x + w, y], [x + w, y + d], [x, y + d], [x, y]]
        tags = {"building": rng.choice(("house", "detached")), "building:levels": rng.choice("12")}
        tags["roof:shape"] = rng.choice(("gabled", "gabled", "hipped"))
        geometry = {"type": "Polygon", "coordinates": [ring]}
        features.append({"type": "Feature", "properties": tags, "geometry": geometry, "id": k})
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}
    folder.mkdir(parents=True, exist_ok=True)
    document = {"type": "FeatureCollection", "crs": crs, "features": features}
    (folder / "footprints.geojson").write_text(json.dumps(document))
    manifest = folder / "district.yaml"
    manifest.write_text(DEMO.format(name=f"detached-{count}", specs=ROOT / "specs", fallback=""))
    return manifest


def cpu(manifest: Path, out: Path, jobs: int = 2) -> tuple[int, float, float]:
    """``facade city -j jobs``: buildings built, CPU seconds of it and its workers, wall s."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    built, seconds = run(manifest, ["-j", str(jobs)], out)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    used = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return built, used, seconds


def cpu_per_building(folder: Path) -> None:
    from facadecli.city.demo import write_terraces

    count = int(os.environ.get("FACADE_BENCH_N", "400"))
    towns = [
        ("Kotka-like (detached houses)", detached(folder / "kotka-like", count)),
        ("Helsinki-like (dense terraces)", write_terraces(folder / "dense", ROOT / "specs", count)),
    ]
    for name, manifest in towns:
        built, used, seconds = cpu(manifest, manifest.parent / "out")
        print(
            f"city {name}, -j 2: {built} buildings, {used / built:.3f} CPU-s a building "
            f"(client and workers; {seconds:.0f} s wall)"
        )


def main() -> None:
    from facadecli.city.demo import write_demo

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        cpu_per_building(folder)
        if "--cpu" in sys.argv[1:]:
            return
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
