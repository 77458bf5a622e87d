"""A demo district the project makes itself (``make city``): blocks of rectangular and
L-shaped footprints along a street grid, with OSM-like properties, in a projected CRS:
apartment blocks, houses, a shop in every other block (a shop front on its front wall),
and a church now and then; the houses' walls take tones of their brick by the seed."""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

from facadecli.export.atomic import write_atomic

MANIFEST = """\
version: 1
name: {name}
footprints: footprints.geojson
defaults:
  facade: {specs}/townhouse.yaml
  height: 12.0
  floor_height: 3.2
  roof: {{type: gable, pitch: 35}}
  min_facade_width: 3.0
  palette: ["#9c4a32", "#86402b", "#af5338", "#93462f"]  # tones of the townhouse's brick
rules:
  - when: {{building: church}}
    facade: {specs}/church.yaml
    roof: {{type: gable, pitch: 50}}
    palette: []
  - when: {{shop: "*"}}
    walls: [{{side: front, facade: {specs}/shop-front.yaml}}]
  - when: {{building: apartments, building:levels: "7"}}
    facade: {specs}/terraced-house.yaml
    roof: {{type: flat, parapet: 0.6}}
    palette: ["#e8e4dc", "#c8c4bd", "#fffbf2", "#dad6cf"]  # tones of its render
  - when: {{building: apartments}}
    facade: {specs}/terraced-house.yaml
    roof: {{type: hip, pitch: 30}}
    palette: ["#e8e4dc", "#c8c4bd", "#fffbf2", "#dad6cf"]
"""


SHOPS = ("bakery", "books", "clothes", "hardware")


def district(blocks: int = 3, seed: int = 0) -> dict[str, object]:
    """A GeoJSON FeatureCollection: ``blocks`` x ``blocks`` blocks of 4 buildings each."""
    rng = random.Random(seed)
    features: list[dict[str, object]] = []
    block, street = 40.0, 12.0
    for bx in range(blocks):
        for by in range(blocks):
            x0, y0 = bx * (block + street), by * (block + street)
            for k in range(4):
                depth = rng.choice((12.0, 14.0, 16.0))
                width = rng.choice((9.4, 14.0, 18.0))
                ox = x0 + (k % 2) * (block - width)
                oy = y0 + (k // 2) * (block - depth)
                ring = [(ox, oy), (ox + width, oy), (ox + width, oy + depth), (ox, oy + depth)]
                if k == 3:  # an L
                    ring = [
                        (ox, oy),
                        (ox + width, oy),
                        (ox + width, oy + depth),
                        (ox + width / 2, oy + depth),
                        (ox + width / 2, oy + depth / 2),
                        (ox, oy + depth / 2),
                    ]
                properties: dict[str, object] = {"osm_id": f"way/{1000 + len(features)}"}
                if k == 0:
                    properties["building"] = "apartments"
                    properties["building:levels"] = str(rng.choice((5, 6, 7)))
                else:
                    properties["building"] = "yes"
                    properties["height"] = rng.choice((9.6, 12.8))
                if k == 1 and (bx + by) % 2 == 0:
                    properties["shop"] = SHOPS[(bx + by * blocks) % len(SHOPS)]
                if k == 2 and (bx * 3 + by) % 7 == 3:
                    properties.update(building="church", height=17.0)
                features.append(
                    {
                        "type": "Feature",
                        "id": properties["osm_id"],
                        "properties": properties,
                        "geometry": {
                            "type": "Polygon",
                            "coordinates": [
                                [[x + 100000.0, y + 400000.0] for x, y in [*ring, ring[0]]]
                            ],
                        },
                    }
                )
    return {
        "type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
        "features": features,
    }


def write_demo(folder: Path, specs: Path, blocks: int = 3, name: str = "demo-district") -> Path:
    """Write the demo's footprints and manifest into ``folder``; returns the manifest."""
    folder.mkdir(parents=True, exist_ok=True)
    write_atomic(folder / "footprints.geojson", json.dumps(district(blocks)) + "\n")
    relative = Path(os.path.relpath(specs.resolve(), folder.resolve())).as_posix()
    manifest = folder / "district.yaml"
    write_atomic(manifest, MANIFEST.format(name=name, specs=relative))
    return manifest
