"""``facade city``: every building of a manifest, in worker processes, written atomically.

The unit of work is a building; each writes ``buildings/<shard>/<name>.glb``
(:mod:`facadecli.city.folders`) through a temporary file, so an interrupted run resumes
(``--resume``, :mod:`facadecli.city.resume`) where it stopped. Results are taken as they
finish and put back in the manifest's order, so the report and the merged model do not
depend on scheduling; what the run ends with (merged models, CityJSON, report) is
streamed to disk, the client holding no more a building than its task.
Everything a user can fix (the output folder, the GeoJSON file, duplicate ids) is checked
before the first building; then the run locks its output folder and removes the temporary
files a killed run left there (:func:`claimed`), and only those. Features that are not
footprints are listed as rejected, apart from the buildings: they do not fail the run; a
building that fails to build does.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import queue
import re
import time
from array import array
from collections import Counter
from collections.abc import Callable, Container, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import shapely

from facadecli.city.building import (
    AxisCache,
    Facade,
    Looks,
    Slot,
    Tries,
    axes_to_solve,
    build_building,
    building_solids,
    building_walls,
    party_volumes,
    rung_length,
    solve_rung,
    wall_tries,
)
from facadecli.city.built import BuiltCity, attributes, feature_file
from facadecli.city.cityjson import (
    BuildingSolids,
    building_object,
    cityjson_bytes,
    write_cityjson,
)
from facadecli.city.entrances import Wall, door_owners
from facadecli.city.folders import BUILDINGS, SHARD, building_file, run_folder, safe_name
from facadecli.city.footprints import (
    ON_EDGE,
    BBox,
    Footprint,
    FootprintSet,
    Rejected,
    Simplified,
    Survey,
    survey,
)
from facadecli.city.georef import Georef, georeference
from facadecli.city.heap import EVERY, give_back
from facadecli.city.landcover import kind_counts
from facadecli.city.lods import feature_scene
from facadecli.city.manifest import Choice, City, Roof, WallRule
from facadecli.city.packed import Packed, Picked, Points, Spooled
from facadecli.city.regions import REGION, around, extent, regions
from facadecli.city.report import CityReport, Entries, Summary, Tally
from facadecli.city.resume import (
    Hashes,
    building_hash,
    recorded,
    reusable,
    spec_digests,
    stamped,
)
from facadecli.city.s3db import (
    Heights,
    inherited,
    lifted,
    outline_rest,
    party_lines,
    replaced_outlines,
    roof_colour,
    screens,
    side_by_side,
    standing_on,
    tagged_heights,
    tagged_roof,
    volume,
    wall_colour,
)
from facadecli.city.straight import Straightened, straighten
from facadecli.city.tileset import FOLDER as TILESET_FOLDER
from facadecli.city.tileset import TilesetWriter
from facadecli.errors import OutputError, SpecError
from facadecli.export import CITY_WRITERS, CityWriter
from facadecli.export.atomic import atomic_output, check_output_folder, write_atomic
from facadecli.export.glb_merge import instance_nodes
from facadecli.export.gltf import glb_bytes
from facadecli.export.lock import locked
from facadecli.export.texture_store import FOLDER as TEXTURES
from facadecli.export.texture_store import PICTURE, TextureStore, externalised, prune
from facadecli.export.usd import stored_usda_text, usda_text
from facadecli.geometry.facade import material_extensions
from facadecli.solver.axis import AxisLayout
from facadecli.spec.model import Spec


@dataclass(frozen=True)
class Task:
    footprint: Footprint
    spec_key: str
    spec: Spec
    heights: Heights
    roof: Roof
    min_facade_width: float
    target: Path
    spec_dir: Path  # the spec's folder: its mesh and texture paths are relative to it
    looks: Looks = field(default_factory=Looks)
    shared: Any = None  # the lines of the outline along a neighbour: party walls
    tolerance: float = 0.3  # metres: how near a neighbour's wall makes a party wall
    cache_key: str = ""  # the spec's identity in a worker's caches: its path and content
    walls: tuple[tuple[WallRule, Facade], ...] = ()  # façades for some walls
    variants: int = 1  # layouts each axis may take
    pick: int = 0  # which of them this building takes (from the seed and its id)
    usd: bool = False  # a USD stage beside the glb (``--usd``)
    above: Any = None  # the taller parts standing on this one: its roof leaves them out
    instanced: bool = False  # repeated parts as GPU instances (``--instance``)
    level: int = 3  # the finest level of detail the run needs: below 3, no façade is solved
    shared_textures: bool = True  # pictures in the run's textures/, not in each glb
    # the manifest's fallback façade (its path there, and it): for walls no other fits
    fallback: tuple[str, Facade] | None = None

    @property
    def pictures(self) -> TextureStore | None:
        """Where its pictures go: the run's ``textures/`` (texture_store.py), or None
        when its glb embeds them (``--embed-textures``)."""
        return TextureStore(run_folder(self.target) / TEXTURES) if self.shared_textures else None

    @property
    def file(self) -> str:
        """Its glb relative to the output folder (folders.py): the report's ``file``."""
        return building_file(self.footprint.id).as_posix()


IN_FLIGHT = 64  # chunks of tasks handed to the workers at once, at most
_CACHE: dict[str, AxisCache] = {}  # per worker process: axes solved for earlier buildings
_SEEDED: dict[str, str] = {}  # per Dask worker process: the run its cache was seeded for
Axes = tuple[AxisLayout, ...]  # an axis's layouts at a rung: the best and its variants


def _needs(task: Task) -> list[Tries]:
    """The axes a building's walls may solve, the façades each tries in turn
    (:func:`.wall_tries`), to solve ahead those they will, once each (none for a run of
    coarser levels of detail only)."""
    if task.level < 3:
        return []
    found = wall_tries(
        task.footprint,
        task.heights,
        task.roof,
        task.min_facade_width,
        task.shared,
        task.tolerance,
        Facade(task.spec, task.cache_key, task.spec_dir),
        task.walls,
        task.variants,
        task.fallback[1] if task.fallback is not None else None,
    )
    return sorted(found)


def _solve(job: tuple[Spec, Slot]) -> tuple[Slot, Axes]:
    spec, slot = job
    return slot, solve_rung(spec, slot[1], rung_length(slot[2]), slot[3])


