"""``make bench-large``: ``facade city`` on a generated town of terraces (minutes to hours).

The town is :func:`facadecli.city.demo.terraces`: blocks of two rows of eight terraced
houses back to back, seeded widths, depths, levels, heights, roof shapes and building
tags, written as GeoJSON to a temporary folder (never kept). ``FACADE_BENCH_N`` buildings
(default 100,000), and a quarter of them first, so the client's memory can be compared at
two sizes; ``FACADE_BENCH_JOBS`` worker processes (default: the machine's CPUs); 3D Tiles
at the levels of detail ``FACADE_BENCH_LODS`` (default 1,2,3, as ``--3dtiles``; the
buildings are built to the finest of them: ``1`` builds blocks alone, as ``--lod 1``).

Each size runs in a fresh client process (``run_city``, as ``facade city`` calls it).
Printed per size: wall time; CPU seconds per building, all processes (the client's own
and its workers', from ``getrusage``: the workers are the client's children, waited for);
the client's peak resident memory (``ru_maxrss``: the workers' are not in it) and its
resident memory when the first and the last building end; the output sizes (the shared
``textures/`` too) and the whole output folder's a building, the shard folders of
``buildings/`` and the tiles' sizes. With ``FACADE_BENCH_PROFILE=1`` the
smaller size also runs in one process under cProfile, and the functions taking the most
CPU (own and cumulative) are printed. First, the client's memory once the town is read
and planned (no building built) at 1,000, 10,000, 100,000 (up to ``FACADE_BENCH_N``)
buildings, and its slope; ``FACADE_BENCH_PLAN_ONLY=1`` stops there. The town's
footprints are GeoJSON; ``FACADE_BENCH_FORMAT`` writes them as ``osm`` (OSM XML, in
lon/lat, some entrances and multipolygons), ``pbf``, ``gpkg`` or ``shp`` instead
(tests/towns.py), to compare the readers' memory.

With ``FACADE_BENCH_TRACE=1``, where that memory goes (tracemalloc, Python's own
allocations, not GEOS's nor the C libraries'): for planning, what it holds once done
and its peak while planning, a building, and the source lines holding the most; for a
run, what the client's live allocations grow by from its first building built to its
last, and the lines growing most; and the client's resident memory at the last
building before and after the C heap's freed memory is given back to the system
(glibc's ``malloc_trim``): what is freed but not returned, not held. Tracing slows the
client and its bookkeeping is in the resident figures: compare traced runs with traced.

The final step, from the last building to the report written, is traced in every run
(:class:`FinalStep`): the client's resident peak over it (sampled from ``/proc``), and
each writer's (merged models, 3D Tiles, USD, CityJSON, report): its resident peak and
the peak of Python's allocations made while it writes (tracemalloc, from the last
building on). A run whose buildings were all kept by ``--resume`` traces it too.

A run of 100,000 buildings takes about an hour of a quiet 2-core machine. With
``FACADE_BENCH_DIR`` the town and its output are kept in that folder, not a temporary
one, so a run that is stopped (Ctrl-C, ``kill``, the end of a working day) goes on where
it stopped when started again: the client runs ``--resume`` (the buildings already built
are kept, :func:`facadecli.city.run.run_city`), each run of a size is a *segment* whose
CPU, buildings built and memory are appended to ``segments-N.jsonl`` when it ends, and
the figures are over all segments (CPU over the buildings each built; each client's
planning is counted again, so the CPU a building is an upper bound; a segment that was
stopped wrote no figures, so neither its CPU nor its buildings are counted). A size
measured to its end is kept as ``done-N.txt`` (its printed figures) and its output
removed; the next start skips it.
Figures depend on the machine and its load; they are for docs/benchmarks.md, never
asserted by the tests.
"""

from __future__ import annotations

import cProfile
import gc
import json
import os
import pstats
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import tracemalloc
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SEED = 1
TRACED = bool(os.environ.get("FACADE_BENCH_TRACE"))
TOP = 8  # source lines listed by FACADE_BENCH_TRACE
FORMAT = os.environ.get("FACADE_BENCH_FORMAT", "geojson")  # of the footprints (tests/towns.py)


def _trace() -> tracemalloc.Snapshot:
    """What Python holds now (tracemalloc), its garbage collected first."""
    gc.collect()
    return tracemalloc.take_snapshot()


