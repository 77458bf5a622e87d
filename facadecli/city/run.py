"""``facade city``: every building of a manifest, in worker processes, written atomically.

The unit of work is a building; each writes ``buildings/<id>.glb`` through a temporary
file, so an interrupted run resumes (``--resume``) where it stopped. Results are gathered
in the manifest's order, so the report and the merged model do not depend on scheduling.
"""

from __future__ import annotations

import hashlib
import json
import re
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from facadecli.city.building import AxisCache, build_building
from facadecli.city.footprints import Footprint, read_footprints
from facadecli.city.manifest import City, Roof
from facadecli.export.atomic import write_atomic
from facadecli.export.glb_merge import merge_glb
from facadecli.export.gltf import glb_bytes
from facadecli.spec.model import Spec


@dataclass(frozen=True)
class Task:
    footprint: Footprint
    spec_key: str
    spec: Spec
    height: float
    roof: Roof
    min_facade_width: float
    target: Path
    spec_dir: Path  # the spec's folder: its mesh and texture paths are relative to it


def safe_name(building_id: str) -> str:
    """A file name for an id (OSM ids hold '/'): unsafe characters replaced, and a short
    hash added when anything was replaced, so two ids never share a file."""
    cleaned = re.sub(r"[^A-Za-z0-9._-]", "_", building_id).strip("._") or "building"
    if cleaned != building_id:
        cleaned += "-" + hashlib.sha1(building_id.encode()).hexdigest()[:8]
    return cleaned[:120]


_CACHE: dict[str, AxisCache] = {}  # per worker process: axes solved for earlier buildings


def build(task: Task) -> dict[str, Any]:
    """Build one building and write its glb; never raises (failures are reported)."""
    started = time.perf_counter()
    cache = _CACHE.setdefault("axes", AxisCache())
    try:
        result = build_building(
            task.footprint,
            task.spec,
            task.spec_key,
            task.height,
            task.roof,
            task.min_facade_width,
            cache,
            task.spec_dir,
        )
        write_atomic(task.target, glb_bytes(result.scene))
    except Exception as error:
        return {
            "id": task.footprint.id,
            "status": "failed",
            "error": f"{type(error).__name__}: {error}",
            "time_ms": round((time.perf_counter() - started) * 1000, 1),
        }
    return {
        "id": task.footprint.id,
        "status": "ok",
        "file": f"buildings/{task.target.name}",
        "facades": result.facades,
        "plain_walls": result.plain_walls,
        "height": round(task.height, 3),
        "repaired": task.footprint.repaired,
        "time_ms": round((time.perf_counter() - started) * 1000, 1),
    }


def plan(city: City, footprints: list[Footprint], outdir: Path) -> list[Task]:
    tasks = []
    for footprint in footprints:
        key, roof, height = city.choose(footprint.properties)
        target = outdir / "buildings" / f"{safe_name(footprint.id)}.glb"
        tasks.append(
            Task(
                footprint,
                key,
                city.specs[key],
                height,
                roof,
                city.manifest.defaults.min_facade_width,
                target,
                (city.folder / key).parent,
            )
        )
    return tasks


def run_city(
    city: City,
    outdir: Path,
    jobs: int = 1,
    limit: int | None = None,
    resume: bool = False,
    progress: Callable[[int, int], None] | None = None,
    scheduler: str | None = None,
) -> dict[str, Any]:
    """Build a city; returns the report (also written to ``<name>.report.json``).

    Buildings run in ``jobs`` local worker processes, or, with ``scheduler`` (a Dask
    scheduler's address), on that Dask cluster: the same tasks and the same ``build``
    function either way, so both give the same files."""
    started = time.perf_counter()
    found = read_footprints(city.footprints)
    footprints = list(found.footprints)[: limit if limit is not None else None]
    tasks = plan(city, footprints, outdir)
    results: list[dict[str, Any]] = []
    todo = []
    for task in tasks:
        if resume and task.target.exists():
            results.append(
                {
                    "id": task.footprint.id,
                    "status": "ok",
                    "resumed": True,
                    "file": f"buildings/{task.target.name}",
                }
            )
        else:
            todo.append(task)
    done = len(results)
    mapped = _map(build, todo, jobs) if scheduler is None else _map_dask(build, todo, scheduler)
    for result in mapped:
        results.append(result)
        done += 1
        if progress is not None:
            progress(done, len(tasks))
    order = {task.footprint.id: i for i, task in enumerate(tasks)}
    results.sort(key=lambda r: order[r["id"]])
    merge_glb(
        ((r["id"], outdir / r["file"]) for r in results if r["status"] == "ok"),
        outdir / f"{city.manifest.name}.glb",
    )
    failed = [r for r in results if r["status"] != "ok"]
    report = {
        "version": 1,
        "name": city.manifest.name,
        "crs": found.crs,
        "origin": list(found.origin),
        "buildings": results,
        "rejected": [{"id": r.id, "status": "rejected", "error": r.reason} for r in found.rejected],
        "summary": {
            "buildings": len(tasks),
            "ok": len(results) - len(failed),
            "failed": len(failed) + len(found.rejected),
            "seconds": round(time.perf_counter() - started, 2),
        },
    }
    write_atomic(outdir / f"{city.manifest.name}.report.json", json.dumps(report, indent=2) + "\n")
    return report


def _map_dask(
    function: Callable[[Task], dict[str, Any]], tasks: list[Task], scheduler: str
) -> Iterator[dict[str, Any]]:
    """The tasks on a Dask distributed cluster, results in task order."""
    from distributed import Client

    with Client(scheduler, set_as_default=False) as client:
        futures = client.map(function, tasks, pure=False)
        for future in futures:
            yield future.result()


def _map(
    function: Callable[[Task], dict[str, Any]], tasks: list[Task], jobs: int
) -> Iterator[dict[str, Any]]:
    if jobs <= 1 or len(tasks) < 2:
        for task in tasks:
            yield function(task)
        return
    chunk = max(1, min(16, len(tasks) // (jobs * 4)))
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        yield from pool.map(function, tasks, chunksize=chunk)
