"""``make bench-large``: ``facade city`` on a generated town of terraces (minutes to hours).

The town is :func:`facadecli.city.demo.terraces`: blocks of two rows of eight terraced
houses back to back, seeded widths, depths, levels, heights, roof shapes and building
tags, written as GeoJSON to a temporary folder (never kept). ``FACADE_BENCH_N`` buildings
(default 100,000), and a quarter of them first, so the client's memory can be compared at
two sizes; ``FACADE_BENCH_JOBS`` worker processes (default: the machine's CPUs).

Each size runs in a fresh client process (``run_city``, as ``facade city`` calls it).
Printed per size: wall time; CPU seconds per building, all processes (the client's own
and its workers', from ``getrusage``: the workers are the client's children, waited for);
the client's peak resident memory (``ru_maxrss``: the workers' are not in it); the output
sizes. With ``FACADE_BENCH_PROFILE=1`` the smaller size also runs in one process under
cProfile, and the functions taking the most CPU (own and cumulative) are printed.
Figures depend on the machine and its load; they are for docs/benchmarks.md, never
asserted by the tests.
"""

from __future__ import annotations

import cProfile
import json
import os
import pstats
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SEED = 1


def client(manifest: Path, out: Path, jobs: int, figures: Path) -> None:
    """A city run in this process; its resource use written to ``figures``."""
    from facadecli.city.manifest import load_city
    from facadecli.city.run import run_city

    report = run_city(load_city(manifest), out, jobs=jobs)
    own = resource.getrusage(resource.RUSAGE_SELF)
    workers = resource.getrusage(resource.RUSAGE_CHILDREN)
    summary = report["summary"]
    figures.write_text(
        json.dumps(
            {
                "ok": summary["ok"],
                "failed": summary["failed"],
                "party_walls": summary["party_walls"],
                "client_cpu": own.ru_utime + own.ru_stime,
                "workers_cpu": workers.ru_utime + workers.ru_stime,
                "client_peak_mib": own.ru_maxrss / 1024,  # Linux: KiB
                "models": report["models"],
            }
        )
    )


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def measure(count: int, jobs: int, folder: Path) -> dict[str, float]:
    """The town of ``count`` buildings built by a fresh client process; prints its figures."""
    from facadecli.city.demo import write_terraces

    manifest = write_terraces(folder / f"town-{count}", ROOT / "specs", count, SEED)
    out = folder / f"out-{count}"
    figures = folder / f"figures-{count}.json"
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, __file__, "--client", str(manifest), str(out), str(jobs), str(figures)],
        check=True,
    )
    seconds = time.perf_counter() - started
    found = json.loads(figures.read_text())
    cpu = found["client_cpu"] + found["workers_cpu"]
    name = f"terraces-{count}"
    sizes = {
        "buildings/": _size(out / "buildings"),
        f"{name}.glb": _size(out / f"{name}.glb"),
        "tiles/": _size(out / "tiles"),
        f"{name}.city.json": _size(out / f"{name}.city.json"),
        f"{name}.report.json": _size(out / f"{name}.report.json"),
    }
    print(
        f"{count} buildings, -j {jobs}: {found['ok']} built, {found['failed']} failed, "
        f"{found['party_walls']} party walls, {seconds:.1f} s wall"
    )
    print(
        f"  CPU {cpu:.1f} s = {cpu / count:.3f} CPU-s a building "
        f"(client {found['client_cpu']:.1f} s, workers {found['workers_cpu']:.1f} s)"
    )
    print(
        f"  client peak memory {found['client_peak_mib']:.0f} MiB "
        f"({found['client_peak_mib'] * 1024 / count:.1f} KiB a building)"
    )
    print(
        "  outputs: "
        + ", ".join(f"{key} {size / 2**20:.1f} MiB" for key, size in sizes.items() if size)
    )
    return {"peak": found["client_peak_mib"], "cpu": cpu / count}


def profile(count: int, folder: Path) -> None:
    """The town of ``count`` in this one process under cProfile: where a building's CPU goes."""
    from facadecli.city.demo import write_terraces
    from facadecli.city.manifest import load_city
    from facadecli.city.run import run_city

    manifest = write_terraces(folder / f"profiled-{count}", ROOT / "specs", count, SEED)
    city = load_city(manifest)
    profiler = cProfile.Profile(time.process_time)  # CPU, not wall: the machine may be busy
    profiler.enable()
    run_city(city, folder / f"profiled-out-{count}", jobs=1)
    profiler.disable()
    stats = pstats.Stats(profiler)
    total = stats.total_tt  # type: ignore[attr-defined]
    print(f"profile, {count} buildings in one process: {total / count:.3f} CPU-s a building")
    for order in ("tottime", "cumulative"):
        print(f"  top by {order} (seconds a building, share of the run):")
        rows = sorted(
            stats.stats.items(),  # type: ignore[attr-defined]
            key=lambda item: item[1][2] if order == "tottime" else item[1][3],
            reverse=True,
        )
        for (file, line, function), (_, _, own, cumulative, _) in rows[:18]:
            spent = own if order == "tottime" else cumulative
            where = f"{Path(file).name}:{line}({function})"
            print(f"    {spent / count:8.4f}  {spent / total:6.1%}  {where}")


def main() -> None:
    count = int(os.environ.get("FACADE_BENCH_N", "100000"))
    jobs = int(os.environ.get("FACADE_BENCH_JOBS", str(os.cpu_count() or 1)))
    with tempfile.TemporaryDirectory(prefix="city-large-") as scratch:
        folder = Path(scratch)
        small = measure(max(1, count // 4), jobs, folder)
        large = measure(count, jobs, folder)
        print(
            f"client peak memory at {count} / at {max(1, count // 4)} buildings: "
            f"{large['peak'] / small['peak']:.2f} (flat: 1.0; growing with N: 4.0)"
        )
        if os.environ.get("FACADE_BENCH_PROFILE"):
            profile(max(1, count // 4), folder)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--client"]:
        manifest, out, jobs, figures = sys.argv[2:6]
        client(Path(manifest), Path(out), int(jobs), Path(figures))
    else:
        main()
