"""The city of a footprints file given without a manifest (``facade city IN.osm -o OUT``):
the manifest a user would write first, built in code.

Every building gets the façade spec given (``--spec``); without one, the shipped examples
dress it by its OSM ``building`` tag: apartments get the terraced house, shops and offices
the shop front, churches, chapels and towers the church, every other building the
townhouse; a building with a ``shop`` tag keeps its own and gets the shop front on its
front walls. A wall its façade does not fit (a shed's, a garage's, a bungalow's walls
are too low for a townhouse; a short wall is too narrow for it) gets the cottage: one
storey of windows over a plinth under an eaves band, more where the wall is taller, in
the building's wall material; it fits walls from 1.2 m long and 1.2 m high, and
shorter (or lower) walls are plain. Each building's walls take one of four tones of its
spec's wall colour (:func:`tones`), picked by the seed and its id. Roofs are hipped
(30°) unless the data tags a shape, a guess that leaves the walls a storey (flat under
4 m: :func:`.s3db.volume`); a building without a height or levels is 9 m tall, 3 m a
level.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from facadecli.city.manifest import ANY, City, Defaults, Manifest, Roof, Rule, WallRule
from facadecli.errors import SpecError
from facadecli.examples import example_spec
from facadecli.spec import Spec, load_spec

SUFFIXES: tuple[str, ...] = (".osm.pbf", ".osm.bz2", ".osm.gz", ".pbf", ".osm", ".geojson")
SUFFIXES += (".json", ".gpkg", ".shp", ".fgb")  # stripped from the file's name
CHURCHES = (  # walls with tall windows, not storeys of flats
    *("church", "cathedral", "chapel", "temple", "mosque", "synagogue", "shrine"),
    *("bell_tower", "tower"),
)
RULES = (  # building tag -> the example that dresses it, when no --spec is given
    (("apartments", "residential", "dormitory"), "terraced-house"),
    (("retail", "commercial", "office", "supermarket", "kiosk"), "shop-front"),
    (CHURCHES, "church"),
)
FALLBACK = "cottage"  # the example for walls the building's own façade does not fit
MIN_FACADE_WIDTH = 1.2  # metres: the cottage has a layout from here (one window, two piers)
TONES = (1.0, 0.86, 1.12, 0.94)  # the lightness of a wall colour's four tones, as factors


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
    plan: list[tuple[dict[str, Any], str, list[WallRule] | None]] = []  # when, façade, walls
    if spec is None:
        default = str(example_spec("townhouse"))
        front = [WallRule(side="front", facade=str(example_spec("shop-front")))]
        dressed = [(kind, str(example_spec(e))) for kinds, e in RULES for kind in kinds]
        for kind, facade in [*dressed, (None, default)]:  # a shop tag: a shop front too
            when = {"shop": ANY} if kind is None else {"building": kind, "shop": ANY}
            plan.append((when, facade, front))
        plan += [({"building": kind}, facade, None) for kind, facade in dressed]
        plan.append(({"man_made": "tower"}, str(example_spec("church")), None))
    else:
        default = str(spec)
    fallback = str(example_spec(FALLBACK)) if spec is None else None
    specs: dict[str, Spec] = {}
    walls = [wall.facade for _, _, chosen in plan for wall in chosen or []]
    walls += [fallback] if fallback is not None else []
    for facade in [default, *(facade for _, facade, _ in plan), *walls]:
        if facade not in specs:  # a spec's own errors name its file, line and column
            specs[facade] = load_spec(facade)
    manifest = Manifest(
        version=1,
        name=city_name(footprints),
        footprints=footprints.name,
        defaults=Defaults(
            facade=default,
            height=9.0,
            floor_height=3.0,
            roof=Roof(type="hip", pitch=30.0),
            min_facade_width=MIN_FACADE_WIDTH if fallback is not None else 3.0,
            fallback_facade=fallback,
            palette=tones(wall_colour(specs[default])),
        ),
        rules=[
            Rule(when=when, facade=facade, walls=chosen, palette=tones(wall_colour(specs[facade])))
            for when, facade, chosen in plan
        ],
    )
    return City(manifest, footprints.parent, footprints, specs)


def wall_colour(spec: Spec) -> str:
    """The colour of a spec's wall material (its ``defaults.material``)."""
    from facadecli.geometry.facade import look

    return look(spec, spec.defaults.material or "").color


def tones(colour: str) -> list[str]:
    """Four tones of a ``#rrggbb`` colour, lighter and darker by the :data:`TONES` factors
    (its hue kept): the walls of one style that still differ from house to house."""
    digits = colour.lstrip("#")
    digits = "".join(c * 2 for c in digits) if len(digits) == 3 else digits
    rgb = [int(digits[i : i + 2], 16) for i in (0, 2, 4)]
    brightest = 255 / max(*rgb, 1)  # no lighter than white allows: the hue stays
    return ["#" + "".join(f"{round(c * min(f, brightest)):02x}" for c in rgb) for f in TONES]