def _seed(axes: dict[Slot, Axes]) -> None:
    """A worker's cache, filled with the axes solved ahead."""
    _CACHE["axes"] = AxisCache(axes=dict(axes))


def _build_seeded(tasks: Sequence[Task], axes: dict[Slot, Axes], run: str) -> list[dict[str, Any]]:
    """``build`` on a Dask worker handed a run's axes solved ahead: its cache is seeded
    with them before its first building of the run (``run`` tells runs apart: workers
    outlive them), as a local pool's processes are when they start."""
    if _SEEDED.get("run") != run:
        _seed(axes)
        _SEEDED["run"] = run
    return [build(task) for task in tasks]


def axes_solved_while_building() -> int:
    """How many axes this worker process solved while building, not ahead: 0 when the
    run's presolve gave it every axis its buildings needed."""
    cache = _CACHE.get("axes")
    return 0 if cache is None else cache.solved


def build(task: Task) -> dict[str, Any]:
    """Build one building and write its glb; never raises (failures are reported)."""
    if task.level < 3:
        return _build_coarse(task)
    started = time.perf_counter()
    cache = _CACHE.setdefault("axes", AxisCache())
    try:
        result = build_building(
            task.footprint,
            task.spec,
            task.cache_key or task.spec_key,
            task.heights,
            task.roof,
            task.min_facade_width,
            cache,
            task.spec_dir,
            task.looks,
            task.shared,
            task.tolerance,
            task.walls,
            task.variants,
            task.pick,
            task.above,
            task.instanced,
            task.fallback[1] if task.fallback is not None else None,
        )
        solids = BuildingSolids(task.footprint.id, result.volumes, attributes(task, result.top))
        write_cityjson(feature_file(task.target), building_object(solids))
        data = glb_bytes(result.scene, material_extensions(task.spec))
        data = instance_nodes(data) if task.instanced else data
        store = task.pictures  # its pictures are written before the files that name them
        write_atomic(task.target, data if store is None else externalised(data, store, task.target))
        if task.usd:
            stage = task.target.with_suffix(".usda")
            text = (
                usda_text(result.scene, task.target.stem)
                if store is None
                else stored_usda_text(result.scene, stage, store)
            )
            write_atomic(stage, text)
    except Exception as error:
        return _failed(task, error, started)
    return _built(
        task,
        started,
        facades=result.facades,
        plain_walls=result.plain_walls,
        party_walls=result.party_walls,
        plain=result.plain,
        **({"doors": result.doors} if result.doors else {}),
        height=result.top,
    )


def _build_coarse(task: Task) -> dict[str, Any]:
    """A building of a run that needs no façades (``--lod 1`` or ``2``): its volumes and
    roofs alone, no axis solved. Its CityJSON feature is the one a full build writes (the
    volumes do not depend on the façades), and its glb (and USD layer) is the feature at
    the run's level (lods.py): what the merged models and the tiles make of it anyway."""
    started = time.perf_counter()
    try:
        volumes = party_volumes(
            task.footprint, task.heights, task.roof, task.shared, task.tolerance, task.above
        )
        solids, top = building_solids(task.footprint, volumes)
        feature = building_object(BuildingSolids(task.footprint.id, solids, attributes(task, top)))
        write_cityjson(feature_file(task.target), feature)
        scene = feature_scene(json.loads(cityjson_bytes(feature)), task.target.stem, task.level)
        write_atomic(task.target, glb_bytes(scene))
        if task.usd:
            write_atomic(task.target.with_suffix(".usda"), usda_text(scene, task.target.stem))
    except Exception as error:
        return _failed(task, error, started)
    return _built(task, started, lod=task.level, height=top)


def _built(task: Task, started: float, **figures: Any) -> dict[str, Any]:
    """A built building's report entry: its id, file, ``figures`` (what it is made of,
    its height), how its footprint was repaired and simplified, and its time."""
    return {
        "id": task.footprint.id,
        "status": "ok",
        "file": task.file,
        **figures,
        "repaired": task.footprint.repaired,
        **_simplified(task.footprint.simplified),
        "time_ms": round((time.perf_counter() - started) * 1000, 1),
    }


def _failed(task: Task, error: Exception, started: float) -> dict[str, Any]:
    """A building that failed: its report entry, with the error."""
    return {
        "id": task.footprint.id,
        "status": "failed",
        "error": f"{type(error).__name__}: {error}",
        "time_ms": round((time.perf_counter() - started) * 1000, 1),
    }


def _pick(seed: int, building_id: str) -> int:
    """A building's own number from the manifest's seed and its id: which of the variants
    and palette colours it takes, the same on every run and machine."""
    digest = hashlib.sha256(f"{seed}/{building_id}".encode("utf-8", "surrogatepass"))
    return int.from_bytes(digest.digest()[:4], "big")


def _centroid(footprint: Footprint) -> tuple[float, float]:
    """Where a building is, for its tile: the centroid of its largest part."""
    largest = max(footprint.parts, key=lambda part: part.area)
    return largest.centroid.x, largest.centroid.y


def _simplified(simplified: Simplified | None) -> dict[str, Any]:
    if simplified is None:
        return {}
    return {
        "simplified": {
            "vertices_before": simplified.before,
            "vertices_after": simplified.after,
            "tolerance_m": simplified.tolerance,
        }
    }


