"""What a ``facade city`` run built: what the writers that end it read
(:data:`facadecli.export.CITY_WRITERS`: the merged models, the 3D Tiles, the USD stage,
the CityJSON), each going over the buildings again in the manifest's order, none held.

A building's CityJSON feature is written by its worker beside its glb
(:func:`feature_file`); the CityJSON is made of those features."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from facadecli.city.building import building_solids, party_volumes
from facadecli.city.cityjson import BuildingSolids, building_object, grouped, outlines
from facadecli.city.footprints import FootprintSet, typed
from facadecli.city.georef import Georef

if TYPE_CHECKING:
    from facadecli.city.run import Task
    from facadecli.city.tileset import TilesetWriter


def feature_file(target: Path) -> Path:
    """Where a building's CityJSON feature goes, beside its glb (written before the glb,
    which marks the building done for --resume)."""
    return target.with_suffix(".city.jsonl")


def attributes(task: Task, top: float) -> dict[str, Any]:
    """A building's CityJSON attributes: its tags, how tall it is, its roof and spec."""
    return {
        **typed(task.footprint.properties),
        "measuredHeight": top,
        "roofType": task.roof.type,
        "facade": task.spec_key,
    }


def feature(task: Task) -> dict[str, Any]:
    """A building's CityJSON feature: the one its worker wrote, or (a building resumed from
    a run before features were written) made here from its volumes."""
    path = feature_file(task.target)
    if path.is_file():
        loaded: dict[str, Any] = json.loads(path.read_bytes())
        return loaded
    volumes = party_volumes(
        task.footprint, task.heights, task.roof, task.shared, task.tolerance, task.above
    )
    solids, top = building_solids(task.footprint, volumes)  # as its worker makes them
    return building_object(BuildingSolids(task.footprint.id, solids, attributes(task, top)))


@dataclass(frozen=True)
class BuiltCity:
    """A run's buildings once every one has ended: its tasks in the manifest's order and
    which of them were built (or kept by ``--resume``)."""

    name: str  # the manifest's: the outputs' names
    outdir: Path
    tasks: Sequence[Task]
    built: bytes  # 1 for a building built or kept, 0 for one that failed; the tasks' order
    centroids: Sequence[tuple[float, float]]  # each task's place, for its tile
    found: FootprintSet  # what was read: the CRS, the origin, the outlines
    replaced: dict[str, list[str]]  # outline id -> its parts' ids
    georef: Georef
    tile_size: float | None = None  # the manifest's ``tiles:``
    tileset: TilesetWriter | None = None  # with --3dtiles: leaves written as buildings ended
    merged_lod: int = 3  # the merged models' level of detail (``--lod``)
    instanced: bool = False  # repeated parts gathered as GPU instances (``--instance``)
    ground: bool = False  # the district's ground in the merged model and tiles (``--ground``)

    def ok(self) -> Iterator[Task]:
        """The buildings built, in the manifest's order."""
        return (task for task, made in zip(self.tasks, self.built, strict=True) if made)

    def placed(self) -> Iterator[tuple[str, Path, tuple[float, float]]]:
        """The buildings built: their id, glb and centroid (local metres)."""
        for task, made, centroid in zip(self.tasks, self.built, self.centroids, strict=True):
            if made:
                yield task.footprint.id, task.target, centroid

    def features(self) -> Iterator[dict[str, Any]]:
        """The CityJSON features of the buildings built, an outline's parts as one."""
        ids = (task.footprint.id for task in self.ok())  # a pass: none held
        found = outlines(self.found.footprints, self.replaced, ids)
        return grouped((feature(task) for task in self.ok()), found)