def _grown(before: tracemalloc.Snapshot, after: tracemalloc.Snapshot) -> list[list[Any]]:
    """The source lines whose live allocations grew most between two snapshots: each
    as [file:line, bytes grown, allocations grown]."""
    rows = []
    for stat in after.compare_to(before, "lineno")[:TOP]:
        frame = stat.traceback[0]
        where = f"{Path(frame.filename).name}:{frame.lineno}"
        rows.append([where, stat.size_diff, stat.count_diff])
    return rows


def _returned_mib() -> float | None:
    """The resident memory (MiB) once the C heap's freed memory is given back to the
    system (:func:`facadecli.city.heap.give_back`; None where it cannot be)."""
    from facadecli.city.heap import give_back

    return _resident_mib() if give_back() else None


def _resident_mib() -> float:
    """This process's resident memory now (Linux: /proc; elsewhere its peak so far)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


class FinalStep:
    """The memory of a run's final step, from its last building to its report written
    (the merged models, 3D Tiles, USD stage, CityJSON and report): the client's resident
    peak over it (``/proc``, sampled every SAMPLE seconds by a thread), and, for each of
    the writers of ``CITY_WRITERS`` and the report, the peak of Python's allocations made
    while it writes (tracemalloc, started at the last building: what the writer holds at
    once, not what the run held before it), and its resident peak."""

    SAMPLE = 0.02

    def __init__(self) -> None:
        self.started = False
        self.rows: dict[str, dict[str, float]] = {}
        self.high = self.overall = self.at_start = self.base = 0.0
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._sample, daemon=True)

    def _sample(self) -> None:
        while not self.stopping.wait(self.SAMPLE):
            resident = _resident_mib()
            self.high, self.overall = max(self.high, resident), max(self.overall, resident)

    def watch(self) -> None:
        """Each city writer measured while it writes, and the report with them."""
        from facadecli.city.report import CityReport
        from facadecli.export import CITY_WRITERS

        for name, writer in list(CITY_WRITERS.items()):
            CITY_WRITERS[name] = replace(writer, write=self._measured(name, writer.write))
        CityReport.chunks = self._measured_chunks(CityReport.chunks)  # type: ignore[method-assign]

    def _measured(self, name: str, write: Any) -> Any:
        def measured(built: Any) -> Any:
            if not self.started:  # every building kept by --resume: none ended here
                self.start()
            self._begin()
            try:
                return write(built)
            finally:
                self._end(name)

        return measured

    def _measured_chunks(self, chunks: Any) -> Any:
        final = self

        def measured(report: Any) -> Iterator[str]:
            final._begin()
            try:
                yield from chunks(report)
            finally:
                final._end("report")

        return measured

    def _begin(self) -> None:
        if self.started:
            tracemalloc.reset_peak()
            self.base = tracemalloc.get_traced_memory()[0]
            self.high = _resident_mib()

    def _end(self, name: str) -> None:
        if self.started:
            peak = tracemalloc.get_traced_memory()[1] - self.base
            self.high = max(self.high, _resident_mib())
            self.rows[name] = {"traced_peak": peak, "resident_peak_mib": self.high}
            self.overall = max(self.overall, self.high)

    def start(self) -> None:
        """At the last building: the final step begins."""
        if not tracemalloc.is_tracing():
            tracemalloc.start()
        self.started = True
        self.overall = self.high = _resident_mib()
        self.at_start = self.overall
        self.thread.start()

    def stop(self) -> dict[str, Any]:
        if not self.started:
            return {}
        self.stopping.set()
        self.thread.join()
        self.overall = max(self.overall, _resident_mib())
        return {"at_start_mib": self.at_start, "peak_mib": self.overall, "writers": self.rows}


def client(manifest: Path, out: Path, jobs: int, figures: Path) -> None:
    """A city run in this process; its resource use written to ``figures``: its peak, and
    its resident memory when the first building ends (read, planned, the axes solved) and
    when the last does (before the merged models, CityJSON and report are written)."""
    from facadecli.city.manifest import load_city
    from facadecli.city.run import run_city
    from facadecli.city.tileset import parse_lods

    resident: dict[str, Any] = {}
    built = [0]  # buildings built by this client (not kept from a stopped run)
    traced: list[tracemalloc.Snapshot] = []
    if TRACED:
        tracemalloc.start()

    def progress(done: int, total: int) -> None:
        built[0] += 1
        if built[0] == 1:
            traced.extend([_trace()] if TRACED else [])
            resident["first_built_mib"] = _resident_mib()
        if done == total:
            if TRACED:
                last = _trace()
                resident["traced_grown"] = _grown(traced[0], last)
                resident["traced_grown_total"] = sum(
                    s.size_diff for s in last.compare_to(traced[0], "filename")
                )
                del traced[:], last
            resident["all_built_mib"] = _resident_mib()
            if TRACED:
                resident["all_built_returned_mib"] = _returned_mib()
            final.start()

    lods = parse_lods(os.environ.get("FACADE_BENCH_LODS", "1,2,3"))
    final = FinalStep()
    final.watch()
    resume = out.exists()  # a stopped run's output (FACADE_BENCH_DIR): go on from there
    report = run_city(
        load_city(manifest),
        out,
        jobs=jobs,
        progress=progress,
        lods=lods,
        merged_lod=max(lods),  # FACADE_BENCH_LODS=1: blocks alone, no façade solved
        resume=resume,
    )
    resident["final"] = final.stop()
    own = resource.getrusage(resource.RUSAGE_SELF)
    workers = resource.getrusage(resource.RUSAGE_CHILDREN)
    summary = report["summary"]
    figures.write_text(
        json.dumps(
            {
                "ok": summary["ok"],
                "failed": summary["failed"],
                "party_walls": summary["party_walls"],
                "built": built[0],
                "client_cpu": own.ru_utime + own.ru_stime,
                "workers_cpu": workers.ru_utime + workers.ru_stime,
                "client_peak_mib": own.ru_maxrss / 1024,  # Linux: KiB
                "models": report["models"],
                **resident,
            }
        )
    )


def planning(manifest: Path, figures: Path) -> None:
    """A city read and planned in this process (:func:`facadecli.city.run.planned`, and
    the buildings' hashes for --resume, as a run holds them), no building built: its
    memory and CPU to ``figures``."""
    from facadecli.city.manifest import load_city
    from facadecli.city.resume import building_hashes
    from facadecli.city.run import planned

    city = load_city(manifest)
    before = _resident_mib()  # the imports
    traced: dict[str, Any] = {}
    if TRACED:
        tracemalloc.start()
        first = _trace()
        start = tracemalloc.get_traced_memory()[0]
    cpu = time.process_time()
    ahead = planned(city, manifest.parent / "out")
    hashes = building_hashes(city, ahead.tasks)
    cpu = time.process_time() - cpu
    resident = _resident_mib()
    if TRACED:
        last = _trace()
        now, peak = tracemalloc.get_traced_memory()
        traced = {"held": now - start, "peak": peak - start, "grown": _grown(first, last)}
        traced["returned_mib"] = _returned_mib()
    figures.write_text(
        json.dumps(
            {
                "buildings": len(ahead.tasks),
                "imports_mib": before,
                "planned_mib": resident,
                "peak_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                "cpu": cpu,
                **traced,
            }
        )
    )
    del hashes


def town_of(folder: Path, count: int) -> Path:
    """The manifest of a generated town of ``count`` terraces, its footprints in the
    format FACADE_BENCH_FORMAT (default geojson; osm, pbf, gpkg, shp: tests/towns.py)."""
    from facadecli.city.demo import write_terraces

    manifest = write_terraces(folder, ROOT / "specs", count, SEED)
    if FORMAT == "geojson":
        return manifest
    sys.path.append(str(ROOT))
    from tests.towns import write_town

    (folder / "footprints.geojson").unlink()
    written = write_town(folder, count, FORMAT, SEED)
    text = manifest.read_text().replace("footprints.geojson", written.name)
    manifest.write_text(text)
    return manifest


def measure_planning(counts: list[int], folder: Path) -> None:
    """The client's memory once a town of each size is read and planned, each in a fresh
    process: what it holds through the run, before the buildings' entries."""
    rows = []
    print(f"footprints as {FORMAT}")
    for count in counts:
        manifest = town_of(folder / f"plan-{count}", count)
        figures = folder / f"plan-{count}.json"
        command = [sys.executable, __file__, "--plan", str(manifest), str(figures)]
        subprocess.run(command, check=True)
        rows.append(json.loads(figures.read_text()))
        shutil.rmtree(folder / f"plan-{count}")
    lines = []
    for row in rows:
        grown = row["planned_mib"] - row["imports_mib"]
        lines.append(
            f"planning {row['buildings']} buildings: {row['cpu']:.1f} CPU-s, resident "
            f"{row['imports_mib']:.0f} MiB after the imports, {row['planned_mib']:.0f} MiB "
            f"planned (+{grown * 1024 / row['buildings']:.1f} KiB a building), peak "
            f"{row['peak_mib']:.0f} MiB"
        )
        lines += _traced_lines(row, row["buildings"])
    if len(rows) > 1:
        first, last = rows[0], rows[-1]
        slope = (last["planned_mib"] - first["planned_mib"]) * 1024
        slope /= last["buildings"] - first["buildings"]
        lines.append(f"planning's slope: {slope:.1f} KiB a building")
    (folder / "planning.txt").write_text("\n".join(lines) + "\n")  # a kept folder's next start
    print("\n".join(lines))


def _traced_lines(row: dict[str, Any], count: int) -> list[str]:
    """What FACADE_BENCH_TRACE found (:func:`planning`, :func:`client`), a building."""
    lines = []
    if "held" in row:
        lines.append(
            f"  traced: {row['held'] / count:.0f} B a building held once planned, "
            f"{row['peak'] / count:.0f} B at the peak of planning"
        )
    if "traced_grown_total" in row:
        lines.append(
            f"  traced: {row['traced_grown_total'] / count:+.0f} B a building grown from the "
            "first building built to the last"
        )
    for where, size, allocations in row.get("grown", row.get("traced_grown", [])):
        lines.append(f"    {size / count:+8.1f} B a building  {allocations:+8d}  {where}")
    returned = row.get("returned_mib", row.get("all_built_returned_mib"))
    if returned is not None:
        lines.append(f"  resident {returned:.0f} MiB once the C heap's freed memory is returned")
    return lines


def _final_lines(final: dict[str, Any], count: int) -> list[str]:
    """What :class:`FinalStep` found: the final step's resident peak, each writer's."""
    if not final:
        return []
    lines = [
        f"  final step: resident {final['at_start_mib']:.0f} MiB at its start, peak "
        f"{final['peak_mib']:.0f} MiB (+{final['peak_mib'] - final['at_start_mib']:.0f})"
    ]
    for name, row in final["writers"].items():
        lines.append(
            f"    {name}: traced peak {row['traced_peak'] / 2**20:.1f} MiB "
            f"({row['traced_peak'] / count:.0f} B a building), resident peak "
            f"{row['resident_peak_mib']:.0f} MiB"
        )
    return lines


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def measure(count: int, jobs: int, folder: Path) -> dict[str, float]:
    """The town of ``count`` buildings built by a fresh client process (going on from a
    stopped run's segments in a kept ``folder``); prints its figures."""
    done = folder / f"done-{count}.txt"
    if done.exists():  # measured to its end by an earlier start
        print(done.read_text(), end="")
        return json.loads(done.read_text().splitlines()[-1].removeprefix("# "))
    town = folder / f"town-{count}"
    kept = town / "district.yaml"  # a stopped run's town: the same bytes
    manifest = kept if kept.exists() else town_of(town, count)
    out = folder / f"out-{count}"
    figures = folder / f"figures-{count}.json"
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, __file__, "--client", str(manifest), str(out), str(jobs), str(figures)],
        check=True,
    )
    seconds = time.perf_counter() - started
    found = json.loads(figures.read_text())
    found["wall"] = seconds
    with open(folder / f"segments-{count}.jsonl", "a") as segments:
        segments.write(json.dumps(found) + "\n")
    runs = [
        json.loads(line) for line in (folder / f"segments-{count}.jsonl").read_text().splitlines()
    ]
    built = sum(run["built"] for run in runs) or 1
    cpu = sum(run["client_cpu"] + run["workers_cpu"] for run in runs)
    peak = max(run["client_peak_mib"] for run in runs)
    lines = _figures(count, jobs, out, runs, found)
    lines.append(f"# {json.dumps({'peak': peak, 'cpu': cpu / built})}")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    write_text = done.with_suffix(".tmp")
    write_text.write_text(text)
    write_text.replace(done)
    shutil.rmtree(out)  # tens of GB at 10,000 buildings: not kept for the next size
    return {"peak": peak, "cpu": cpu / built}


