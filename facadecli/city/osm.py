"""Reading footprints from an OpenStreetMap extract (``.osm.pbf``, ``.osm``, ``.osm.bz2``,
``.osm.gz``) with pyosmium, as one downloads them (Geofabrik, BBBike, the OSM website).

Every area tagged ``building`` or ``building:part`` is a footprint: closed ways and
multipolygon relations, assembled by libosmium (holes and all). Its id is ``way/<id>`` or
``relation/<id>``, its properties its tags, so heights, levels, roof shapes, colours and
building parts work as in a GeoJSON export (the city's S3DB rules). Coordinates are
lon/lat (EPSG:4326). The file is read in one streaming pass per object kind; only the
buildings are kept. A file libosmium cannot read is a SpecError (exit 2).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pyproj

from facadecli.city.geojson import GeoJSON, NoPlaces
from facadecli.errors import SpecError

SUFFIXES = (".osm.pbf", ".pbf", ".osm", ".osm.bz2", ".osm.gz")
KEYS = ("building", "building:part")
HINT = "give an OpenStreetMap extract (.osm.pbf or .osm), a GeoPackage or a GeoJSON file"


def is_osm(path: Path) -> bool:
    return path.name.lower().endswith(SUFFIXES)


def read_osm(path: Path) -> GeoJSON:
    """The building areas of an extract (see the module)."""
    import osmium  # imported here: only OSM extracts need it

    file = str(path)
    factory = osmium.geom.GeoJSONFactory()
    features: list[dict[str, Any]] = []
    try:
        processor = (
            osmium.FileProcessor(file)
            .with_areas(osmium.filter.KeyFilter(*KEYS))
            .with_filter(osmium.filter.KeyFilter(*KEYS))
        )
        for area in processor:
            if not isinstance(area, osmium.osm.Area):
                continue
            kind = "way" if area.from_way() else "relation"
            try:
                geometry = json.loads(factory.create_multipolygon(area))
            except RuntimeError:  # libosmium could not build it: the caller rejects it
                geometry = None
            features.append(
                {
                    "type": "Feature",
                    "id": f"{kind}/{area.orig_id()}",
                    "properties": {tag.k: tag.v for tag in area.tags},
                    "geometry": geometry,
                }
            )
    except RuntimeError as error:
        raise SpecError.at(file, None, None, f"not an OSM extract: {error}", HINT) from None
    return GeoJSON(file, features, pyproj.CRS.from_epsg(4326), NoPlaces())
