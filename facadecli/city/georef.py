"""Where a city's outputs lie on the map: the named CRS of their metres and their origin.

Lon/lat footprints are projected into the UTM zone (WGS 84, EPSG:326NN north of the
equator, 327NN south) of the middle of the data, with the Norwegian and Svalbard
exceptions of the UTM grid, and into the polar stereographic UPS (EPSG:5041, 5042) beyond
84° N and 80° S: a standard, conformal CRS in metres that CityJSON tools, QGIS, FME and
Cesium know by its EPSG code. Footprints across a zone's edge stay in the middle's zone
(PROJ's transverse Mercator is exact well beyond it; the scale factor there is about
1.001). Input in a projected CRS keeps that CRS.

Every output shares one local frame: metres from the run's origin (the south-west corner
of the footprints, in the CRS), heights from the buildings' ground (no vertical datum).
:func:`georeference` describes it for the glTF scenes' ``extras``, the
``<name>.georef.json`` sidecar and the report.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass
from typing import Any

import pyproj

LON_LAT = pyproj.CRS.from_epsg(4326)
GEOD = pyproj.Geod(ellps="WGS84")
STEP = 10.0  # metres: the grid step that measures grid north and the scale factor
AXES = (
    "glTF: x east, y up, z south; "
    "easting = origin[0] + x{per}, northing = origin[1] - z{per}, "
    "height = y above the buildings' ground"
)


def reference_system(crs: str) -> str | None:
    """The OGC URL (``https://www.opengis.net/def/crs/EPSG/0/<code>``) of ``crs`` when it is
    an EPSG code of a projected CRS in metres; None otherwise, and the metadata then has no
    referenceSystem: lon/lat is not the vertices' CRS (lon/lat input is projected to a
    UTM zone, whose code comes here), and a CRS in feet was scaled to metres. Heights are
    metres above the buildings' ground, in no vertical datum."""
    match = re.fullmatch(r"(?:EPSG:|urn:ogc:def:crs:EPSG::)(\d+)", crs.strip(), re.IGNORECASE)
    if match is None:
        return None
    try:
        found = pyproj.CRS.from_epsg(int(match.group(1)))
    except pyproj.exceptions.CRSError:
        return None
    units = {axis.unit_name for axis in found.axis_info}
    if not found.is_projected or units != {"metre"}:
        return None
    return f"https://www.opengis.net/def/crs/EPSG/0/{match.group(1)}"


def utm_epsg(lon: float, lat: float) -> int:
    """The EPSG code of the WGS 84 UTM zone of (lon, lat) (UPS beyond 84° N or 80° S)."""
    if lat > 84.0:
        return 5041  # WGS 84 / UPS North (E,N)
    if lat < -80.0:
        return 5042  # WGS 84 / UPS South (E,N)
    zone = min(60, math.floor((lon + 180.0) / 6.0) + 1)
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        zone = 32  # south-west Norway
    elif lat >= 72.0 and 0.0 <= lon < 42.0:  # Svalbard: 31X, 33X, 35X, 37X
        zone = 31 if lon < 9.0 else 33 if lon < 21.0 else 35 if lon < 33.0 else 37
    return (32600 if lat >= 0.0 else 32700) + zone


@dataclass(frozen=True)
class Georef:
    """The outputs' frame: ``crs`` (a pyproj string, ``EPSG:32632``), ``origin`` (local
    (0, 0) in metres, in that CRS scaled to metres) and ``unit`` (metres per unit of the
    CRS: 1, or 0.3048... for a CRS in feet, whose coordinates were scaled to metres)."""

    crs: str
    origin: tuple[float, float]
    unit: float = 1.0

    def in_crs(self, x: float, y: float) -> tuple[float, float]:
        """A local point (metres from the origin, north up) in the CRS's own units."""
        return (self.origin[0] + x) / self.unit, (self.origin[1] + y) / self.unit

    def _to_lonlat(self) -> pyproj.Transformer:
        return _to_lonlat(self.crs)

    def lonlat(self, x: float, y: float) -> tuple[float, float]:
        """A local point in WGS 84 degrees (lon, lat)."""
        lon, lat = self._to_lonlat().transform(*self.in_crs(x, y))
        return float(lon), float(lat)

    def bounds_lonlat(self, bounds: tuple[float, float, float, float]) -> list[float]:
        """Local bounds (west, south, east, north metres) as [west, south, east, north]
        WGS 84 degrees holding the whole box (its edges are followed, not its corners)."""
        west, south = self.in_crs(bounds[0], bounds[1])
        east, north = self.in_crs(bounds[2], bounds[3])
        box = self._to_lonlat().transform_bounds(west, south, east, north, densify_pts=21)
        return [round(float(v), 9) for v in box]

    def grid(self) -> tuple[float, float]:
        """At the origin: the bearing of grid north (degrees clockwise from true north)
        and the scale factor (grid metres a metre on the ground), measured on the ellipsoid."""
        lon, lat = self.lonlat(0.0, 0.0)
        north = self.lonlat(0.0, STEP)
        east = self.lonlat(STEP, 0.0)
        bearing, _, _ = GEOD.inv(lon, lat, north[0], north[1])
        _, _, distance = GEOD.inv(lon, lat, east[0], east[1])
        return float(bearing), STEP / float(distance)


@functools.lru_cache(maxsize=8)
def _to_lonlat(crs: str) -> pyproj.Transformer:
    return pyproj.Transformer.from_crs(pyproj.CRS.from_user_input(crs), LON_LAT, always_xy=True)


def georeference(georef: Georef) -> dict[str, Any]:
    """The frame as JSON: the CRS (code, OGC URL when it is an EPSG CRS in metres), the
    origin in it and in lon/lat, the axes, and grid north and scale at the origin."""
    lon, lat = georef.lonlat(0.0, 0.0)
    bearing, scale = georef.grid()
    easting, northing = georef.in_crs(0.0, 0.0)
    return {
        "crs": georef.crs,
        "crs_url": reference_system(georef.crs),
        "origin": [easting, northing, 0.0],
        "origin_lonlat": [round(lon, 9), round(lat, 9), 0.0],
        "metres_per_unit": georef.unit,
        "axes": AXES.format(per="" if georef.unit == 1.0 else " / metres_per_unit"),
        "grid_north_bearing": round(bearing, 6),
        "scale_factor": round(scale, 8),
    }