def _figures(
    count: int, jobs: int, out: Path, runs: list[dict[str, Any]], last: dict[str, Any]
) -> list[str]:
    """The printed figures of a size: CPU over every segment's buildings, memory per client."""
    built = sum(run["built"] for run in runs) or 1
    client = sum(run["client_cpu"] for run in runs)
    workers = sum(run["workers_cpu"] for run in runs)
    wall = sum(run["wall"] for run in runs)
    peak = max(run["client_peak_mib"] for run in runs)
    name = f"terraces-{count}"
    shards = [folder for folder in (out / "buildings").iterdir() if folder.is_dir()]
    most = max((len(list(folder.iterdir())) for folder in shards), default=0)
    sizes = {
        "buildings/": _size(out / "buildings"),
        f"{name}.glb": _size(out / f"{name}.glb"),
        "tiles/": _size(out / "tiles"),
        "3dtiles/": _size(out / "3dtiles"),
        f"{name}.city.json": _size(out / f"{name}.city.json"),
        f"{name}.report.json": _size(out / f"{name}.report.json"),
        "textures/": _size(out / "textures"),
    }
    segments = f" in {len(runs)} segments (stopped and resumed)" if len(runs) > 1 else ""
    lines = [
        f"{count} buildings, -j {jobs}: {last['ok']} built, {last['failed']} failed, "
        f"{last['party_walls']} party walls, {wall:.1f} s wall{segments}",
        f"  CPU {client + workers:.1f} s = {(client + workers) / built:.3f} CPU-s a building "
        f"(client {client:.1f} s, workers {workers:.1f} s, {built} buildings built)",
        f"  client peak memory {peak:.0f} MiB ({peak * 1024 / count:.1f} KiB a building)",
        f"  client memory: {last.get('first_built_mib', 0):.0f} MiB at the first building "
        f"built, {last.get('all_built_mib', 0):.0f} MiB at the last",
        *_traced_lines(last, count),
        *_final_lines(last.get("final", {}), count),
        "  outputs: "
        + ", ".join(f"{key} {size / 2**20:.1f} MiB" for key, size in sizes.items() if size),
    ]
    on_disk = _size(out)
    lines.append(
        f"  on disk: {on_disk / 2**20:.1f} MiB in all, {on_disk / count / 2**20:.3f} MiB a building"
    )
    lines.append(f"  buildings/: {len(shards)} shard folders, at most {most} files in one")
    if last["models"].get("merged_left_out"):
        lines.append(f"  no merged glb: {last['models']['merged_left_out']}")
    lines += _tile_sizes(out)
    return lines


