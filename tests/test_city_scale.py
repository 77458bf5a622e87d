"""``facade city`` at any size: the buildings' files spread over shard folders, the merged
glb and the report written without holding every building, the merged glb left out
(with why) past its cap. Sizes here are small; ``make bench-large`` measures the large."""

from __future__ import annotations

import dataclasses
import errno
import gc
import json
import random
import subprocess
import sys
import tracemalloc
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import shapely
import trimesh

import facadecli.city.tiles as tiles_module
from facadecli.city.built import BuiltCity
from facadecli.city.demo import write_terraces
from facadecli.city.folders import SHARD, SHARDS, building_file, safe_name, shard
from facadecli.city.heap import give_back
from facadecli.city.manifest import load_city
from facadecli.city.packed import Packed, Picked, Points
from facadecli.city.report import CityReport, Entries, Summary, Tally, report_chunks
from facadecli.city.resume import building_hash, building_hashes, recorded, spec_digests
from facadecli.city.run import planned, run_city
from facadecli.export import CITY_WRITERS, CityWriter
from facadecli.export.glb_merge import merge_glb, read_glb
from tests.running import facade
from tests.test_city_inputs import city, square, town

ROOT = Path(__file__).resolve().parents[1]


def test_a_buildings_file_is_in_a_shard_named_by_a_hash_of_its_id() -> None:
    # the rule pinned: a change of it moves every building of every run (--resume rebuilds)
    assert str(building_file("way/1")) == f"buildings/{shard('way/1')}/{safe_name('way/1')}.glb"
    assert [shard(i) for i in ("a", "way/1", "b0")] == ["ca", "5c", "c0"]
    assert str(building_file("a", ".usda")) == "buildings/ca/a.usda"
    ids = [f"way/{n}" for n in range(20_000)]
    counts = Counter(shard(i) for i in ids)
    assert len(counts) == SHARDS and all(SHARD.fullmatch(name) for name in counts)
    mean = len(ids) / SHARDS
    assert max(counts.values()) < 1.5 * mean and min(counts.values()) > 0.5 * mean