def plan(
    city: City,
    footprints: list[Footprint],
    outdir: Path,
    usd: bool = False,
    instanced: bool = False,
    level: int = 3,
    shared_textures: bool = True,
    core: Container[str] | None = None,
    same: Same | None = None,
    checked: bool = True,
) -> tuple[Packed[Task], list[tuple[str, Rejected]]]:
    """One task a building, built to ``level`` of detail (below 3: no façades), kept
    packed as they are made (packed.py: a client's memory for a city of any size), and
    the warnings of the planning, each with the id of the first footprint it is about:
    an entrance that two buildings hold (:func:`one_door_each`). Paths are absolute:
    workers (Dask's too) may run elsewhere. With ``core`` (ids), the tasks of those
    footprints alone, the others their neighbours (a region of a town, :func:`planned`);
    ``same`` is the town's (:class:`Same`); with ``checked`` False, two ids giving one
    file name are left to the caller (:class:`FileNames`: a town checks them in order)."""
    outdir = outdir.resolve()
    defaults = city.manifest.defaults
    tolerance = defaults.party_wall_tolerance
    names = FileNames(str(city.footprints))
    same = Same() if same is None else same  # most buildings share a choice and a roof
    shapes = {}
    for footprint in footprints:
        choice, heights, roof = _shape(city, footprint.properties)
        shapes[footprint.id] = (same(choice), heights, same(roof))
    above = standing_on(footprints, {key: shape[1] for key, shape in shapes.items()})
    raised = lifted(
        footprints, {k: s[1] for k, s in shapes.items()}, {k: s[2] for k, s in shapes.items()}
    )
    shapes |= {key: (shapes[key][0], heights, shapes[key][2]) for key, heights in raised.items()}
    beside = _beside(footprints, shapes)

    def lines_of(only: Container[str] | None = None) -> Iterator[tuple[str, bytes]]:
        """Party walls, footprint by footprint in their order, as WKB (exact coordinates,
        as the packed task keeps them; a building's lines found as its task is made, not
        every building's held: 40,000 generated terraces held 67 MiB more resident with
        them all as GEOS objects, 9 MiB as WKB)."""
        found = party_lines(footprints, tolerance, beside, only) if tolerance > 0 else ()
        return ((key, shapely.to_wkb(lines)) for key, lines in found)

    doors = shared_doors(footprints)  # only footprints sharing an entrance need walls ahead
    ahead = dict(lines_of(doors)) if doors else {}

    def walls_of(footprint: Footprint) -> list[Wall]:
        _, heights, roof = shapes[footprint.id]
        lines = _from_wkb(ahead.get(footprint.id))
        return building_walls(footprint, heights, roof, lines, tolerance)

    footprints, warnings = one_door_each(footprints, walls_of, core)
    ahead.clear()
    shared = Lockstep(lines_of(core))
    identities: dict[str, str] = {}  # spec path -> its path and a digest of its content

    def facade_of(path: str) -> Facade:
        """The façade the manifest names by ``path`` (its identity made first)."""
        return Facade(city.specs[path], identities[path], (city.folder / path).parent.resolve())

    tasks: Packed[Task] = Packed(dict(city.specs))
    for footprint in footprints:
        if core is not None and footprint.id not in core:
            continue
        choice, heights, roof = shapes[footprint.id]
        if checked:
            names.add(footprint.id)
        properties = footprint.properties
        fallback_path = defaults.fallback_facade
        named = (choice.facade, *(rule.facade for rule in choice.walls))
        for path in (*named, *([fallback_path] if fallback_path is not None else [])):
            if path not in identities:  # workers outlive a run: tell specs apart
                content = city.specs[path].model_dump_json().encode("utf-8")
                digest = hashlib.sha256(content).hexdigest()[:16]
                identities[path] = f"{(city.folder / path).resolve()}#{digest}"
        walls = tuple((rule, facade_of(rule.facade)) for rule in choice.walls)
        pick = _pick(city.manifest.seed, footprint.id)
        looks = Looks()
        if choice.colours == "tags":
            looks = Looks(wall_colour(properties), roof_colour(properties))
        if choice.palette and looks.wall is None:
            looks = replace(looks, wall=choice.palette[pick % len(choice.palette)])
        tasks.append(
            Task(
                footprint,
                choice.facade,
                city.specs[choice.facade],
                heights,
                roof,
                defaults.min_facade_width,
                outdir / building_file(footprint.id),
                (city.folder / choice.facade).parent.resolve(),
                looks,
                _from_wkb(shared.take(footprint.id)),
                tolerance,
                identities[choice.facade],
                walls,
                choice.variants,
                pick,
                usd,
                above.get(footprint.id),
                instanced,
                level,
                shared_textures,
                None if fallback_path is None else (fallback_path, facade_of(fallback_path)),
            )
        )
    return tasks, warnings


class FileNames:
    """The buildings' file names (folders.py), each added in the manifest's order: two
    ids giving one name are an error (exit 2) at the second, naming the first."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.owners: dict[str, str] = {}  # file name -> building id

    def add(self, key: str) -> None:
        name = safe_name(key)
        if self.owners.setdefault(name, key) != key:
            raise SpecError.at(
                self.file,
                None,
                None,
                f"ids '{self.owners[name]}' and '{key}' give one file name '{name}'",
                "change one of the ids",
            )


def _from_wkb(data: bytes | None) -> Any:
    """A footprint's party walls kept as WKB (:func:`plan`), None when it has none."""
    return None if data is None else shapely.from_wkb(data)


class Same:
    """Each value as the first equal one seen, so that equal values are held once (a
    call gives its argument back when the first is equal but not the same, as 1 and
    1.0, or 0.0 and -0.0 are: their text tells them apart)."""

    def __init__(self) -> None:
        self.seen: dict[Any, Any] = {}

    def __call__(self, value: T) -> T:
        found: T = self.seen.setdefault(value, value)
        return found if found is value or repr(found) == repr(value) else value


class Lockstep:
    """Values by key from pairs that come in the order they are asked for, each key at
    most once (a footprint's party walls as the tasks are made, in the footprints'
    order): :meth:`take` gives a key's value, None for a key the pairs skip."""

    def __init__(self, pairs: Iterator[tuple[str, bytes]]):
        self.pairs = pairs
        self.next = next(pairs, None)

    def take(self, key: str) -> bytes | None:
        if self.next is None or self.next[0] != key:
            return None
        found = self.next[1]
        self.next = next(self.pairs, None)
        return found


def shared_doors(footprints: Sequence[Footprint]) -> set[str]:
    """The ids of the footprints holding an entrance another one holds too."""
    holders: dict[tuple[float, float], list[str]] = {}
    for footprint in footprints:
        for point in footprint.entrances:
            holders.setdefault(point, []).append(footprint.id)
    return {key for ids in holders.values() if len(ids) > 1 for key in ids}


