"""Reading footprints from a Shapefile or a FlatGeobuf through pyogrio (GDAL), the other
formats national building datasets ship in.

pyogrio is an optional dependency (``pip install 'facadecli[gdal]'``: GDAL is some 100 MB):
without it, such a file is a SpecError saying how to get it. The first layer is read; each
record becomes a GeoJSON feature (its id the record's, its properties the attribute
columns), checked as a GeoJSON file's are, in the layer's CRS (a Shapefile without its
``.prj`` has none: exit 2). The records are read from the file a batch at a time as the
survey walks them, not the whole layer at once.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import pyproj
import pyproj.exceptions
import shapely
import shapely.errors

from facadecli.city.geojson import GeoJSON, NoPlaces, changed_while_read, too_long
from facadecli.errors import SpecError
from facadecli.limits import GEOJSON_BYTES_MAX

SUFFIXES = (".shp", ".fgb")
HINT = "give a Shapefile (with its .prj) or a FlatGeobuf, a GeoPackage or a GeoJSON file"


def is_ogr(path: Path) -> bool:
    return path.suffix.lower() in SUFFIXES


def read_ogr(path: Path) -> GeoJSON:
    """The CRS of the file's first layer and its records as features, read BATCH at a
    time as they are iterated (:class:`Records`; see the module)."""
    file = str(path)
    try:
        import pyogrio
        import pyogrio.errors
    except ImportError:
        raise SpecError.at(
            file,
            None,
            None,
            f"reading {path.suffix} files needs pyogrio (GDAL)",
            "pip install 'facadecli[gdal]', or convert the file to GeoPackage or GeoJSON",
        ) from None
    if path.stat().st_size > GEOJSON_BYTES_MAX:
        raise too_long(path)
    try:
        info = pyogrio.read_info(path, force_feature_count=True)
    except (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError) as error:
        raise SpecError.at(file, None, None, f"cannot read it: {error}", HINT) from None
    if not info.get("crs"):
        raise SpecError.at(file, None, None, "the layer has no CRS (no .prj?)", HINT)
    try:
        crs = pyproj.CRS.from_user_input(info["crs"])
    except pyproj.exceptions.CRSError:
        raise SpecError.at(file, None, None, f"unknown CRS {info['crs']!r}", HINT) from None
    return GeoJSON(file, Records(path, int(info["features"])), crs, NoPlaces())


BATCH = 1024  # records read from the file at once


class Records(Iterable[dict[str, Any]]):
    """The first layer's records as GeoJSON features (its id the record's, its properties
    the attribute columns), read from the file BATCH at a time as they are iterated."""

    def __init__(self, path: Path, count: int) -> None:
        self.path = path
        self.count = count

    def __iter__(self) -> Iterator[dict[str, Any]]:
        import pyogrio.errors
        import pyogrio.raw

        file = str(self.path)
        found = 0
        for skip in range(0, self.count, BATCH):
            try:
                meta, ids, geometries, columns = pyogrio.raw.read(
                    self.path, return_fids=True, skip_features=skip, max_features=BATCH
                )
            except (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError) as error:
                raise SpecError.at(file, None, None, f"cannot read it: {error}", HINT) from None
            names = [str(name) for name in meta["fields"]]
            for i, blob in enumerate(geometries):
                found += 1
                yield _feature(
                    int(ids[i]) if ids is not None else skip + i,
                    {name: _value(column[i]) for name, column in zip(names, columns, strict=True)},
                    blob,
                )
            del meta, ids, geometries, columns
        if found != self.count:
            raise changed_while_read(file)


def _feature(fid: int, properties: dict[str, Any], blob: Any) -> dict[str, Any]:
    return {
        "type": "Feature",
        "id": fid,
        "properties": {k: v for k, v in properties.items() if v is not None},
        "geometry": _geometry(blob),
    }


def _value(value: Any) -> Any:
    """A column's value as plain JSON (numpy scalars made Python's; NaN and bytes left out)."""
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, bytes) or (isinstance(value, float) and not math.isfinite(value)):
        return None
    return value


def _geometry(blob: Any) -> Any:
    if blob is None:
        return None
    try:
        return json.loads(shapely.to_geojson(shapely.from_wkb(blob)))
    except (shapely.errors.GEOSException, ValueError, TypeError):
        return None
