"""Reading footprints from a GeoPackage (OGC 12-128), the format national building datasets
ship in (the French BD TOPO, the Dutch BAG, the Finnish buildings), with the standard
library's sqlite3 and shapely: no GDAL.

The first feature table (by name) is read; each row becomes a GeoJSON feature (its id the
row's primary key, its properties the other columns, blobs left out), so the footprints
are checked exactly as a GeoJSON file's are. The table's CRS comes from
``gpkg_spatial_ref_sys`` (an EPSG code, else the WKT definition). A file that is not a
GeoPackage, or has no feature table or no CRS, is a SpecError (exit 2); a row whose
geometry cannot be read is a feature the caller rejects with its reason.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import Any

import pyproj
import pyproj.exceptions
import shapely
import shapely.errors

from facadecli.city.geojson import GeoJSON, NoPlaces, too_long
from facadecli.errors import SpecError
from facadecli.limits import GEOJSON_BYTES_MAX

ENVELOPES = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}  # envelope code -> bytes (GeoPackage 2.1.3)
HINT = "give a GeoPackage (.gpkg) with a feature table, or a GeoJSON file"


def read_geopackage(path: Path) -> GeoJSON:
    """The features and CRS of the first feature table (see the module)."""
    file = str(path)
    if path.stat().st_size > GEOJSON_BYTES_MAX:
        raise too_long(path)
    try:
        with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as db:
            tables = db.execute(
                "SELECT c.table_name, g.column_name, g.srs_id FROM gpkg_contents c "
                "JOIN gpkg_geometry_columns g ON c.table_name = g.table_name "
                "WHERE c.data_type = 'features' ORDER BY c.table_name"
            ).fetchall()
            if not tables:
                raise SpecError.at(file, None, None, "the GeoPackage has no feature table", HINT)
            table, column, srs = tables[0]
            crs = _crs(db, srs, file)
            rows = db.execute(f'SELECT * FROM "{str(table).replace(chr(34), chr(34) * 2)}"')
            names = [description[0] for description in rows.description]
            key = _primary_key(db, str(table))
            features = [_feature(dict(zip(names, row, strict=True)), column, key) for row in rows]
    except sqlite3.Error as error:
        raise SpecError.at(file, None, None, f"not a GeoPackage: {error}", HINT) from None
    return GeoJSON(file, features, crs, NoPlaces())


def _crs(db: sqlite3.Connection, srs: Any, file: str) -> pyproj.CRS:
    found = db.execute(
        "SELECT organization, organization_coordsys_id, definition FROM gpkg_spatial_ref_sys "
        "WHERE srs_id = ?",
        (srs,),
    ).fetchone()
    if found is None or srs in (0, -1):
        raise SpecError.at(file, None, None, f"the feature table's CRS ({srs}) is undefined", HINT)
    organization, code, definition = found
    try:
        if str(organization).upper() == "EPSG":
            return pyproj.CRS.from_epsg(int(code))
        return pyproj.CRS.from_wkt(str(definition))
    except (pyproj.exceptions.CRSError, ValueError, TypeError):
        raise SpecError.at(
            file, None, None, f"the feature table's CRS ({organization} {code}) is unknown", HINT
        ) from None


def _primary_key(db: sqlite3.Connection, table: str) -> str | None:
    quoted = table.replace('"', '""')
    for row in db.execute(f'PRAGMA table_info("{quoted}")'):
        if row[5]:  # pk
            return str(row[1])
    return None


def _feature(row: dict[str, Any], column: str, key: str | None) -> dict[str, Any]:
    """A row as a GeoJSON feature (its geometry None when it cannot be read)."""
    properties = {
        name: value
        for name, value in row.items()
        if name not in (column, key) and not isinstance(value, bytes)
    }
    feature: dict[str, Any] = {"type": "Feature", "properties": properties}
    if key is not None:
        feature["id"] = row[key]
    feature["geometry"] = _geometry(row.get(column))
    return feature


def _geometry(blob: Any) -> Any:
    """A GeoPackage geometry blob as a GeoJSON geometry (None when it is not one)."""
    if not isinstance(blob, bytes) or len(blob) < 8 or blob[:2] != b"GP":
        return None
    size = ENVELOPES.get((blob[3] >> 1) & 0b111)
    if size is None or blob[3] & 0b10000:  # an unknown envelope, or an empty geometry
        return None
    try:
        geometry = shapely.from_wkb(blob[8 + size :])
    except (shapely.errors.GEOSException, ValueError):
        return None
    return json.loads(shapely.to_geojson(geometry))