def _tile_sizes(out: Path) -> list[str]:
    """The sizes of the square tiles (``tiles/``) and of the 3D Tiles at each LOD."""
    kinds: dict[str, list[int]] = {}
    for path in (out / "tiles").glob("*.glb"):
        kinds.setdefault("tiles/", []).append(path.stat().st_size)
    for path in (out / "3dtiles").rglob("*.glb"):
        kinds.setdefault(f"3D Tiles {path.suffixes[-2][1:].upper()}", []).append(
            path.stat().st_size
        )
    lines = []
    for kind, sizes in sorted(kinds.items()):
        sizes.sort()
        lines.append(
            f"  {kind}: {len(sizes)} tiles, median {sizes[len(sizes) // 2] / 2**20:.2f} MiB, "
            f"largest {sizes[-1] / 2**20:.2f} MiB, {sum(sizes) / 2**20:.1f} MiB in all"
        )
    return lines


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
    kept = os.environ.get("FACADE_BENCH_DIR")
    with tempfile.TemporaryDirectory(prefix="city-large-") as scratch:
        folder = Path(kept) if kept else Path(scratch)
        folder.mkdir(parents=True, exist_ok=True)
        sizes = [n for n in (1_000, 10_000, 100_000) if n < count] + [count]
        if (folder / "planning.txt").exists():  # FACADE_BENCH_DIR: measured by an earlier start
            print((folder / "planning.txt").read_text(), end="")
        else:
            measure_planning(sizes, folder)
        if os.environ.get("FACADE_BENCH_PLAN_ONLY"):
            return
        quarter = max(1, count // 4)
        small = measure(quarter, jobs, folder)
        large = measure(count, jobs, folder)
        slope = (large["peak"] - small["peak"]) * 1024 / max(1, count - quarter)
        print(
            f"client peak memory: {small['peak']:.0f} MiB at {quarter} buildings, "
            f"{large['peak']:.0f} MiB at {count}: {large['peak'] / small['peak']:.2f} times "
            f"(flat: 1.0; in proportion to N: 4.0), {slope:.2f} KiB a building more"
        )
        if os.environ.get("FACADE_BENCH_PROFILE"):
            profile(max(1, count // 4), folder)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--plan"]:
        planning(Path(sys.argv[2]), Path(sys.argv[3]))
    elif sys.argv[1:2] == ["--client"]:
        manifest, out, jobs, figures = sys.argv[2:6]
        client(Path(manifest), Path(out), int(jobs), Path(figures))
    else:
        main()