def one_door_each(
    footprints: list[Footprint],
    walls: Callable[[Footprint], list[Wall]],
    core: Container[str] | None = None,
) -> tuple[list[Footprint], list[tuple[str, Rejected]]]:
    """The footprints with each entrance held by one of them only: an entrance node two
    outlines share (a terrace's corner, a wall two buildings share), or an entrance point
    within reach of both, goes to the first of :func:`.entrances.door_owners` (whose wall
    there is not a party wall, the door farthest from the wall's ends), to none when it
    is on party walls alone. A warning (counted under ``entrance``) says which got it
    when several could have, and that none did when it is on party walls alone; each
    with the id of the first footprint holding the entrance. With ``core`` (ids), the
    entrances those footprints hold alone, and the warnings whose first holder it is."""
    holders: dict[tuple[float, float], list[int]] = {}
    for index, footprint in enumerate(footprints):
        for point in footprint.entrances:
            holders.setdefault(point, []).append(index)
    dropped: dict[int, set[tuple[float, float]]] = {}
    warnings = []
    for point, indices in holders.items():
        if len(indices) < 2:
            continue
        if core is not None and not any(footprints[k].id in core for k in indices):
            continue
        first = footprints[indices[0]].id
        ranked = door_owners(point, [(footprints[k].id, walls(footprints[k])) for k in indices])
        for k in indices:
            if not ranked or footprints[k].id != ranked[0]:
                dropped.setdefault(k, set()).add(point)
        where = f"entrance at ({point[0]:.2f}, {point[1]:.2f})"
        if len(ranked) > 1:
            reason = (
                f"{where} is on walls of {', '.join(ranked)}, none a party wall: the door "
                f"goes to {ranked[0]}, where it lies farthest from its wall's ends"
            )
            warnings.append((first, Rejected(ranked[0], reason, None, None, None)))
        elif not ranked:
            ids = ", ".join(footprints[k].id for k in indices)
            reason = f"{where} is on party walls of {ids} only: no door there"
            warnings.append((first, Rejected(first, reason, None, None, None)))
    if core is not None:
        warnings = [(key, warning) for key, warning in warnings if key in core]
    kept = [
        replace(f, entrances=tuple(p for p in f.entrances if p not in dropped[k]))
        if k in dropped
        else f
        for k, f in enumerate(footprints)
    ]
    return kept, warnings


def _shape(city: City, properties: dict[str, Any]) -> tuple[Choice, Heights, Roof]:
    """What the manifest and a feature's tags make of a building: the manifest's choice,
    its heights (a rule's height wins over the tags'; under the manifest's default
    roof, no tag shaping it, the walls keep a storey: :func:`.s3db.volume`) and its
    roof."""
    defaults = city.manifest.defaults
    choice = city.choose(properties)
    names = city.manifest.properties.names()
    heights = tagged_heights(properties, defaults.floor_height, defaults.height, names)
    if choice.height is not None:
        heights = replace(heights, top=choice.height, eaves=None)
    if choice.guessed_roof:  # no tag or rule gives the roof: a one-storey shed is not half roof
        heights = replace(heights, storey=defaults.floor_height)
    return choice, heights, tagged_roof(properties, choice.roof)


def _beside(
    footprints: Sequence[Footprint], shapes: dict[str, tuple[Choice, Heights, Roof]]
) -> Callable[[str, str], bool]:
    """Whether two footprints' walls stand side by side (:func:`side_by_side`): always
    when both stand on the ground; else from their volumes, found only then (a roof's
    height from its pitch needs its skeleton)."""
    by_id = {footprint.id: footprint for footprint in footprints}

    @functools.cache
    def span(key: str) -> tuple[float, float]:
        _, heights, roof = shapes[key]
        blocks = [volume(part, heights, roof) for part in by_id[key].parts]
        return min(block.base for block in blocks), max(block.eaves for block in blocks)

    def beside(one: str, other: str) -> bool:
        if not screens(shapes[one][1], shapes[other][1]):
            return False  # a lower neighbour: the wall stands free above it
        if shapes[one][1].base <= 0 and shapes[other][1].base <= 0:
            return True  # walls from the ground up meet for MIN_WALL at least
        return side_by_side(span(one), span(other))

    return beside


def standing(
    city: City, footprints: Sequence[Footprint], replaced: dict[str, list[str]]
) -> tuple[list[Footprint], dict[str, float]]:
    """The footprints to build: an outline with parts (``replaced``) as what its parts
    leave of it (:func:`outline_rest`; dropped when they leave nothing), every other
    footprint as it is; and the area (m²) still built of each outline with parts."""
    by_id = {footprint.id: footprint for footprint in footprints}
    built: list[Footprint] = []
    kept: dict[str, float] = {}
    for footprint in footprints:
        ids = replaced.get(footprint.id)
        if ids is None:
            built.append(footprint)
            continue
        _, heights, roof = _shape(city, footprint.properties)
        bases = {i: _shape(city, by_id[i].properties)[1].base for i in ids}  # once a part
        parts = [(shape, bases[i]) for i in ids for shape in by_id[i].parts]
        rest = [
            piece
            for shape in footprint.parts
            for piece in outline_rest(shape, volume(shape, heights, roof).eaves, parts)
        ]
        kept[footprint.id] = round(sum(piece.area for piece in rest), 1)
        if rest:
            built.append(replace(footprint, parts=tuple(rest)))
    return built, kept


def check_output(outdir: Path, name: str) -> None:
    """Before any work: the outputs can be written in ``outdir`` (SpecError, exit 2, for
    ``--output`` if not); nothing is created here."""
    check_output_folder(outdir)
    problem = None
    buildings = outdir / BUILDINGS
    if os.path.lexists(buildings) and not os.path.isdir(buildings):
        problem = f"'{buildings}' is a file, where the buildings' folder goes"
    elif os.path.isdir(buildings) and not os.access(buildings, os.W_OK | os.X_OK):
        problem = f"cannot write in '{buildings}' (permission denied)"
    for folder in ("tiles", TILESET_FOLDER):
        tiles = outdir / folder
        if os.path.lexists(tiles) and not os.path.isdir(tiles):
            problem = f"'{tiles}' is a file, where the tiles' folder goes"
    for output in (
        outdir / f"{name}.glb",
        outdir / f"{name}.report.json",
        outdir / f"{name}.city.json",
        outdir / f"{name}.tiles.json",
        outdir / f"{name}.georef.json",
        outdir / f"{name}.report.jsonl",
        outdir / f"{name}.ground.geojson",
        outdir / f"{name}.ground.glb",
    ):
        if os.path.isdir(output):
            problem = f"'{output}' is a folder, where an output file goes"
    if problem is not None:
        raise SpecError.at("--output", None, None, problem, "give another folder, or move it")


# mkstemp's names: a prefix, 8 characters of these, a suffix (facadecli.export.atomic,
# glb_merge, cityjson write ``.<target>.<8>.tmp``, ``.bin``, ``.objects``, ``.vertices``)
_RANDOM = r"\.[a-z0-9_]{8}\."
BUILT = rf"\.[A-Za-z0-9._~-]+\.(?:glb|city\.jsonl|usda){_RANDOM}tmp"  # a building's files


