"""``facade city --resume`` keeps what the last run built when nothing that decides it
changed (a hash a building), figures and all, and builds the rest; results are taken as
they finish, the outputs stay in the manifest's order."""

from __future__ import annotations

import dataclasses
import json
import shutil
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from facadecli.city.built import feature, feature_file
from facadecli.city.demo import terraces, write_terraces
from facadecli.city.footprints import read_footprints
from facadecli.city.manifest import load_city
from facadecli.city.resume import UNHASHED, building_hash, spec_digests
from facadecli.city.run import Task, _bounded, plan, run_city
from facadecli.export.texture_store import image_uris

ROOT = Path(__file__).resolve().parent.parent
HOUSES = 6  # a row of terraced houses: party walls between them
SEED = 5  # its houses: two apartments (terraced-house.yaml), the rest townhouse.yaml


class Stopped(Exception):
    """A run stopped half-way, as a kill would."""


def _stop_after(count: int) -> Any:
    def progress(done: int, total: int) -> None:
        if done >= count:
            raise Stopped

    return progress


def _entries(report: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """A report's buildings by id, without what differs between runs of the same inputs."""
    return {
        b["id"]: {k: v for k, v in b.items() if k not in ("time_ms", "resumed")}
        for b in report["buildings"]
    }


def _outputs(out: Path) -> dict[str, bytes]:
    """Every file a run wrote, but its report (which holds times)."""
    return {
        str(path.relative_to(out)): path.read_bytes()
        for path in sorted(out.rglob("*"))
        if path.is_file() and ".report." not in path.name
    }


def _town(tmp_path: Path) -> Path:
    specs = tmp_path / "specs"  # a copy: the tests edit it
    specs.mkdir()
    for spec in (ROOT / "specs").glob("*.yaml"):  # every one the demo's manifest may name
        shutil.copy(spec, specs / spec.name)
    return write_terraces(tmp_path / "town", specs, HOUSES, SEED)


def test_a_resumed_run_keeps_every_figure_and_gives_the_same_bytes(tmp_path: Path) -> None:
    city = load_city(_town(tmp_path))
    full = run_city(city, tmp_path / "full", jobs=2)
    assert full["summary"]["ok"] == HOUSES and full["summary"]["party_walls"] >= 2 * (HOUSES - 1)
    with pytest.raises(Stopped):
        run_city(city, tmp_path / "part", jobs=1, progress=_stop_after(3))
    report = run_city(city, tmp_path / "part", jobs=1, resume=True)
    assert sum(1 for b in report["buildings"] if b.get("resumed")) == 3
    assert _entries(report) == _entries(full)  # party walls, plain walls by reason, ...
    assert [b["id"] for b in report["buildings"]] == [b["id"] for b in full["buildings"]]
    assert {k: v for k, v in report["summary"].items() if k != "seconds"} == {
        k: v for k, v in full["summary"].items() if k != "seconds"
    }
    assert _outputs(tmp_path / "part") == _outputs(tmp_path / "full")  # and -j 1 as -j 2
    lines = (tmp_path / "part" / f"{city.manifest.name}.report.jsonl").read_text().splitlines()
    assert sorted(json.loads(line)["id"] for line in lines) == sorted(_entries(full))


def test_a_resumed_run_rebuilds_the_buildings_whose_pictures_are_gone(tmp_path: Path) -> None:
    """The pictures are stored once for the run (``textures/``): a building whose glb
    names a picture no longer there is built again, which writes it again."""
    city = load_city(_town(tmp_path))
    out = tmp_path / "out"
    run_city(city, out, jobs=1)
    before = _outputs(out)
    named: dict[Path, set[str]] = {}  # a picture -> the buildings naming it
    for building in json.loads((out / f"{city.manifest.name}.report.json").read_text())[
        "buildings"
    ]:
        glb = out / building["file"]
        for uri in image_uris(glb):
            named.setdefault((glb.parent / uri).resolve(), set()).add(building["id"])
    assert set(named) == set((out / "textures").iterdir())
    report = run_city(city, out, jobs=1, resume=True)
    assert all(b.get("resumed") for b in report["buildings"])
    picture = min(named, key=lambda p: (len(named[p]), p.name))  # the fewest name it
    assert len(named[picture]) < HOUSES
    picture.unlink()
    report = run_city(city, out, jobs=1, resume=True)
    assert set(_rebuilt(report)) == named[picture]  # those naming it, not the rest
    assert _outputs(out) == before


def _rebuilt(report: dict[str, Any]) -> list[str]:
    return [b["id"] for b in report["buildings"] if not b.get("resumed")]


def test_an_edited_spec_or_tag_rebuilds_exactly_what_it_changes(tmp_path: Path) -> None:
    manifest = _town(tmp_path)
    out = tmp_path / "out"
    run_city(load_city(manifest), out, jobs=1)
    assert _rebuilt(run_city(load_city(manifest), out, jobs=1, resume=True)) == []
    pictures = {p.name for p in (out / "textures").iterdir()}

    spec = tmp_path / "specs" / "terraced-house.yaml"  # the apartments' façade
    text = spec.read_text().replace('color: "#e8e4dc"', 'color: "#d8c4bc"')
    text = text.replace('color: "#b8b5ae", resolution: 256', 'color: "#b8b5ae", resolution: 128')
    spec.write_text(text)  # another colour, and the concrete's pictures at another size
    kinds = {str(f["id"]): f["properties"] for f in terraces(HOUSES, SEED)}
    apartments = [key for key, tags in kinds.items() if tags["building"] == "apartments"]  # type: ignore[index]
    assert 0 < len(apartments) < HOUSES  # the seed gives both kinds
    assert _rebuilt(run_city(load_city(manifest), out, jobs=1, resume=True)) == apartments
    # its concrete's pictures changed: the old ones are gone, as from a fresh run's folder
    run_city(load_city(manifest), tmp_path / "fresh", jobs=1)
    now = {p.name for p in (out / "textures").iterdir()}
    assert now != pictures and now == {p.name for p in (tmp_path / "fresh" / "textures").iterdir()}

    footprints = manifest.parent / "footprints.geojson"
    data = json.loads(footprints.read_text())
    data["features"][1]["properties"]["name"] = "The Old Bakery"  # its CityJSON changes
    footprints.write_text(json.dumps(data))
    report = run_city(load_city(manifest), out, jobs=1, resume=True)
    assert _rebuilt(report) == [data["features"][1]["id"]]
    assert all("party_walls" in b and b["hash"] for b in report["buildings"])


def test_every_field_of_a_task_is_hashed_or_said_why_not(tmp_path: Path) -> None:
    city = load_city(_town(tmp_path))
    found = read_footprints(city.footprints)
    tasks, _ = plan(city, list(found.footprints), tmp_path / "out")
    digest = spec_digests(city)
    names = {f.name for f in dataclasses.fields(Task)}
    assert set(UNHASHED) <= names
    task = tasks[0]
    first = building_hash(task, digest)
    assert first == building_hash(task, spec_digests(city))  # the same on every run
    elsewhere = dataclasses.replace(task, target=tmp_path / "other" / task.target.name)
    assert building_hash(elsewhere, digest) == first  # where the run writes is not hashed
    changed = [
        dataclasses.replace(task, usd=True),
        dataclasses.replace(task, pick=task.pick + 1),
        dataclasses.replace(task, tolerance=task.tolerance + 0.1),
        dataclasses.replace(task, min_facade_width=task.min_facade_width + 1),
        dataclasses.replace(task, roof=task.roof.model_copy(update={"pitch": 44.0})),
        dataclasses.replace(task, shared=None),
        dataclasses.replace(task, footprint=tasks[1].footprint),
    ]
    hashes = {building_hash(t, digest) for t in changed}
    assert len(hashes) == len(changed) and first not in hashes
    assert len({building_hash(t, digest) for t in tasks}) == len(tasks)


def test_results_are_taken_as_they_finish() -> None:
    released = threading.Event()

    def work(batch: list[int]) -> list[int]:
        if batch[0] == 0:  # the first chunk ends only once the second's results are taken
            assert released.wait(timeout=60)
        return [item * 10 for item in batch]

    with ThreadPoolExecutor(max_workers=2) as pool:
        stream = _bounded(lambda batch: pool.submit(work, list(batch)), [0, 1, 2, 3], 2)
        first = [next(stream), next(stream)]  # in order, this would wait for the first
        released.set()
        assert first == [(2, 20), (3, 30)] and list(stream) == [(0, 0), (1, 10)]


def test_kill_9_then_resume_gives_a_fresh_runs_files(tmp_path: Path) -> None:
    manifest = _town(tmp_path)
    out = tmp_path / "killed"
    log = out / f"terraces-{HOUSES}.report.jsonl"
    facade = Path(sys.executable).with_name("facade")
    command = [str(facade), "city", str(manifest), "-o", str(out), "-j", "1"]
    run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while run.poll() is None and not (log.is_file() and log.read_text().count("\n") >= 1):
        time.sleep(0.02)
    run.send_signal(signal.SIGKILL)
    assert run.wait() == -signal.SIGKILL, "the run ended before it was killed"
    done = subprocess.run([*command, "--resume"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    fresh = run_city(load_city(manifest), tmp_path / "fresh", jobs=1)
    report = json.loads((out / f"terraces-{HOUSES}.report.json").read_text())
    assert 1 <= sum(1 for b in report["buildings"] if b.get("resumed")) < HOUSES
    assert _entries(report) == _entries(fresh)
    assert _outputs(out) == _outputs(tmp_path / "fresh")


def test_a_feature_made_again_from_its_volumes_is_the_one_its_worker_wrote(
    tmp_path: Path,
) -> None:
    """A building resumed from a run that wrote no feature file has its CityJSON made from
    its volumes (built.feature): party walls, solids and height as a worker makes them."""
    city = load_city(_town(tmp_path))
    out = tmp_path / "out"
    run_city(city, out, jobs=1)
    tasks, _ = plan(city, list(read_footprints(city.footprints).footprints), out)
    for task in tasks:
        written = json.loads(feature_file(task.target).read_bytes())
        feature_file(task.target).unlink()
        assert feature(task) == written, task.footprint.id