def test_a_run_writes_every_building_in_its_shard_and_the_report_says_where(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    ids = [f"h{i}" for i in range(6)]
    manifest = town(tmp_path, [square(i, x=12.0 * k) for k, i in enumerate(ids)])
    code, _, err = city(capsys, manifest, "--usd")
    assert code == 0, err
    out = tmp_path / "out"
    report = json.loads((out / "town.report.json").read_text())
    assert [b["file"] for b in report["buildings"]] == [str(building_file(i)) for i in ids]
    files = sorted(p.relative_to(out).as_posix() for p in (out / "buildings").rglob("*.*"))
    expected = [str(building_file(i, suffix)) for i in ids for suffix in (".glb", ".usda")]
    features = [str(building_file(i, ".city.jsonl")) for i in ids]
    assert files == sorted(expected + features)
    assert not [p for p in (out / "buildings").iterdir() if p.is_file()]  # none at the top
    stage = (out / "town.usda").read_text()
    assert all(f"@./{building_file(i, '.usda')}@" in stage for i in ids)


def test_resume_rebuilds_into_shards_what_a_run_before_them_left_flat(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A folder of a run before the shards (``buildings/<id>.glb``, the report's ``file``
    naming it): nothing of it is taken for a sharded building; every building is built
    again into its shard, and the files are those of a run from scratch."""
    manifest = town(tmp_path, [square(f"h{i}", x=12.0 * i) for i in range(3)])
    assert city(capsys, manifest)[0] == 0
    out = tmp_path / "out"
    fresh = {p.relative_to(out): p.read_bytes() for p in (out / "buildings").rglob("*.*")}
    log = out / "town.report.jsonl"
    entries = [json.loads(line) for line in log.read_text().splitlines()]
    for entry in entries:  # as a run before the shards left them
        path = out / entry["file"]
        flat = out / "buildings" / path.name
        path.rename(flat)
        path.with_suffix(".city.jsonl").rename(flat.with_suffix(".city.jsonl"))
        path.parent.rmdir()
        entry["file"] = f"buildings/{path.name}"
    log.write_text("".join(json.dumps(entry) + "\n" for entry in entries))
    code, _, err = city(capsys, manifest, "--resume")
    assert code == 0, err
    report = json.loads((out / "town.report.json").read_text())
    assert not any(b.get("resumed") for b in report["buildings"])
    for path, content in fresh.items():
        assert (out / path).read_bytes() == content


def test_a_run_past_the_merged_cap_writes_tiles_and_says_why(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    manifest = town(tmp_path, [square(f"h{i}", x=12.0 * i) for i in range(4)])
    out = tmp_path / "out"
    assert city(capsys, manifest)[0] == 0
    assert (out / "town.glb").is_file()  # 4 buildings: merged
    monkeypatch.setattr(tiles_module, "MERGED_BUILDINGS_MAX", 3)
    code, said, err = city(capsys, manifest, "--resume")
    assert code == 0, err
    assert f"{out}: no merged town.glb: 4 buildings, more than a single glb" in err
    assert "--3dtiles" in err and f"-> {out}/town.tiles.json" in said
    assert not (out / "town.glb").exists()  # the smaller run's, not left to mislead
    models = json.loads((out / "town.report.json").read_text())["models"]
    assert models["merged"] is None and "MERGED_BUILDINGS_MAX" in models["merged_left_out"]
    index = json.loads((out / "town.tiles.json").read_text())
    assert sum(tile["buildings"] for tile in index["tiles"]) == 4
    for tile in index["tiles"]:
        document, _ = read_glb((out / tile["file"]).read_bytes())
        assert len(document["scenes"][0]["nodes"]) == tile["buildings"]
    streamed = tmp_path / "streamed"  # with 3D Tiles, they are the way in: no square tiles
    code, said, err = facade(capsys, "city", manifest, "-o", streamed, "-j", "1", "--3dtiles")
    assert code == 0, err
    assert "4 buildings, more than a single glb" in err and "open 3dtiles/tileset.json" in err
    assert not (streamed / "town.glb").exists() and not (streamed / "tiles").exists()
    assert said.rstrip().endswith(f"{streamed}/town.report.json, {streamed}/3dtiles/tileset.json")


ENTRIES: list[dict[str, Any]] = [
    {"id": "a", "status": "ok", "plain": {"party": 2, "too_short": 1}, "party_walls": 2},
    {"id": "b/é", "status": "failed", "error": 'x "y"\nz', "list": [], "empty": {}},
    {"id": "c", "status": "ok", "height": 7.25, "nested": [[1, 2], {"k": None}], "plain": {}},
]


@pytest.mark.parametrize("count", [0, 1, 3])
def test_the_report_written_a_building_at_a_time_is_the_whole_document(count: int) -> None:
    entries = Entries(count)
    tally = Tally()
    for index in reversed(range(count)):  # as buildings end: in any order
        entries.put(index, ENTRIES[index])
        tally.add(ENTRIES[index])
    assert list(entries) == ENTRIES[:count] and entries[-1:] == ENTRIES[count - 1 : count]
    report = {"version": 1, "buildings": entries, "rejected": [], "summary": {"ok": tally.ok}}
    whole = json.dumps({**report, "buildings": ENTRIES[:count]}, indent=2) + "\n"
    assert "".join(report_chunks(report, "buildings", entries)) == whole
    assert tally.ok == sum(1 for e in ENTRIES[:count] if e["status"] == "ok")
    assert tally.plain_by_reason()["party"] == (2 if count else 0)


def _parts(folder: Path, count: int) -> list[tuple[str, Path]]:
    """``count`` small glbs, each of three meshes (a building's façade, roof and walls)."""
    folder.mkdir()
    parts = []
    for i in range(count):
        scene = trimesh.Scene()
        for k in range(3):
            box = trimesh.creation.box((1.0 + i % 7, 2.0 + k, 3.0))
            scene.add_geometry(box, node_name=f"n{k}", geom_name=f"g{k}")
        path = folder / f"b{i}.glb"
        path.write_bytes(scene.export(file_type="glb"))
        parts.append((f"b{i}", path))
    return parts


def test_merging_holds_what_one_building_needs_not_every_building(tmp_path: Path) -> None:
    """The merged glb's JSON grows with every building merged; the merge spools it to disk
    as it grows, so merging eight times the buildings takes no more memory (tracemalloc's
    peak of Python's allocations; holding the JSON took about 17 KB a building here)."""
    few = _parts(tmp_path / "few", 40)
    many = few * 8  # the same files again under other names: 320 buildings
    many = [(f"{name}-{k}", path) for k, (name, path) in enumerate(many)]
    peaks = []
    for parts, target in ((few, tmp_path / "few.glb"), (many, tmp_path / "many.glb")):
        tracemalloc.start()
        merge_glb(parts, target)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert peaks[1] < peaks[0] * 1.5, peaks
    document, binary = read_glb((tmp_path / "many.glb").read_bytes())
    assert [document["nodes"][n]["name"] for n in document["scenes"][0]["nodes"]] == [
        name for name, _ in many
    ]
    assert len(document["meshes"]) == 3 * len(many)
    merged = trimesh.load(tmp_path / "many.glb", force="scene")
    assert len(merged.geometry) == 3 * len(many)
    assert document["buffers"] == [{"byteLength": len(binary)}]


def test_the_report_is_a_typed_object_read_as_its_json_document(tmp_path: Path) -> None:
    """What a run returns is a :class:`CityReport` (its summary a :class:`Summary`), its
    buildings held as lines (:class:`Entries`); read as a mapping it is the document on
    disk, key for key and in order (but the times, null on disk without --timings)."""
    manifest = town(tmp_path, [square(f"h{i}", x=12.0 * i) for i in range(3)])
    report = run_city(load_city(manifest), tmp_path / "out")
    assert isinstance(report, CityReport) and isinstance(report.summary, Summary)
    assert isinstance(report.buildings, Entries) and report.summary.ok == 3
    on_disk = json.loads((tmp_path / "out" / "town.report.json").read_text())
    assert list(on_disk) == list(report) == [
        "version", "name", "crs", "origin", "georeference", "buildings", "rejected",
        "warnings", "replaced", "models", "summary",
    ]  # fmt: skip
    untimed = [{**entry, "time_ms": None} for entry in report["buildings"]]  # no --timings
    summary = {**dataclasses.asdict(report.summary), "seconds": None}
    assert on_disk == {**report, "buildings": untimed, "summary": summary}


def test_a_city_is_ended_by_the_writers_of_the_registry(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The merged model, 3D Tiles, USD stage, CityJSON and land cover are written by
    CITY_WRITERS, in that order; a writer the disk refuses is exit 1 naming its output,
    the buildings kept."""
    manifest = town(tmp_path, [square(f"h{i}", x=12.0 * i) for i in range(2)])
    assert list(CITY_WRITERS) == ["glb", "3dtiles", "usd", "cityjson", "ground"]
    called: list[str] = []
    for name, writer in CITY_WRITERS.items():

        def spy(built: BuiltCity, name: str = name, write: Any = writer.write) -> Any:
            called.append(name)
            assert [t.footprint.id for t in built.ok()] == ["h0", "h1"]
            return write(built)

        monkeypatch.setitem(CITY_WRITERS, name, dataclasses.replace(writer, write=spy))
    code, _, err = city(capsys, manifest, "--usd", "--3dtiles")
    assert code == 0, err
    assert called == ["glb", "3dtiles", "usd", "cityjson", "ground"]
    models = json.loads((tmp_path / "out" / "town.report.json").read_text())["models"]
    assert models["usd"] == "town.usda" and models["3dtiles"]["tileset"] == "3dtiles/tileset.json"
    called.clear()
    assert city(capsys, manifest)[0] == 0
    assert called == ["glb", "cityjson", "ground"]  # no --usd, no --3dtiles

    def full(built: BuiltCity) -> Any:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setitem(CITY_WRITERS, "cityjson", CityWriter("CityJSON", full))
    code, _, err = city(capsys, manifest, "--resume")
    assert code == 1
    assert "cannot write the CityJSON: No space left on device" in err
    assert "run again with --resume" in err
    assert (tmp_path / "out" / building_file("h1")).is_file()


def test_the_command_names_the_merged_model_it_wrote(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    manifest = town(tmp_path, [square("a")])
    code, said, err = facade(capsys, "city", manifest, "-o", tmp_path / "out", "-j", "1")
    assert code == 0, err
    assert f"-> {tmp_path / 'out'}/town.glb, " in said and "no merged" not in err


def test_resume_reads_the_last_run_as_lines(tmp_path: Path) -> None:
    """The last run's entries are kept as their lines (a city of 100,000 resumes in little
    memory): the last line of an id wins, a line cut short or without a hash is skipped."""
    log = tmp_path / "town.report.jsonl"
    entries = [
        {"id": "a", "status": "ok", "hash": "1", "height": 3.5},
        {"id": "b", "status": "ok"},  # a run before the hashes
        {"id": "c", "status": "failed", "hash": "2"},
        {"id": "a", "status": "ok", "hash": "3", "height": 4.0},
    ]
    log.write_text("".join(json.dumps(e) + "\n" for e in entries) + '{"id": "d", "sta')
    found = recorded(tmp_path, "town")
    assert found == {"a": json.dumps(entries[3]).encode("utf-8")}
    log.unlink()  # without the log, the report
    (tmp_path / "town.report.json").write_text(json.dumps({"buildings": entries[:2]}))
    assert recorded(tmp_path, "town") == {"a": json.dumps(entries[0]).encode("utf-8")}


PLANNED_HELD = """
import gc, json, sys, tracemalloc
from pathlib import Path
from facadecli.city.demo import write_terraces
from facadecli.city.manifest import load_city
from facadecli.city.run import planned
root, folder = Path(sys.argv[1]), Path(sys.argv[2])
held = []
for count in (100, 800):
    loaded = load_city(write_terraces(folder / f"town-{count}", root / "specs", count, 1))
    ahead = None
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    ahead = planned(loaded, folder / "out")
    gc.collect()
    held.append(tracemalloc.get_traced_memory()[0] - before)
    tracemalloc.stop()
print(json.dumps(held))
"""


def _in_fresh_python(script: str, folder: Path) -> Any:
    """What ``script`` prints last (JSON), run in a fresh Python (as a client starts: no
    heap or caches left by earlier tests) with the project's root and ``folder``."""
    run = subprocess.run(
        [sys.executable, "-c", script, str(ROOT), str(folder)],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    return json.loads(run.stdout.splitlines()[-1])


def test_a_planned_city_holds_its_tasks_packed(tmp_path: Path) -> None:
    """What a client holds through a run once planned grows little with the city: the
    tasks packed (packed.py), the footprints read not kept (tracemalloc's count of
    Python's live allocations: 0.1 KB a building here, where the unpacked tasks and
    the footprints took 2.8 KB). Counted in a fresh Python, as a client starts: in a
    test worker, what earlier tests left (a large heap, caches) read as 5.6-6.2 KB a
    building held on some runs. Read back, each task is the one planned, its spec the
    city's own."""
    held = _in_fresh_python(PLANNED_HELD, tmp_path / "fresh")
    per_building = (held[1] - held[0]) / 700
    assert per_building < 600, per_building
    loaded = load_city(write_terraces(tmp_path / "town", ROOT / "specs", 800, 1))
    ahead = planned(loaded, tmp_path / "out")
    tasks = list(ahead.tasks)
    assert len(tasks) == 800 and [t.footprint.id for t in tasks[:2]] == ["t0", "t1"]
    again: Packed[Any] = Packed(dict(loaded.specs), chunk=3)
    again.extend(tasks)
    assert list(again) == tasks and again[-1] == tasks[-1] and again[4:8] == tasks[4:8]
    assert all(task.spec is loaded.specs[task.spec_key] for task in again)
    assert Picked(again, [1, 5, 799])[:] == [tasks[1], tasks[5], tasks[799]]


def test_packed_tasks_are_spilled_to_disk_not_held() -> None:
    """A run's packed tasks (the plan's building list, held all run) keep their chunks in
    an unnamed temporary file: what stays in memory from 2,000 to 8,000 items is where
    each chunk starts (tracemalloc's count of Python's live allocations): 0.1 bytes an
    item, where the chunks in memory took their compressed size (here ~110 bytes an
    item; a planned terrace's task ~130). Each reads back as put in, in any order."""
    rng = random.Random(7)
    held = []
    for count in (2000, 8000):
        items = [(k, rng.randbytes(96)) for k in range(count)]
        gc.collect()
        tracemalloc.start()
        before = tracemalloc.get_traced_memory()[0]
        packed: Packed[Any] = Packed()
        packed.extend(items)
        gc.collect()
        held.append(tracemalloc.get_traced_memory()[0] - before)
        tracemalloc.stop()
        assert [packed[k] for k in (count - 1, 0, 70, 64)] == [
            items[k] for k in (count - 1, 0, 70, 64)
        ]
        assert list(packed) == items and packed.packed_bytes() > 96 * (count - 64)
        del packed
    assert (held[1] - held[0]) / 6000 < 4, held


PLANNING_PEAK = """
import gc, json, sys, tracemalloc
from pathlib import Path
from facadecli.city.demo import write_terraces
from facadecli.city.manifest import load_city
from facadecli.city.run import planned
root, folder = Path(sys.argv[1]), Path(sys.argv[2])
planned(load_city(write_terraces(folder / "town-50", root / "specs", 50, 1)), folder / "out")
peaks = []
for count in (400, 1600):
    loaded = load_city(write_terraces(folder / f"town-{count}", root / "specs", count, 1))
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    ahead = planned(loaded, folder / "out")
    peaks.append(tracemalloc.get_traced_memory()[1] - before)
    tracemalloc.stop()
    del ahead
print(json.dumps(peaks))
"""


def test_planning_peaks_at_little_a_building(tmp_path: Path) -> None:
    """Planning's peak, all of it (reading, the neighbours, the tasks), hardly grows with
    the city: the town is planned a region at a time (regions.py), so the peak is a
    region's footprints and what is kept of every building (its task packed...). The
    slope from 400 to 1,600 buildings of tracemalloc's peak (three regions of REGION =
    512 features), in a fresh Python (a test worker's leftovers would be counted), a town
    of 50 planned first (the one-off caches): 1,109 bytes a building when every footprint
    was read and every neighbour found at once, 301 since (most of it the tasks packed,
    kept for the run). Measured again from 400 to 3,200 buildings: 192; to 1,600: 209,
    and 1,508 with the whole town one region (``planned(..., region=10**9)``, as when
    every footprint was read at once), in half the time. GEOS's memory is not counted:
    ``make bench-large`` measures the resident memory (docs/benchmarks.md)."""
    peaks = _in_fresh_python(PLANNING_PEAK, tmp_path / "fresh")
    slope = (peaks[1] - peaks[0]) / 1200
    assert slope < 600, slope


def test_a_run_keeps_its_buildings_hashes_and_places_in_flat_buffers(tmp_path: Path) -> None:
    """What a run keeps of every building beside its packed task, for the whole run: its
    hash (resume.py) in 32 bytes and its centroid in 16, in one buffer each, not as small
    objects (a dict of hex strings by id took 145-195 bytes a building, a list of tuples 112;
    tracemalloc's count, the garbage collected before and after). Each reads back as made."""
    manifest = write_terraces(tmp_path / "town", ROOT / "specs", 600, 1)
    loaded = load_city(manifest)
    tasks = list(planned(loaded, tmp_path / "out").tasks)
    centroids = [(task.footprint.parts[0].centroid.x, 0.5 + i) for i, task in enumerate(tasks)]
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    hashes = building_hashes(loaded, tasks)
    points = Points()
    for point in centroids:
        points.append(point)
    gc.collect()
    held = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    assert held / len(tasks) < 64, held / len(tasks)
    digest = spec_digests(loaded)
    assert len(hashes) == len(tasks) == 600 and hashes[-1] == hashes[599]
    assert [hashes[i] for i in (0, 299)] == [building_hash(tasks[i], digest) for i in (0, 299)]
    assert hashes[1:3] == [building_hash(task, digest) for task in tasks[1:3]]
    assert list(points) == centroids and points[-1] == centroids[-1] and len(points) == 600
    with pytest.raises(IndexError):
        hashes[600]
    assert isinstance(give_back(), bool)  # glibc's malloc_trim, or nothing elsewhere


def test_report_entries_are_kept_on_disk_not_in_memory(tmp_path: Path) -> None:
    """The buildings' entries take a few bytes each in memory, whatever their size."""
    entry = {**ENTRIES[0], "error": "x" * 2000}
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    entries = Entries(500, tmp_path)
    for index in range(500):
        entries.put(index, {**entry, "id": f"b{index}"})
    held = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    assert held < 500 * 100, held
    assert entries[499] == {**entry, "id": "b499"} and entries.line(0).startswith(b'{"id": "b0"')
    assert list(tmp_path.iterdir()) == []  # its file has no name


def _traced_peak(work: Any) -> tuple[Any, int]:
    """What ``work()`` returns, and the peak of Python's live allocations while it ran
    above those before (tracemalloc), the garbage collected first."""
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    try:
        done = work()
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    return done, peak


def test_planning_peaks_grow_little_with_the_city(tmp_path: Path) -> None:
    """The two largest peaks of planning before the tasks, a building (the slope from 200
    to 1,600 buildings, tracemalloc's count, the first read's one-off caches left out):
    reading holds each footprint in one form at a time (1,363 -> 732 B a building when
    it held the features as read, in metres and as footprints at once), and finding the
    nodes a neighbour shares keeps the vertices in flat arrays (1,053 -> 668 B a building
    with a shapely point and tuples a vertex). GEOS's own memory is not counted here:
    ``make bench-large`` measures the resident memory (docs/benchmarks.md)."""
    from facadecli.city.footprints import read_footprints
    from facadecli.city.straight import straighten

    def footprints(count: int) -> Path:
        town = write_terraces(tmp_path / f"town-{count}", ROOT / "specs", count, 1)
        return town.parent / "footprints.geojson"

    read_footprints(footprints(50))  # pyproj's caches, once
    reading, merging = [], []
    for count in (200, 1600):
        path = footprints(count)
        found, peak = _traced_peak(lambda path=path: read_footprints(path))
        reading.append(peak)
        assert len(found.footprints) == count
        kept = list(found.footprints)
        del found
        merged, peak = _traced_peak(lambda kept=kept: straighten(kept, 3.0, 0.3))
        merging.append(peak)
        assert merged.footprints == tuple(kept)  # rectangles: nothing to merge
    read_slope = (reading[1] - reading[0]) / 1400
    merge_slope = (merging[1] - merging[0]) / 1400
    assert read_slope < 1000, read_slope
    assert merge_slope < 850, merge_slope


def test_equal_values_are_held_once_unless_their_text_differs() -> None:
    from facadecli.city.manifest import Roof
    from facadecli.city.run import Same
    from facadecli.city.s3db import Heights

    same = Same()
    first, again = Roof(type="gable", pitch=30.0), Roof(type="gable", pitch=30.0)
    assert same(first) is first and same(again) is first
    whole, floating = Heights(10, None, 0.0, None, 12.0), Heights(10.0, None, 0.0, None, 12.0)
    assert whole == floating and same(whole) is whole and same(floating) is floating
    assert (
        same(Heights(None, None, -0.0, None, 12.0)).base
        == same(Heights(None, None, 0.0, None, 12.0)).base
    )
    assert str(same(Heights(None, None, 0.0, None, 12.0)).base) == "0.0"


def test_the_tags_words_are_held_once_for_the_town() -> None:
    from facadecli.city.footprints import WORD_LENGTH, Words

    words = Words()
    long = "x" * (WORD_LENGTH + 1)
    text = json.dumps({"building": "house", "levels": 3, "name": long})
    one, two = (words.properties(json.loads(text)) for _ in range(2))
    assert one == two == json.loads(text)
    assert [k1 is k2 for k1, k2 in zip(one, two, strict=True)] == [True, True, True]
    assert one["building"] is two["building"] and one["name"] is not two["name"]


def test_party_lines_of_some_footprints_are_theirs_among_all(tmp_path: Path) -> None:
    from facadecli.city.footprints import read_footprints
    from facadecli.city.s3db import party_lines

    town = write_terraces(tmp_path / "town", ROOT / "specs", 48, 1).parent
    footprints = list(read_footprints(town / "footprints.geojson").footprints)
    every = dict(party_lines(footprints, 0.3))
    some = dict(party_lines(footprints, 0.3, only={"t1", "t17", "t40"}))
    assert list(some) == ["t1", "t17", "t40"] and all(key in every for key in some)
    assert all(some[key].equals_exact(every[key], 0) for key in some)


def test_party_lines_do_not_depend_on_what_else_was_read(tmp_path: Path) -> None:
    """A footprint's party walls are the same bytes whether the whole town was read or
    only the footprints around it (a region of it, run.py): its neighbours' lines are
    united in their order in the input, not in the order the tree of every shape read
    gives them (the walls of 1,541 of 2,000 terraces changed their vertices' order)."""
    from facadecli.city.footprints import read_footprints
    from facadecli.city.s3db import party_lines

    town = write_terraces(tmp_path / "town", ROOT / "specs", 400, 1).parent
    footprints = list(read_footprints(town / "footprints.geojson").footprints)
    every = dict(party_lines(footprints, 0.3))
    middle = footprints[200].parts[0].centroid
    near = [f for f in footprints if f.parts[0].distance(middle) < 40]
    mine = {f.id for f in near if f.parts[0].distance(middle) < 10}
    some = dict(party_lines(near, 0.3, only=mine))
    assert len(some) >= 4 and all(key in every for key in some)
    assert all(shapely.to_wkb(some[key]) == shapely.to_wkb(every[key]) for key in some)


def _doors_and_strays(manifest: Path) -> Path:
    """A generated town's footprints with entrance points on some walls (one on the wall
    two terraces share, one on no wall), a feature that is no polygon and one far off."""
    path = manifest.parent / "footprints.geojson"
    data = json.loads(path.read_text())
    features = data["features"]
    for k in (0, 1, 9, 30, 31, 77):
        x0, y0 = features[k]["geometry"]["coordinates"][0][1]  # its south-east corner
        features.append(_point(f"door-{k}", x0 - 0.2, y0 + 4.0, {"entrance": "yes"}))
    features.append(_point("lost", 99_000.0, 399_000.0, {"entrance": "yes"}))
    features.append(_point("bench", 100_005.0, 400_000.5, {"amenity": "bench"}))
    far = [[[9e5, 4e6], [9e5 + 9, 4e6], [9e5 + 9, 4e6 + 9], [9e5, 4e6]]]
    features.append(
        {
            "type": "Feature",
            "id": "far",
            "properties": {"height": "tall"},
            "geometry": {"type": "Polygon", "coordinates": far},
        }
    )
    path.write_text(json.dumps(data))
    return manifest


def _point(key: str, x: float, y: float, tags: dict[str, str]) -> dict[str, Any]:
    geometry = {"type": "Point", "coordinates": [x, y]}
    return {"type": "Feature", "id": key, "properties": tags, "geometry": geometry}


@pytest.mark.parametrize("region", [1, 5, 40])
def test_a_town_planned_a_region_at_a_time_is_planned_as_at_once(
    tmp_path: Path, region: int
) -> None:
    """Planned a region of ``region`` features at a time (regions.py), a town gives the
    tasks, warnings, rejected features, outlines with parts and counts that planning it
    at once gives: the OSM district of every S3DB case (parts in outlines, towers on
    podiums, collinear nodes, entrance nodes), a terrace sharing entrance nodes, and
    generated terraces with entrance points (one on a party wall, one on no wall), a
    point that is no entrance and a far feature."""
    from facadecli.city.default import default_city
    from tests.osm_district import write_district
    from tests.test_entrances import _terrace

    district = write_district(tmp_path / "district.osm")
    terrace = tmp_path / "terrace.osm"
    _terrace(terrace)
    spec = ROOT / "specs" / "residential-house.yaml"
    towns = [default_city(district, spec), default_city(terrace, spec)]
    towns.append(
        load_city(_doors_and_strays(write_terraces(tmp_path / "t", ROOT / "specs", 120, 1)))
    )
    for loaded in towns:
        once = planned(loaded, tmp_path / "out", region=10**9)
        cut = planned(loaded, tmp_path / "out", region=region)
        assert list(cut.tasks) == list(once.tasks) and len(once.tasks) > 3
        assert cut.found == once.found and cut.straight == once.straight
        assert list(cut.replaced.items()) == list(once.replaced.items())
        assert list(cut.kept.items()) == list(once.kept.items())
    assert once.found.warnings and once.found.rejected  # the generated town's
    assert any("party walls" in w.reason for w in once.found.warnings)
    assert [r.id for r in once.found.rejected] == ["bench", "far"]  # a point; far off
    assert all(w.id != "far" for w in once.found.warnings)


def test_regions_cover_every_feature_once_each_holding_at_most_their_size() -> None:
    """The boxes cut by counts, not metres: every place in one region, none over the
    size, however unevenly the boxes lie; around a region, the region itself and the
    boxes within the margin of it, not those farther."""
    import numpy as np

    from facadecli.city.regions import around, regions

    rng = np.random.default_rng(1)
    xy = np.concatenate([rng.normal(0, 50, (900, 2)), rng.uniform(-5000, 5000, (100, 2))])
    boxes = np.column_stack([xy, xy + rng.uniform(1, 20, (1000, 2))])
    cut = regions(boxes, 64)
    places = np.concatenate(cut)
    assert sorted(places.tolist()) == list(range(1000)) and max(len(r) for r in cut) <= 64
    assert all((np.diff(r) > 0).all() for r in cut) and len(cut) >= 1000 // 64
    core = cut[0]
    near = around(boxes, core, 2.0, rings=1)
    assert set(core.tolist()) <= set(near.tolist())
    x0, y0 = boxes[core, :2].min(axis=0) - 2.0
    x1, y1 = boxes[core, 2:].max(axis=0) + 2.0
    inside = (boxes[:, 0] <= x1) & (boxes[:, 2] >= x0) & (boxes[:, 1] <= y1) & (boxes[:, 3] >= y0)
    assert near.tolist() == np.flatnonzero(inside).tolist()


def test_spooled_items_read_back_in_any_order() -> None:
    from facadecli.city.packed import Spooled

    shared = {"big": list(range(1000))}
    items: Spooled[Any] = Spooled(shared)
    for k in range(50):
        items.append((k, f"item-{k}", shared["big"]))
    assert [items[k][0] for k in (49, 0, 17, -1)] == [49, 0, 17, 49]
    assert items[3][2] is shared["big"] and len(items) == 50
    assert [item[0] for item in items.only([5, 2, 40])] == [5, 2, 40]


BUILDING_HELD = """
import gc, json, sys, tracemalloc
from pathlib import Path
import facadecli.city.run as run
from facadecli.city.demo import write_terraces
from facadecli.city.manifest import load_city
root, folder = Path(sys.argv[1]), Path(sys.argv[2])

def ended(task):  # no building built: the client's own bookkeeping alone is measured
    return {"id": task.footprint.id, "status": "failed", "error": "not built", "time_ms": 0.0}

run.build = ended
planned, marks = run.planned, {}

def measured_planning(*args, **kwargs):
    found = planned(*args, **kwargs)
    gc.collect()
    marks["planned"] = tracemalloc.get_traced_memory()[0]
    return found

def progress(done, total):
    if done == total:
        gc.collect()
        marks["ended"] = tracemalloc.get_traced_memory()[0]

run.planned = measured_planning
held = []
for count in (50, 300, 1200):
    city = load_city(write_terraces(folder / f"town-{count}", root / "specs", count, 1))
    gc.collect()
    tracemalloc.start()
    run.run_city(city, folder / f"out-{count}", progress=progress, lods=(1, 2, 3), usd=True)
    tracemalloc.stop()
    held.append(marks["ended"] - marks["planned"])
print(json.dumps(held[1:]))
"""


def test_a_run_holds_a_few_flat_bytes_a_building_while_it_builds(tmp_path: Path) -> None:
    """What the client holds more a building from its town planned to its last building
    ended (tracemalloc, the slope from 300 to 1,200 generated terraces, 3D Tiles and USD
    asked for; no building built: the client's own bookkeeping), in a fresh Python: the
    buildings' places, hashes, report lines and tiles' order in flat buffers, and the
    quadtree's squares: 120 bytes.
    With a map from every id to its position, the tiles' quadtree listing each id in every
    square on the way to its leaf and a map from each id to its squares, it was 432."""
    held = _in_fresh_python(BUILDING_HELD, tmp_path / "fresh")
    slope = (held[1] - held[0]) / 900
    assert slope < 240, slope


def test_a_tileset_keeps_its_buildings_in_one_array_not_in_its_squares(tmp_path: Path) -> None:
    """A 3D Tiles writer planned for a city keeps where each building is in the quadtree
    as 8 bytes in one array, and its squares (here one for about every two buildings, a
    grid 10 m apart) in numpy arrays, 42 bytes a square: what it holds a building more
    from 2,000 to 8,000 buildings (tracemalloc), 30 bytes. With each square a Python
    object, 93; with every square listing its buildings' ids, a map from each id to its
    squares and a list of children and of tiles in every square, 380; each building's
    squares are found again from its centroid."""
    from facadecli.city.georef import Georef
    from facadecli.city.tileset import TilesetWriter

    held = []
    for count in (2000, 8000):
        places = Points()
        for k in range(count):
            places.append((10.0 * (k % 97) + (k * 7919 % 13) / 5, 10.0 * (k // 97)))
        gc.collect()
        tracemalloc.start()
        before = tracemalloc.get_traced_memory()[0]
        writer = TilesetWriter(tmp_path, Georef("EPSG:3067", (0.0, 0.0)), (1, 2, 3), places)
        gc.collect()
        held.append(tracemalloc.get_traced_memory()[0] - before)
        tracemalloc.stop()
        assert sorted(writer.tree.order.tolist()) == list(range(count))
        del writer
    slope = (held[1] - held[0]) / 6000
    assert slope < 48, slope


def test_a_city_stage_names_its_buildings_without_keeping_the_names(tmp_path: Path) -> None:
    """The city's USD stage is written holding no name of the prims written (they are
    unique by construction, :func:`.building_prim`): the peak of Python's allocations
    while it is written grows by no byte a building from 2,000 to 8,000 (a set of the
    names written took 100 bytes a building). ``pathlib`` interns each part of a path,
    and the interpreter's table of interned strings is resized, by a few MB, whenever
    inserts have used it up, dead strings or not (at 2,000 or at 8,000, as the tests run
    before left it): the paths' parts, the stages' names too, are made and kept alive
    before measuring, so that the paths the stage makes find them interned."""
    from facadecli.export.usd import city_usda_lines

    def files(count: int) -> Iterator[Path]:
        return (tmp_path / building_file(f"house-{k:05d}") for k in range(count))

    interned = [(glb, glb.with_suffix(".usda").relative_to(tmp_path)) for glb in files(8000)]
    sum(1 for _ in city_usda_lines("c", files(8000), tmp_path))
    peaks = []
    for count in (2000, 8000):
        glbs = files(count)
        _, peak = _traced_peak(
            lambda glbs=glbs: sum(1 for _ in city_usda_lines("c", glbs, tmp_path))
        )
        peaks.append(peak)
    slope = (peaks[1] - peaks[0]) / 6000
    assert slope < 8, slope
    assert len(interned) == 8000