def leftovers(outdir: Path, name: str) -> list[Path]:
    """The temporary files a killed run of the city ``name`` left in ``outdir``: only
    regular files named as this tool names them, beside the outputs it writes."""
    plain = re.escape(name)
    patterns = {
        outdir: rf"\.{plain}\.(?:glb|report\.json|city\.json|tiles\.json|usda|ground\.geojson"
        rf"|ground\.glb){_RANDOM}(?:tmp|bin|objects|vertices|ids)",
        outdir / BUILDINGS: BUILT,  # a run before the shards wrote there
        outdir / "tiles": rf"\.{plain}_-?\d+_-?\d+\.glb{_RANDOM}(?:tmp|bin)",
        outdir / TILESET_FOLDER: rf"\.(?:tileset\.json{_RANDOM}tmp"
        rf"|ground\.glb{_RANDOM}(?:tmp|bin))",  # the ground's tile (--ground)
        outdir / TEXTURES: rf"\.{PICTURE.pattern}{_RANDOM}tmp",  # a picture (texture_store.py)
    }
    with contextlib.suppress(OSError):  # buildings/<shard>/ (folders.py)
        for entry in os.scandir(outdir / BUILDINGS):
            if SHARD.fullmatch(entry.name) and entry.is_dir(follow_symlinks=False):
                patterns[Path(entry.path)] = BUILT
    tileset = outdir / TILESET_FOLDER  # 3D Tiles: <level>/<column>/<row>.lod<k>.glb
    for sub, _, _ in sorted(os.walk(tileset)):
        if Path(sub) != tileset:
            patterns[Path(sub)] = rf"\.\d+\.lod[123]\.glb{_RANDOM}(?:tmp|bin)"
    found = []
    for folder, pattern in patterns.items():
        matcher = re.compile(pattern, re.ASCII)
        try:
            entries = list(os.scandir(folder))
        except OSError:  # no such folder (yet)
            continue
        for entry in entries:
            if matcher.fullmatch(entry.name) and entry.is_file(follow_symlinks=False):
                found.append(Path(entry.path))
    return sorted(found)


@contextlib.contextmanager
def claimed(outdir: Path, name: str) -> Iterator[None]:
    """The output folder, made and locked for this run (:mod:`facadecli.export.lock`:
    another run into it is exit 2), with what a killed run left in it removed
    (:func:`leftovers`)."""
    with locked(outdir, "facade city"):
        for path in leftovers(outdir, name):
            with contextlib.suppress(FileNotFoundError):
                path.unlink()
        yield


def run_city(
    city: City,
    outdir: Path,
    jobs: int = 1,
    limit: int | None = None,
    resume: bool = False,
    progress: Callable[[int, int], None] | None = None,
    scheduler: str | None = None,
    bbox: BBox | None = None,
    usd: bool = False,
    lods: tuple[int, ...] = (),
    merged_lod: int = 3,
    instanced: bool = False,
    timings: bool = False,
    shared_textures: bool = True,
    ground: bool = False,
) -> CityReport:
    """Build a city; returns the report (also written to ``<name>.report.json``).
    With ``lods`` (levels of detail, of 1, 2, 3), 3D Tiles too (tileset.py); the merged
    models are at ``merged_lod`` (tiles.py). With ``instanced``, the parts façades repeat
    are GPU instances, in each building's glb and across the merged models. With
    ``timings``, the report file keeps the times (else null there: reproducible bytes).
    The texture pictures are stored once for the run, in ``textures/`` (texture_store.py),
    and every model names them there; with ``shared_textures`` False, each glb embeds its own.
    With ``ground``, the district's ground too (ground.py): ``<name>.ground.glb``, in the
    merged model and as a tile of the 3D Tiles.

    Buildings run in ``jobs`` local worker processes, or, with ``scheduler`` (a Dask
    scheduler's address), on that Dask cluster: the same tasks, the same axes solved
    ahead and the same ``build`` function either way, so both give the same files."""
    started = time.perf_counter()
    check_output(outdir, city.manifest.name)
    outdir = outdir.resolve()  # workers, Dask's too, may run in another folder
    level = max((*lods, merged_lod))  # the finest any output needs
    ahead = planned(city, outdir, bbox, limit, usd, instanced, level, shared_textures)
    with claimed(outdir, city.manifest.name):  # leftovers of a killed run removed
        return _build(
            city,
            outdir,
            ahead.tasks,
            ahead.found,
            ahead.replaced,
            ahead.kept,
            jobs,
            resume,
            progress,
            scheduler,
            usd,
            started,
            ahead.straight,
            lods,
            merged_lod,
            instanced,
            timings,
            ground,
        )


@dataclass(frozen=True)
class Planned:
    """A city read and planned, before any building: what the client holds all run."""

    found: FootprintSet  # as read, its footprints the outlines with parts alone
    replaced: dict[str, list[str]]  # outlines whose parts are built instead
    kept: dict[str, float]  # of those, the area (m²) still built of each
    straight: Straightened  # how many collinear nodes were merged (not the footprints)
    tasks: Packed[Task]  # a building each, in the manifest's order, packed


