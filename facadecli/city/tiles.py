"""A city's merged models: one ``<name>.glb`` of every building while it stays within a
glb's limits, and with ``tiles`` (or when it would not fit) one glb a square tile of the
map, so a district of any size loads in pieces (a glb's lengths are 32-bit: 4 GiB).

A building belongs to the tile its footprint's centroid lies in; tiles are named by their
column and row from the run's origin (``tiles/<name>_<i>_<j>.glb``) and listed, with
their bounds in local metres, in the outputs' CRS (named in the index) and in WGS 84
lon/lat, in ``<name>.tiles.json``. Every merged model carries the georeference of the
run's frame (georef.py) in its scene's ``extras``, and ``<name>.georef.json`` beside them
holds it too, with the CRS's WKT: it places every glb of the run, buildings' included.

The merged models are at one level of detail (``--lod``): 3, the buildings' own glb files
with their façades (the default); 2, walls and roofs; 1, blocks (lods.py), each made from
the CityJSON feature beside a building's glb."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pyproj

from facadecli.city.georef import Georef, georeference
from facadecli.city.lods import lod_glb
from facadecli.export.atomic import write_atomic
from facadecli.export.glb_merge import merge_glb
from facadecli.limits import MERGED_GLB_MAX

DEFAULT_TILE = 1000.0  # metres: the tiles' side when a merged model would not fit


def tile_of(centroid: tuple[float, float], size: float) -> tuple[int, int]:
    return math.floor(centroid[0] / size), math.floor(centroid[1] / size)


def merge_city(
    buildings: Iterable[tuple[str, Path, tuple[float, float]]],
    outdir: Path,
    name: str,
    size: float | None,
    georef: Georef,
    lod: int = 3,
    instanced: bool = False,
) -> dict[str, Any]:
    """Write the merged model(s) of the built buildings (id, glb file, centroid in local
    metres) at level of detail ``lod`` (with ``instanced``, each repeated part drawn by
    one node for all: :func:`.merge_glb`), and ``<name>.georef.json``; returns what was
    written for the report:
    ``merged`` (the one glb, or None when it would pass MERGED_GLB_MAX), ``tiles`` (the
    index file, or None) and ``georef``."""
    buildings = list(buildings)
    frame = georeference(georef)
    extras = {"georeference": frame}
    sidecar = f"{name}.georef.json"
    wkt = pyproj.CRS.from_user_input(georef.crs).to_wkt()
    write_atomic(outdir / sidecar, json.dumps({**frame, "crs_wkt": wkt}, indent=2) + "\n")
    total = sum(path.stat().st_size for _, path, _ in buildings)
    merged: str | None = f"{name}.glb"
    if total <= MERGED_GLB_MAX:
        merged_parts = ((bid, _at(path, lod)) for bid, path, _ in buildings)
        merge_glb(merged_parts, outdir / f"{name}.glb", extras, instanced)
    else:
        merged = None
        size = size or DEFAULT_TILE
    if size is None:
        return {"merged": merged, "tiles": None, "georef": sidecar}
    groups: dict[tuple[int, int], list[tuple[str, Path]]] = {}
    for bid, path, centroid in buildings:
        groups.setdefault(tile_of(centroid, size), []).append((bid, path))
    index = []
    for (i, j), members in sorted(groups.items()):
        file = f"tiles/{name}_{i}_{j}.glb"
        members_at = ((bid, _at(path, lod)) for bid, path in members)
        merge_glb(members_at, outdir / file, extras, instanced)
        bounds = (i * size, j * size, (i + 1) * size, (j + 1) * size)
        index.append(
            {
                "file": file,
                "column": i,
                "row": j,
                "buildings": len(members),
                "bounds": list(bounds),
                "bounds_crs": [*georef.in_crs(*bounds[:2]), *georef.in_crs(*bounds[2:])],
                "bounds_lonlat": georef.bounds_lonlat(bounds),
            }
        )
    document = {
        "name": name,
        "size": size,
        "crs": frame["crs"],
        "crs_url": frame["crs_url"],
        "origin": frame["origin"][:2],
        "tiles": index,
    }
    write_atomic(outdir / f"{name}.tiles.json", json.dumps(document, indent=2) + "\n")
    return {"merged": merged, "tiles": f"{name}.tiles.json", "georef": sidecar}


def _at(glb: Path, lod: int) -> Path | bytes:
    """A building's glb at ``lod``: its own file for 3, else made from its feature."""
    return glb if lod == 3 else lod_glb(glb, lod)
