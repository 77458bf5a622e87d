"""A demo district the project makes itself (``make city``): blocks of rectangular and
L-shaped footprints along a street grid, with OSM-like properties, in a projected CRS:
apartment blocks, houses, a shop in every other block (a shop front on its front wall),
and a church now and then; the houses' walls take tones of their brick by the seed, and
the cottage where the townhouse does not fit (a low house's walls). And
a generated town of terraces of any size (:func:`terraces`, for benchmarks)."""

from __future__ import annotations

import json
import math
import os
import random
from collections.abc import Iterator
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
{fallback}  palette: ["#9c4a32", "#86402b", "#af5338", "#93462f"]  # tones of the townhouse's brick
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
    # the cottage on the walls the townhouse does not fit: a 9.6 m house under its 35°
    # gable has 4.8 m of wall, too low for the townhouse's three storeys
    fallback = f"  fallback_facade: {relative}/cottage.yaml\n"
    write_atomic(manifest, MANIFEST.format(name=name, specs=relative, fallback=fallback))
    return manifest


TERRACE = 8  # houses in a row of a generated block; a block is two rows back to back
ROOFS = ("gabled", "gabled", "hipped", "flat", None)  # OSM roof:shape, None: the manifest's


def terraces(count: int, seed: int = 0) -> Iterator[dict[str, object]]:
    """``count`` GeoJSON features of a generated town of terraces, for benchmarks at any
    size: blocks of two rows of TERRACE houses back to back (party walls along both
    sides and the back), on a square grid of streets. Widths, depths, levels, heights,
    roof shapes and building tags are drawn from ``seed``; coordinates are metres in the
    demo's CRS, so the town needs no projection."""
    rng = random.Random(seed)
    side = max(1, math.ceil(math.sqrt(count / (2 * TERRACE))))  # blocks along a street
    block, street = TERRACE * 9.0, 12.0
    for index in range(count):
        house, row = index % TERRACE, (index // TERRACE) % 2
        number = index // (2 * TERRACE)
        x0 = (number % side) * (block + street)
        y0 = (number // side) * (2 * 12.0 + street)
        width = block / TERRACE
        depth = rng.choice((10.0, 11.0, 12.0))
        ox = x0 + house * width
        oy = y0 + (12.0 - depth if row == 0 else 12.0)
        ring = [(ox, oy), (ox + width, oy), (ox + width, oy + depth), (ox, oy + depth)]
        properties: dict[str, object] = {
            "building": rng.choice(("house", "house", "apartments", "retail")),
            "building:levels": str(rng.choice((2, 3, 3, 4))),
        }
        if rng.random() < 0.3:
            properties["height"] = rng.choice((8.5, 10.0, 13.0))
        shape = rng.choice(ROOFS)
        if shape is not None:
            properties["roof:shape"] = shape
        yield {
            "type": "Feature",
            "id": f"t{index}",
            "properties": properties,
            "geometry": {
                "type": "Polygon",
                "coordinates": [[[x + 100000.0, y + 400000.0] for x, y in [*ring, ring[0]]]],
            },
        }


def write_terraces(folder: Path, specs: Path, count: int, seed: int = 0) -> Path:
    """Write :func:`terraces` and the demo's manifest into ``folder``; returns the manifest."""
    folder.mkdir(parents=True, exist_ok=True)
    crs = '{"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}'
    features = ",\n".join(json.dumps(feature) for feature in terraces(count, seed))
    text = f'{{"type": "FeatureCollection", "crs": {crs}, "features": [\n{features}\n]}}\n'
    write_atomic(folder / "footprints.geojson", text)
    relative = Path(os.path.relpath(specs.resolve(), folder.resolve())).as_posix()
    manifest = folder / "district.yaml"
    text = MANIFEST.format(name=f"terraces-{count}", specs=relative, fallback="")
    write_atomic(manifest, text)
    return manifest