def planned(
    city: City,
    outdir: Path,
    bbox: BBox | None = None,
    limit: int | None = None,
    usd: bool = False,
    instanced: bool = False,
    level: int = 3,
    shared_textures: bool = True,
    region: int = REGION,
) -> Planned:
    """The footprints read (those in ``bbox``), an outline's tags given to its parts, the
    outlines with parts cut to what they leave, collinear nodes merged, the first
    ``limit`` planned (:func:`plan`) for ``outdir``.

    The file is surveyed first (footprints.py: the CRS, the origin, the far features),
    then the town is planned a region of at most ``region`` features at a time
    (regions.py), each with the features around it its buildings depend on, its tasks
    packed and the rest freed before the next; the tasks are then put in the manifest's
    order, and the warnings in the order planning the town at once gives them: the same
    tasks and warnings. With ``limit``, the town is one region (the first ``limit``
    buildings are planned among themselves)."""
    outdir = outdir.resolve()
    surveyed = survey(city.footprints, bbox, city.manifest.properties.names())
    same = Same()  # the town's choices and roofs, each held once
    made = bytearray(len(surveyed))  # 1 at the place of each feature that is a footprint
    near_doors: set[int] = set()  # the entrance points on some footprint's edge
    rejected: list[Rejected] = []
    outlines: list[tuple[int, Footprint]] = []  # outlines with parts (their Building)
    replaced: list[tuple[int, str, list[str], float]] = []  # and their parts, area kept
    nodes = changed = 0
    warned: list[tuple[int, Rejected]] = []  # planning's, by their first footprint's index
    spooled: Spooled[Task] = Spooled(dict(city.specs))  # the tasks, region by region
    keys = array("q")  # the index of each one's feature in the file
    for core in regions(surveyed.boxes, region if limit is None else len(surveyed) or 1):
        done = _region(
            city, surveyed, core, outdir, limit, usd, instanced, level, shared_textures, same
        )
        for place in done.made:
            made[place] = 1
        near_doors |= done.near_doors
        rejected += done.rejected
        outlines += done.outlines
        replaced += done.replaced
        nodes, changed = nodes + done.nodes, changed + done.changed
        warned += done.warned
        for key, task in zip(done.keys, done.tasks, strict=True):
            keys.append(key)
            spooled.append(task)
        del done
    warned.sort(key=lambda found: found[0])  # stable: a region's in their order
    names = FileNames(str(city.footprints))
    tasks: Packed[Task] = Packed(dict(city.specs))
    for position in np.argsort(np.frombuffer(keys, dtype=np.int64), kind="stable"):
        task = spooled[int(position)]
        names.add(task.footprint.id)
        tasks.append(task)
    del spooled, keys
    found = surveyed.found(
        [footprint for _, footprint in sorted(outlines, key=_first)],
        rejected,
        made,
        near_doors,
        [warning for _, warning in warned],
    )
    replaced.sort(key=lambda outline: outline[0])
    give_back()  # what planning freed (the footprints read, their neighbours...)
    return Planned(
        found,
        {key: parts for _, key, parts, _ in replaced},
        {key: area for _, key, _, area in replaced},
        Straightened((), nodes, changed),
        tasks,
    )


MARGIN = 1.0  # metres more than the party walls' tolerance around a region (regions.py)


@dataclass
class Region:
    """A region of a town planned (:func:`_region`): its buildings' tasks and what the
    town's report needs of them, each footprint's by its feature's index in the file."""

    keys: list[int]  # each task's feature's index
    tasks: Packed[Task]
    made: list[int]  # the survey's places of the region's features that are footprints
    near_doors: set[int]  # the entrance points found on some footprint's edge
    rejected: list[Rejected]  # the region's features that are no footprint
    outlines: list[tuple[int, Footprint]]  # its outlines with parts
    replaced: list[tuple[int, str, list[str], float]]  # and their parts, the area kept
    nodes: int  # collinear nodes merged in its footprints
    changed: int  # its footprints with some merged
    warned: list[tuple[int, Rejected]]  # planning's warnings, by the first footprint's


def _region(
    city: City,
    surveyed: Survey,
    core: Any,
    outdir: Path,
    limit: int | None,
    usd: bool,
    instanced: bool,
    level: int,
    shared_textures: bool,
    same: Same,
) -> Region:
    """The buildings of the features at ``core`` (places in the survey) planned with
    every feature around them they depend on (regions.py): read, outlines cut by their
    parts, collinear nodes merged and tasks made as for the whole town, the others read
    only as their neighbours."""
    defaults = city.manifest.defaults
    margin = max(defaults.party_wall_tolerance, ON_EDGE) + MARGIN
    places = around(surveyed.boxes, core, margin)
    doors = surveyed.doors_within(extent(surveyed.boxes, places, ON_EDGE))
    read = surveyed.read(places.tolist(), doors)
    del places
    inner = set(core.tolist())
    index_of = {f.id: surveyed.indices[place] for place, f in read.footprints}
    mine = {f.id for place, f in read.footprints if place in inner}
    indices = {surveyed.indices[place] for place in inner}
    footprints = [footprint for _, footprint in read.footprints]
    made = [place for place in read.made if place in inner]
    rejected = [r for r in read.rejected if r.index in indices]
    near_doors = read.near_doors
    del read  # the footprints as read, let go as they are made into tasks
    parted = replaced_outlines(footprints)
    built, kept = standing(city, inherited(footprints, parted), parted)
    outlines = [(index_of[f.id], f) for f in footprints if f.id in parted and f.id in mine]
    del footprints
    straight = straighten(
        built, defaults.collinear_angle, defaults.party_wall_tolerance, counted=mine
    )
    del built
    chosen = list(straight.footprints[: limit if limit is not None else None])
    nodes, changed = straight.nodes, straight.footprints_changed
    del straight
    tasks, warnings = plan(
        city,
        chosen,
        outdir,
        usd,
        instanced,
        level,
        shared_textures,
        core=mine,
        same=same,
        checked=False,
    )
    return Region(
        [index_of[task.footprint.id] for task in tasks],
        tasks,
        made,
        near_doors,
        rejected,
        outlines,
        [(key, f.id, parted[f.id], kept[f.id]) for key, f in outlines],
        nodes,
        changed,
        [(index_of[key], warning) for key, warning in warnings],
    )


def _first(pair: tuple[int, Any]) -> int:
    return pair[0]


