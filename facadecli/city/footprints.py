"""Building footprints from GeoJSON, in local metres (SPEC 5).

RFC 7946 lon/lat is projected with pyproj to a transverse Mercator centred on the data (a
few millimetres of distortion across a district); a projected CRS named in the file's
legacy ``crs`` member is used as it is. Either way coordinates are then shifted so the
data's south-west corner is the origin, which keeps glTF's 32-bit floats precise.
Invalid rings are repaired with shapely's make_valid; what cannot be used is reported per
building, never raised.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyproj
import shapely
import shapely.affinity
import shapely.errors
from shapely.geometry import MultiPolygon, Polygon, shape
from shapely.geometry.polygon import orient

from facadecli.errors import SpecError

MIN_AREA = 1.0  # m²: smaller parts are slivers, not buildings


@dataclass(frozen=True)
class Footprint:
    """One building's ground plan: polygons in local metres (outer rings counter-clockwise)."""

    id: str
    parts: tuple[Polygon, ...]
    properties: dict[str, Any] = field(default_factory=dict)
    repaired: bool = False


@dataclass(frozen=True)
class Rejected:
    """A feature that yields no building, and why."""

    id: str
    reason: str


@dataclass(frozen=True)
class FootprintSet:
    footprints: tuple[Footprint, ...]
    rejected: tuple[Rejected, ...]
    crs: str  # what the input was in
    origin: tuple[float, float]  # where local (0, 0) is, in the projected CRS


def feature_id(feature: dict[str, Any], index: int) -> str:
    properties = feature.get("properties") or {}
    for value in (feature.get("id"), properties.get("osm_id"), properties.get("id")):
        if value not in (None, ""):
            return str(value)
    return f"feature-{index}"


def _crs(data: dict[str, Any]) -> pyproj.CRS:
    named = ((data.get("crs") or {}).get("properties") or {}).get("name")
    return pyproj.CRS.from_user_input(named) if named else pyproj.CRS.from_epsg(4326)


def read_footprints(path: Path) -> FootprintSet:
    """Footprints of every usable feature; rejected features with a reason."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as error:
        raise SpecError.at(
            str(path),
            error.lineno,
            error.colno,
            f"invalid GeoJSON: {error.msg}",
            "check the file's JSON syntax",
        ) from None
    except (OSError, UnicodeDecodeError) as error:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"cannot read the footprints: {error}",
            "check the path in the manifest",
        ) from None
    if not isinstance(data, dict) or not isinstance(data.get("features"), list):
        raise SpecError.at(
            str(path),
            1,
            1,
            "not a GeoJSON FeatureCollection",
            'write {"type": "FeatureCollection", "features": [...]}',
        )
    features = data["features"]
    source = _crs(data)
    geometries: list[tuple[str, dict[str, Any], Any]] = []
    rejected: list[Rejected] = []
    for index, feature in enumerate(features):
        fid = feature_id(feature, index)
        try:
            geometry = shape(feature["geometry"])
        except (KeyError, TypeError, ValueError, shapely.errors.GEOSException) as error:
            rejected.append(Rejected(fid, f"unreadable geometry: {error}"))
            continue
        if geometry.geom_type not in ("Polygon", "MultiPolygon"):
            rejected.append(Rejected(fid, f"a {geometry.geom_type}, not a polygon"))
            continue
        geometries.append((fid, feature.get("properties") or {}, geometry))
    if not geometries:
        return FootprintSet((), tuple(rejected), source.to_string(), (0.0, 0.0))
    transform = _projection(source, [g for _, _, g in geometries])
    projected = [
        (fid, props, shapely.transform(g, transform, interleaved=False))
        for fid, props, g in geometries
    ]
    minx = min(g.bounds[0] for _, _, g in projected)
    miny = min(g.bounds[1] for _, _, g in projected)
    footprints = []
    for fid, properties, geometry in projected:
        local = shapely.affinity.translate(geometry, -minx, -miny)
        repaired = False
        if not local.is_valid:
            local = shapely.make_valid(local)
            repaired = True
        parts = tuple(orient(part, sign=1.0) for part in _polygons(local) if part.area >= MIN_AREA)
        if not parts:
            rejected.append(Rejected(fid, "no part of at least 1 m² (degenerate footprint)"))
            continue
        footprints.append(Footprint(fid, parts, dict(properties), repaired))
    return FootprintSet(tuple(footprints), tuple(rejected), source.to_string(), (minx, miny))


def _polygons(geometry: Any) -> list[Polygon]:
    if isinstance(geometry, Polygon):
        return [geometry]
    if isinstance(geometry, MultiPolygon):
        return list(geometry.geoms)
    if hasattr(geometry, "geoms"):  # a collection from make_valid: keep its polygons
        return [p for g in geometry.geoms for p in _polygons(g)]
    return []


def _projection(source: pyproj.CRS, geometries: list[Any]) -> Any:
    """A function (x, y) -> (x, y) in metres."""
    if not source.is_geographic:
        return lambda x, y: (x, y)
    bounds = shapely.GeometryCollection(geometries).bounds
    lon = (bounds[0] + bounds[2]) / 2
    lat = (bounds[1] + bounds[3]) / 2
    local = pyproj.CRS.from_proj4(
        f"+proj=tmerc +lat_0={lat:.7f} +lon_0={lon:.7f} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m"
    )
    transformer = pyproj.Transformer.from_crs(source, local, always_xy=True)
    return transformer.transform


_NUMBER = re.compile(r"[-+]?\d+(?:[.,]\d+)?")


def number(value: Any) -> float | None:
    """A number from a property: 12, 12.5, "12.5", "12,5 m", "3;4" (the first one)."""
    if isinstance(value, bool) or value is None:
        return None
    if isinstance(value, (int, float)):
        return float(value) if math.isfinite(value) else None
    match = _NUMBER.search(str(value))
    return float(match.group().replace(",", ".")) if match else None


def building_height(properties: dict[str, Any], default: float, floor_height: float) -> float:
    """``height`` (or ``measuredHeight``), else levels x floor height, else the default."""
    for key in ("height", "measuredHeight"):
        height = number(properties.get(key))
        if height is not None and height > 0:
            return height
    for key in ("levels", "building:levels"):
        levels = number(properties.get(key))
        if levels is not None and levels > 0:
            return levels * floor_height
    return default
