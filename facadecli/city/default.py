"""The city of a footprints file given without a manifest (``facade city IN.osm -o OUT``):
the manifest a user would write first, built in code.

Every building gets the façade spec given (``--spec``); without one, the shipped examples
dress it by its OSM ``building`` tag: apartments get the terraced house, shops and offices
the shop front, every other building the townhouse. Roofs are hipped (30°) unless the
data tags a shape; a building without a height or levels is 9 m tall, 3 m a level; walls
shorter than 3 m are plain.
"""

from __future__ import annotations

import re
from pathlib import Path

from facadecli.city.manifest import City, Defaults, Manifest, Roof, Rule
from facadecli.errors import SpecError
from facadecli.examples import example_spec
from facadecli.spec import Spec, load_spec

SUFFIXES: tuple[str, ...] = (".osm.pbf", ".osm.bz2", ".osm.gz", ".pbf", ".osm", ".geojson")
SUFFIXES += (".json", ".gpkg", ".shp", ".fgb")  # stripped from the file's name
RULES = (  # building tag -> the example that dresses it, when no --spec is given
    (("apartments", "residential", "dormitory"), "terraced-house"),
    (("retail", "commercial", "office", "supermarket", "kiosk"), "shop-front"),
)


def city_name(footprints: Path) -> str:
    """The city's name (its output files' stem): the file's, without its suffixes."""
    name = footprints.name
    for suffix in SUFFIXES:
        if name.lower().endswith(suffix):
            name = name[: -len(suffix)]
            break
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "city"


def default_city(footprints: Path, spec: Path | None = None) -> City:
    """The city of ``footprints`` with ``spec`` on every wall, or the examples by tag (see
    the module); raises SpecError (exit 2) for a missing file or an unusable spec."""
    if not footprints.is_file():
        what = "is a folder" if footprints.is_dir() else "no such file"
        raise SpecError.at(str(footprints), None, None, what, "give a footprints file")
    rules: list[Rule] = []
    if spec is None:
        default = str(example_spec("townhouse"))
        for kinds, example in RULES:
            for kind in kinds:
                rules.append(Rule(when={"building": kind}, facade=str(example_spec(example))))
    else:
        default = str(spec)
    manifest = Manifest(
        version=1,
        name=city_name(footprints),
        footprints=footprints.name,
        defaults=Defaults(
            facade=default,
            height=9.0,
            floor_height=3.0,
            roof=Roof(type="hip", pitch=30.0),
            min_facade_width=3.0,
        ),
        rules=rules,
    )
    specs: dict[str, Spec] = {}
    for facade in [default, *(rule.facade for rule in rules if rule.facade is not None)]:
        if facade not in specs:  # a spec's own errors name its file, line and column
            specs[facade] = load_spec(facade)
    return City(manifest, footprints.parent, footprints, specs)
