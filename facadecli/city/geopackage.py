"""Reading footprints from a GeoPackage (OGC 12-128), the format national building datasets
ship in (the French BD TOPO, the Dutch BAG, the Finnish buildings), with the standard
library's sqlite3 and shapely: no GDAL.

The first feature table (by name) is read; each row becomes a GeoJSON feature (its id the
row's primary key, its properties the other columns, blobs left out), so the footprints
are checked exactly as a GeoJSON file's are; the rows are read one at a time as the
survey walks them (:class:`Rows`), never the whole table at once. The table's CRS comes from
``gpkg_spatial_ref_sys`` (an EPSG code, else the WKT definition). A file that is not a
GeoPackage, or has no feature table or no CRS, is a SpecError (exit 2); a row whose
geometry cannot be read is a feature the caller rejects with its reason.

A feature table may be a view, and a view may never end (a recursive query) or make
values far larger than the file: the rows are counted first (at most GPKG_ROWS_MAX),
SQLite's work is counted in its virtual machine's steps (a budget from the file's size,
never seconds), a value may not be longer than the file, and the values read may not
pass the file's size by more than GPKG_BYTES_FREE. Each is exit 2 naming the limit.
"""

from __future__ import annotations

import contextlib
import json
import sqlite3
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import pyproj
import pyproj.exceptions
import shapely
import shapely.errors

from facadecli.city.geojson import (
    GeoJSON,
    NoPlaces,
    changed_while_read,
    printable,
    too_long,
)
from facadecli.errors import SpecError
from facadecli.limits import (
    GEOJSON_BYTES_MAX,
    GPKG_BYTES_FREE,
    GPKG_ROWS_MAX,
    GPKG_STEPS_FREE,
    GPKG_STEPS_PER_BYTE,
)

ENVELOPES = {0: 0, 1: 32, 2: 48, 3: 48, 4: 64}  # envelope code -> bytes (GeoPackage 2.1.3)
HINT = "give a GeoPackage (.gpkg) with a feature table, or a GeoJSON file"


STEPS = 10_000  # SQLite steps between two counts of the budget
LIMIT_HINT = "give the buildings as a plain table, or cut the district into smaller files"


class _Budget:
    """SQLite's progress handler: counts the steps and stops the query past ``steps``."""

    def __init__(self, steps: int):
        self.left = steps
        self.spent = False

    def __call__(self) -> int:
        self.left -= STEPS
        self.spent = self.left < 0
        return int(self.spent)


def read_geopackage(path: Path) -> GeoJSON:
    """The CRS of the first feature table and its rows as features, read from the file one
    at a time as they are iterated (:class:`Rows`; see the module)."""
    file = str(path)
    size = path.stat().st_size
    if size > GEOJSON_BYTES_MAX:
        raise too_long(path)
    steps = GPKG_STEPS_FREE + GPKG_STEPS_PER_BYTE * size
    budget = _Budget(steps)
    try:
        with _connected(path, size, budget) as db:
            tables = db.execute(
                "SELECT c.table_name, g.column_name, g.srs_id FROM gpkg_contents c "
                "JOIN gpkg_geometry_columns g ON c.table_name = g.table_name "
                "WHERE c.data_type = 'features' ORDER BY c.table_name"
            ).fetchall()
            if not tables:
                raise SpecError.at(file, None, None, "the GeoPackage has no feature table", HINT)
            table, column, srs = tables[0]
            crs = _crs(db, srs, file)
            count = _count(db, str(table), file)
    except sqlite3.Error as error:
        raise _refused(error, budget, steps, size, file) from None
    rows = Rows(path, str(table), column, count, (steps, budget.left))
    return GeoJSON(file, rows, crs, NoPlaces())


@contextlib.contextmanager
def _connected(path: Path, size: int, budget: _Budget) -> Iterator[sqlite3.Connection]:
    """The file opened read-only, no value longer than the file, SQLite's work counted."""
    with contextlib.closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as db:
        db.setlimit(sqlite3.SQLITE_LIMIT_LENGTH, max(size, 1 << 20))
        db.set_progress_handler(budget, STEPS)
        yield db


def _refused(error: sqlite3.Error, budget: _Budget, steps: int, size: int, file: str) -> SpecError:
    """What SQLite's refusal means for the user: a budget spent, a value too long, or a
    file that is not a GeoPackage."""
    if budget.spent:
        message = (
            f"reading the feature table takes more than {steps:,} steps of SQLite's work "
            f"(limit: {GPKG_STEPS_PER_BYTE} a byte of the file and {GPKG_STEPS_FREE:,}: "
            "a view that does not end?)"
        )
        return SpecError.at(file, None, None, message, LIMIT_HINT)
    if getattr(error, "sqlite_errorname", "") == "SQLITE_TOOBIG":
        message = f"a value of the feature table is longer than the file ({size:,} bytes)"
        return SpecError.at(file, None, None, message, LIMIT_HINT)
    return SpecError.at(file, None, None, f"not a GeoPackage: {error}", HINT)


def _count(db: sqlite3.Connection, table: str, file: str) -> int:
    """The table's rows, at most GPKG_ROWS_MAX (more: a SpecError)."""
    quoted = table.replace('"', '""')
    (count,) = db.execute(
        f'SELECT count(*) FROM (SELECT 1 FROM "{quoted}" LIMIT {GPKG_ROWS_MAX + 1})'
    ).fetchone()
    if count > GPKG_ROWS_MAX:
        message = f"the feature table '{printable(table)}' has more than {GPKG_ROWS_MAX:,} rows"
        raise SpecError.at(file, None, None, message, LIMIT_HINT)
    return int(count)


class Rows(Iterable[dict[str, Any]]):
    """A feature table's rows as features, read from the file one at a time as they are
    iterated (the survey's one pass: a row's feature is not held once the next is read);
    their values' bytes counted as they come, SQLite's work against what the first read
    left of the budget (``steps``: the whole budget, and what is left of it)."""

    def __init__(
        self, path: Path, table: str, column: str, count: int, steps: tuple[int, int]
    ) -> None:
        self.path = path
        self.table = table
        self.column = column
        self.count = count
        self.steps = steps

    def __iter__(self) -> Iterator[dict[str, Any]]:
        file = str(self.path)
        size = self.path.stat().st_size
        budget = _Budget(self.steps[1])
        quoted = self.table.replace('"', '""')
        name = printable(self.table)
        most, read, found = size + GPKG_BYTES_FREE, 0, 0
        try:
            with _connected(self.path, size, budget) as db:
                key = _primary_key(db, self.table)
                rows = db.execute(f'SELECT * FROM "{quoted}"')
                names = [description[0] for description in rows.description]
                for row in rows:
                    read += sum(len(v) for v in row if isinstance(v, (str, bytes)))
                    if read > most:
                        message = (
                            f"reading the feature table '{name}' makes more than {most:,} "
                            f"bytes (the file's size and {GPKG_BYTES_FREE:,}: a view?)"
                        )
                        raise SpecError.at(file, None, None, message, LIMIT_HINT)
                    found += 1
                    yield _feature(dict(zip(names, row, strict=True)), self.column, key)
        except sqlite3.Error as error:
            raise _refused(error, budget, self.steps[0], size, file) from None
        if found != self.count:
            raise changed_while_read(file)


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