def _build(
    city: City,
    outdir: Path,
    tasks: Sequence[Task],
    found: FootprintSet,
    replaced: dict[str, list[str]],
    kept: dict[str, float],
    jobs: int,
    resume: bool,
    progress: Callable[[int, int], None] | None,
    scheduler: str | None,
    usd: bool,
    started: float,
    straight: Straightened | None = None,
    lods: tuple[int, ...] = (),
    merged_lod: int = 3,
    instanced: bool = False,
    timings: bool = False,
    ground: bool = False,
) -> CityReport:
    """The planned buildings built (those built before skipped with ``resume``), then
    the merged models, the CityJSON and the report written; returns the report.

    The client holds no more a building than its task and its report entry as a line
    (report.py): the merged models, the CityJSON and the report are streamed to disk."""
    georef = Georef(found.crs, found.origin, found.unit)
    warned = {warning.id for warning in found.warnings}  # a few ids, those warned about
    present: set[str] = set()  # which of them are buildings of this run
    centroids = Points()  # each building's, in the manifest's order
    entries = Entries(len(tasks), outdir)
    built = bytearray(len(tasks))  # 1 for a building built (or kept), in the manifest's order
    tally = Tally()
    todo = array("q")  # positions of the buildings to build
    resumed = array("q")  # positions of the buildings kept from the last run
    hashes = Hashes()  # each building's (resume.py), in the manifest's order
    digests = spec_digests(city)
    previous = recorded(outdir, city.manifest.name) if resume else {}
    for index, task in enumerate(tasks):  # one pass: each read unpacks its tasks' chunk
        if task.footprint.id in warned:
            present.add(task.footprint.id)
        centroids.append(_centroid(task.footprint))
        hashes.append(building_hash(task, digests))
        entry = reusable(task, hashes[index], previous, usd)
        if entry is None:
            todo.append(index)
        else:
            entries.put(index, entry)
            built[index] = entry["status"] == "ok"
            tally.add(entry)
            resumed.append(index)
    del previous
    give_back()  # the last run's entries read (--resume)
    done = len(resumed)
    tileset = None
    if lods:  # 3D Tiles: a leaf's tiles are written as soon as its buildings are done
        tileset = TilesetWriter(outdir, georef, lods, centroids)
    local = scheduler is None
    building = Picked(tasks, todo)
    del todo
    mapped = stamped(  # each result at its task's position (the results' order is theirs)
        (
            (building.positions[k], result)
            for k, result in (
                _map_local(building, jobs) if local else _map_dask(building, str(scheduler))
            )
        ),
        hashes,
    )
    log = outdir / f"{city.manifest.name}.report.jsonl"  # a line a building, as they end
    try:
        outdir.mkdir(parents=True, exist_ok=True)
        with open(log, "wb") as lines:
            for index in resumed:
                lines.write(entries.line(index) + b"\n")
                _tiled(tileset, outdir, index, entries[index]["id"], built[index])
            for index, result in mapped:
                lines.write(entries.put(index, result) + b"\n")
                lines.flush()
                built[index] = result["status"] == "ok"
                tally.add(result)
                _tiled(tileset, outdir, index, result["id"], built[index])
                done += 1
                if done % EVERY == 0:  # what the tiles written since freed
                    give_back()
                if progress is not None:
                    progress(done, len(tasks))
    except OSError as error:
        raise OutputError(
            f"{outdir}: cannot write the report: {error.strerror or error}; the buildings "
            "built are kept: run again with --resume"
        ) from None

    finished = BuiltCity(
        city.manifest.name,
        outdir,
        tasks,
        bytes(built),
        centroids,
        found,
        replaced,
        georef,
        city.manifest.tiles,
        tileset,
        merged_lod,
        instanced,
        ground,
    )
    _prune_pictures(outdir)
    formats = ["glb", "3dtiles", "usd", "cityjson", "ground"]  # CITY_WRITERS' order: the report's
    asked = {"3dtiles": tileset is not None, "usd": usd}
    models: dict[str, Any] = {}
    for name in (name for name in formats if asked.get(name, True)):
        models |= _written(CITY_WRITERS[name], finished)
    report = CityReport(
        city.manifest.name,
        found.crs,
        list(found.origin),
        georeference(georef),
        entries,
        [_rejected(r) for r in found.rejected],
        [_warning(w) for w in (*(w for w in found.warnings if w.id in present), *found.ignored)],
        [{"id": key, "parts": ids, "kept_m2": kept[key]} for key, ids in sorted(replaced.items())],
        models,
        _summary(tally, found, kept, len(tasks), present, straight, time.perf_counter() - started),
        timings=timings,
    )
    try:
        with atomic_output(outdir / f"{city.manifest.name}.report.json") as out:
            for chunk in report.chunks():
                out.write(chunk.encode("utf-8"))
    except OSError as error:
        raise OutputError(
            f"{outdir}: cannot write the report: {error.strerror or error}; run again with --resume"
        ) from None
    return report


def _prune_pictures(outdir: Path) -> None:
    """The pictures of ``textures/`` that no building's glb in ``buildings/`` names
    removed (texture_store.py): an earlier run's, whose buildings changed since. Every
    glb there counts, this run's or not (a ``--limit`` leaves an earlier run's others)."""
    if not (outdir / TEXTURES).is_dir():
        return
    try:
        prune(outdir / TEXTURES, _building_glbs(outdir / BUILDINGS))
    except OSError as error:
        raise OutputError(
            f"{outdir}: cannot tidy the texture pictures: {error.strerror or error}; the "
            "buildings built are kept: run again with --resume"
        ) from None


def _building_glbs(buildings: Path) -> Iterator[Path]:
    """Every glb in ``buildings/``: in its shards (folders.py), and at its top, where runs
    before the shards wrote."""
    if not buildings.is_dir():
        return
    for entry in sorted(os.scandir(buildings), key=lambda entry: entry.name):
        if entry.name.endswith(".glb") and entry.is_file(follow_symlinks=False):
            yield Path(entry.path)
        elif SHARD.fullmatch(entry.name) and entry.is_dir(follow_symlinks=False):
            for inner in sorted(os.scandir(entry.path), key=lambda inner: inner.name):
                if inner.name.endswith(".glb") and inner.is_file(follow_symlinks=False):
                    yield Path(inner.path)


def _written(writer: CityWriter, finished: BuiltCity) -> dict[str, Any]:
    """What ``writer`` wrote of the city, for the report; OutputError (exit 1) when the
    disk refuses it: the buildings stay, for ``--resume``."""
    try:
        written: dict[str, Any] = writer.write(finished)
    except OSError as error:
        raise OutputError(
            f"{finished.outdir}: cannot write the {writer.what}: {error.strerror or error}; "
            "the buildings built are kept: run again with --resume"
        ) from None
    return written


def _summary(
    tally: Tally,
    found: FootprintSet,
    kept: dict[str, float],
    buildings: int,
    present: Container[str],
    straight: Straightened | None,
    seconds: float,
) -> Summary:
    """The report's summary of a run of ``buildings``: ``tally`` of them, what was read
    (the warnings about those ``present`` among them, and the features ignored)."""
    warned = [w for w in found.warnings if w.id in present] + list(found.ignored)
    return Summary(
        buildings=buildings,
        ok=tally.ok,
        failed=tally.failed,
        rejected=len(found.rejected),
        warnings=len(warned),
        outside_bbox=found.outside,
        replaced=sum(1 for area in kept.values() if area == 0),
        trimmed=sum(1 for area in kept.values() if area > 0),
        party_walls=tally.party_walls,
        plain_walls=tally.plain_by_reason(),
        collinear_nodes_merged=straight.nodes if straight else 0,
        warnings_by_tag=dict(sorted(Counter(w.reason.split(" ", 1)[0] for w in warned).items())),
        seconds=round(seconds, 2),
        ground=kind_counts(found.ground, found.built_up),
    )


