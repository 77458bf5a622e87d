"""Reading footprints from a Shapefile or a FlatGeobuf through pyogrio (GDAL), the other
formats national building datasets ship in.

pyogrio is an optional dependency (``pip install 'facadecli[gdal]'``: GDAL is some 100 MB):
without it, such a file is a SpecError saying how to get it. The first layer is read; each
record becomes a GeoJSON feature (its id the record's, its properties the attribute
columns), checked as a GeoJSON file's are, in the layer's CRS (a Shapefile without its
``.prj`` has none: exit 2).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pyproj
import pyproj.exceptions
import shapely
import shapely.errors

from facadecli.city.geojson import GeoJSON, NoPlaces, too_long
from facadecli.errors import SpecError
from facadecli.limits import GEOJSON_BYTES_MAX

SUFFIXES = (".shp", ".fgb")
HINT = "give a Shapefile (with its .prj) or a FlatGeobuf, a GeoPackage or a GeoJSON file"


def is_ogr(path: Path) -> bool:
    return path.suffix.lower() in SUFFIXES


def read_ogr(path: Path) -> GeoJSON:
    """The features and CRS of the file's first layer (see the module)."""
    file = str(path)
    try:
        import pyogrio.errors
        import pyogrio.raw
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
        meta, ids, geometries, columns = pyogrio.raw.read(path, return_fids=True)
    except (pyogrio.errors.DataSourceError, pyogrio.errors.DataLayerError) as error:
        raise SpecError.at(file, None, None, f"cannot read it: {error}", HINT) from None
    if not meta.get("crs"):
        raise SpecError.at(file, None, None, "the layer has no CRS (no .prj?)", HINT)
    try:
        crs = pyproj.CRS.from_user_input(meta["crs"])
    except pyproj.exceptions.CRSError:
        raise SpecError.at(file, None, None, f"unknown CRS {meta['crs']!r}", HINT) from None
    names = [str(name) for name in meta["fields"]]
    features = []
    for i, blob in enumerate(geometries):
        properties = {name: _value(column[i]) for name, column in zip(names, columns, strict=True)}
        features.append(
            {
                "type": "Feature",
                "id": int(ids[i]) if ids is not None else i,
                "properties": {k: v for k, v in properties.items() if v is not None},
                "geometry": _geometry(blob),
            }
        )
    return GeoJSON(file, features, crs, NoPlaces())


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
