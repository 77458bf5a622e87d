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

import contextlib
import itertools
import json
import math
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import pyproj

from facadecli.city.georef import Georef, georeference
from facadecli.city.lods import lod_glb
from facadecli.export.atomic import write_atomic
from facadecli.export.glb_merge import merge_glb
from facadecli.limits import MERGED_BUILDINGS_MAX, MERGED_GLB_MAX

DEFAULT_TILE = 1000.0  # metres: the tiles' side when a merged model would not fit


def tile_of(centroid: tuple[float, float], size: float) -> tuple[int, int]:
    return math.floor(centroid[0] / size), math.floor(centroid[1] / size)


def merge_city(
    buildings: Callable[[], Iterable[tuple[str, Path, tuple[float, float]]]],
    outdir: Path,
    name: str,
    size: float | None,
    georef: Georef,
    streamed: bool = False,
    lod: int = 3,
    instanced: bool = False,
    ground: Path | None = None,
) -> dict[str, Any]:
    """Write the merged model(s) of the built buildings (``buildings()`` gives them again
    each time it is called: id, glb file, centroid in local metres; none is held) at level
    of detail ``lod`` (with ``instanced``, each repeated part drawn by one node for all:
    :func:`.merge_glb`), and ``<name>.georef.json``; returns what was written for the
    report: ``merged`` (the one glb, or None and why in ``merged_left_out``: more than
    MERGED_BUILDINGS_MAX buildings or MERGED_GLB_MAX bytes), ``tiles`` (the index file, or
    None) and ``georef``. The tiles are written when ``size`` is given, or in DEFAULT_TILE
    squares when there is no merged glb, unless the run writes 3D Tiles (``streamed``), a
    viewer's way in then. With ``ground`` (a glb: city/ground.py), the merged model holds
    it too, after the buildings, under a root node ``ground``."""
    frame = georeference(georef)
    extras = {"georeference": frame}
    sidecar = f"{name}.georef.json"
    wkt = pyproj.CRS.from_user_input(georef.crs).to_wkt()
    write_atomic(outdir / sidecar, json.dumps({**frame, "crs_wkt": wkt}, indent=2) + "\n")
    count = total = 0
    for _, path, _ in buildings():
        count += 1
        total += path.stat().st_size
    merged: str | None = f"{name}.glb"
    left_out = _left_out(count, total, "open 3dtiles/tileset.json" if streamed else _TILED)
    if left_out is None:
        merged_parts = ((bid, _at(path, lod)) for bid, path, _ in buildings())
        laid: list[tuple[str, Path | bytes]] = [] if ground is None else [("ground", ground)]
        merge_glb(itertools.chain(merged_parts, laid), outdir / f"{name}.glb", extras, instanced)
    else:
        merged = None
        size = size or (None if streamed else DEFAULT_TILE)
        with contextlib.suppress(FileNotFoundError):  # an earlier, smaller run's: stale
            (outdir / f"{name}.glb").unlink()
    written: dict[str, Any] = {"merged": merged}
    if left_out is not None:
        written["merged_left_out"] = left_out
    if size is None:
        return {**written, "tiles": None, "georef": sidecar}
    counts = Counter(tile_of(centroid, size) for _, _, centroid in buildings())
    index = []
    for (i, j), members in sorted(counts.items()):  # a pass each: no tile's list is held
        file = f"tiles/{name}_{i}_{j}.glb"
        tiled = (
            (bid, _at(path, lod))
            for bid, path, centroid in buildings()
            if tile_of(centroid, size) == (i, j)
        )
        merge_glb(tiled, outdir / file, extras, instanced)
        bounds = (i * size, j * size, (i + 1) * size, (j + 1) * size)
        index.append(
            {
                "file": file,
                "column": i,
                "row": j,
                "buildings": members,
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
    return {**written, "tiles": f"{name}.tiles.json", "georef": sidecar}


_TILED = "open the tiles (tiles/), or use --3dtiles, which a viewer streams"


def _left_out(count: int, total: int, instead: str) -> str | None:
    """Why a run's buildings make no single merged glb (and what to open ``instead``), or
    None when they do."""
    if count > MERGED_BUILDINGS_MAX:
        return (
            f"{count:,} buildings, more than a single glb is made of "
            f"({MERGED_BUILDINGS_MAX:,}, MERGED_BUILDINGS_MAX): {instead}"
        )
    if total > MERGED_GLB_MAX:
        return (
            f"the buildings' models hold {total / 2**30:.1f} GiB, more than a glb may "
            f"({MERGED_GLB_MAX / 2**30:.0f} GiB, MERGED_GLB_MAX): {instead}"
        )
    return None


def _at(glb: Path, lod: int) -> Path | bytes:
    """A building's glb at ``lod``: its own file for 3, else made from its feature."""
    return glb if lod == 3 else lod_glb(glb, lod)