def _tiled(
    tileset: TilesetWriter | None, outdir: Path, index: int, building_id: str, built: int
) -> None:
    """The building at ``index`` done (built or resumed, or failed: ``built`` 0), for the
    3D Tiles of its leaf: its glb (where :func:`plan` put it, in ``outdir``)."""
    if tileset is None:
        return
    try:
        glb = outdir / building_file(building_id) if built else None
        tileset.done(index, building_id, glb)
    except OSError as error:
        raise OutputError(
            f"{outdir}: cannot write the 3D Tiles: {error.strerror or error}; the "
            "buildings built are kept: run again with --resume"
        ) from None


def _rejected(rejected: Rejected) -> dict[str, Any]:
    """A rejected feature's report entry: its id, why, and where it is in the GeoJSON."""
    return {
        "id": rejected.id,
        "status": "rejected",
        "error": rejected.reason,
        "feature": rejected.index,
        "line": rejected.line,
        "column": rejected.column,
    }


def _warning(warned: Rejected) -> dict[str, Any]:
    """A built feature's report entry for what of its tags was ignored, and where."""
    return {
        "id": warned.id,
        "warning": warned.reason,
        "feature": warned.index,
        "line": warned.line,
        "column": warned.column,
    }


Submit = Callable[..., Any]  # a pool's or a Dask client's submit: (function, *args) -> future


def _chunk(tasks: int, workers: int) -> int:
    """Tasks handed to a worker at once: a few chunks a worker, 16 tasks a chunk at most."""
    return max(1, min(16, tasks // (max(1, workers) * 4)))


def _presolve(submit: Submit, tasks: Sequence[Task], chunk: int) -> dict[Slot, Axes]:
    """The axes every building needs (:func:`_needs`), each solved once, spread over the
    workers ``submit`` hands work to (a local pool's or a Dask cluster's), in rounds: the
    walls' own façades' first, then the fallback's for the walls their own does not fit
    (:func:`.axes_to_solve`). Each worker's cache is then seeded with them: no two
    workers solve one axis, and the layouts are those a worker would have solved itself,
    so the files are the same."""
    specs = {task.cache_key: task.spec for task in tasks}
    specs.update({f.key: f.spec for task in tasks for _, f in task.walls})
    specs.update({t.fallback[1].key: t.fallback[1].spec for t in tasks if t.fallback is not None})
    needs = _bounded(lambda batch: submit(_each, _needs, batch), tasks, chunk)
    tries = sorted({tried for _, need in needs for tried in need})
    solved: dict[Slot, Axes] = {}
    while slots := sorted(axes_to_solve(tries, solved)):
        jobs = [(specs[slot[0]], slot) for slot in slots]
        solved.update(found for _, found in _bounded(lambda b: submit(_each, _solve, b), jobs, 1))
    return dict(sorted(solved.items()))  # in order, whichever order they ended in


def _map_dask(tasks: Sequence[Task], scheduler: str) -> Iterator[tuple[int, dict[str, Any]]]:
    """The buildings on a Dask distributed cluster, results as they finish, each with its
    task's position in ``tasks`` (:func:`_bounded`): the axes are
    solved ahead over the cluster (:func:`_presolve`), sent to every worker once, and
    each worker's cache is seeded with them before its first building."""
    from distributed import Client

    with Client(scheduler, set_as_default=False) as client:
        chunk = _chunk(len(tasks), sum(client.nthreads().values()))
        solved = _presolve(functools.partial(client.submit, pure=False), tasks, chunk)
        [axes] = client.scatter([solved], broadcast=True, hash=False)
        yield from _bounded(
            lambda batch: client.submit(_build_seeded, batch, axes, axes.key, pure=False),
            tasks,
            chunk,
        )


def _map_local(tasks: Sequence[Task], jobs: int) -> Iterator[tuple[int, dict[str, Any]]]:
    """The buildings in ``jobs`` local processes, results as they finish, each with its
    task's position in ``tasks`` (:func:`_bounded`). With several
    processes, the axes every building needs are solved first (:func:`_presolve`) and
    handed to each process as it starts; one process solves them as it goes."""
    if jobs <= 1 or len(tasks) < 2:
        for index, task in enumerate(tasks):
            yield index, build(task)
        return
    chunk = _chunk(len(tasks), jobs)
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        solved = _presolve(pool.submit, tasks, chunk)
    with ProcessPoolExecutor(max_workers=jobs, initializer=_seed, initargs=(solved,)) as pool:
        yield from _bounded(lambda batch: pool.submit(_each, build, batch), tasks, chunk)


T = TypeVar("T")
R = TypeVar("R")


def _bounded(
    hand: Callable[[Sequence[T]], Any], items: Sequence[T], chunk: int
) -> Iterator[tuple[int, Any]]:
    """A map as a bounded stream: ``hand`` gives a chunk of ``chunk`` items to the workers
    (a future of their results, a local pool's or Dask's); results come as their chunks
    finish, whichever first, with at most IN_FLIGHT chunks handed out at once
    (``Executor.map`` would queue every item first, and a city of a million buildings with
    it; taking them in order would let one slow chunk hold up the rest). Each result
    comes with its item's position in ``items``: callers put them in order by it, with
    no map of their own from the results back to the items."""
    finished: queue.SimpleQueue[Any] = queue.SimpleQueue()
    pending: dict[Any, int] = {}  # each chunk's future and its first item's position (Dask
    # cancels a future nobody holds)

    def take() -> list[tuple[int, Any]]:
        future = finished.get()
        start = pending.pop(future)
        return list(enumerate(future.result(), start))

    for start in range(0, len(items), chunk):
        future = hand(items[start : start + chunk])
        pending[future] = start
        future.add_done_callback(finished.put)
        if len(pending) >= IN_FLIGHT:
            yield from take()
    while pending:
        yield from take()


def _each(function: Callable[[T], R], items: Sequence[T]) -> list[R]:
    return [function(item) for item in items]
