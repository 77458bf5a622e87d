"""OpenStreetMap's Simple 3D Buildings (S3DB) scheme: what a feature's tags say about its
volume, roof and colours, read into numbers the builder uses.

- ``height`` is the top of the roof; the walls stop ``roof:height`` (or ``roof:levels`` x
  the floor height, else the roof's own height from its pitch) below it.
- ``building:levels`` counts the levels below the roof: with no ``height`` the walls are
  levels x floor height and the roof sits on top.
- ``min_height`` (or ``building:min_level`` x floor height) lifts the bottom of the walls.
- Features tagged ``building:part`` replace the volume of the outline they lie in; what
  of the outline no part stands in (a wing left undrawn, a podium under upper storeys
  drawn as parts) is still built.
- ``building:colour`` / ``building:material`` colour the walls, ``roof:colour`` /
  ``roof:material`` the roof.

Pure functions of the tags and the footprint; no mesh library.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import shapely
from shapely import STRtree
from shapely.geometry import LineString, Polygon
from shapely.geometry.polygon import orient

from facadecli.city.footprints import MAX_HEIGHT, MIN_AREA, Footprint, length, number
from facadecli.city.manifest import Roof
from facadecli.city.roofs import roof_height

MIN_WALL = 0.5  # metres: a roof taller than its building leaves at least this much wall
SLIVER = 1.0  # metres: what parts leave of an outline narrower than this is a gap in the drawing
ROOF_SHARE = 0.5  # of a building's height, at most, for a roof no tag gives a height


@dataclass(frozen=True)
class Heights:
    """What the tags (and the manifest) say of a building's heights, before its geometry."""

    top: float | None  # the top of the roof (OSM ``height``), if known
    eaves: float | None  # the top of the walls, if known (levels x floor height)
    base: float  # the bottom of the walls (``min_height``)
    roof: float | None  # the roof's own height (``roof:height``, ``roof:levels``), if tagged
    default: float  # the top when nothing else says


@dataclass(frozen=True)
class Volume:
    """One part of a building: walls from ``base`` to ``eaves`` around ``part``, and the
    roof on them (its ``height`` set: the roof's top is ``eaves + roof.height``)."""

    part: Polygon
    base: float
    eaves: float
    roof: Roof

    @property
    def top(self) -> float:
        return self.eaves + (self.roof.height or 0.0)


def volume(part: Polygon, heights: Heights, roof: Roof) -> Volume:
    """The part's walls and roof as the heights say. A roof whose height comes from its
    pitch alone (no ``roof:height``, ``roof:levels`` or roof ``height``) takes at most
    ROOF_SHARE of the building's height (a wide footprint gets a flatter roof, not walls
    half a metre high; under levels, the walls keep the levels' height and the roof is
    lowered); a roof too tall for the building is lowered to leave MIN_WALL of
    wall; a roof of no height is flat. With no height and no levels the top is the
    default, or, higher, a tagged roof on MIN_WALL of wall above the base (a dome drawn
    as a part of its own, lifted above the default: the tag wins over the guess)."""
    own = 0.0 if roof.type == "flat" else roof_height(part, roof)
    rise = heights.roof if heights.roof is not None else own
    if roof.type == "flat":
        rise = 0.0
    pitched = heights.roof is None and roof.height is None  # a roof from its pitch alone
    if heights.top is not None:
        top = heights.top
    elif heights.eaves is not None:
        if pitched:  # ROOF_SHARE of the walls and the roof together, at most
            walls = max(0.0, heights.eaves - heights.base)
            rise = min(rise, ROOF_SHARE / (1 - ROOF_SHARE) * walls)
        top = heights.eaves + rise
    else:
        top = max(heights.default, heights.base + MIN_WALL + (heights.roof or 0.0))
    top = max(top, heights.base + MIN_WALL)
    if pitched:  # at most a share of the building
        rise = min(rise, ROOF_SHARE * (top - heights.base))
    eaves = max(top - rise, min(heights.base + MIN_WALL, top))
    rise = top - eaves
    if rise <= 1e-6:
        return Volume(part, heights.base, top, Roof(type="flat", parapet=roof.parapet))
    return Volume(part, heights.base, eaves, roof.model_copy(update={"height": rise}))


def tagged_heights(
    properties: dict[str, Any],
    floor_height: float,
    default: float,
    names: dict[str, tuple[str, float]] | None = None,
) -> Heights:
    """The heights a feature's tags give. ``names`` maps ``height``, ``eaves``, ``levels``
    and ``min_height`` to (property name, scale) for datasets that are not OSM's; a
    feature without that property falls back to the OSM tags."""
    names = names or {}

    def read(key: str, *osm: str) -> float | None:
        """The named property (scaled) if the feature has it, else the OSM tags."""
        parse = number if key == "levels" else length
        if key in names:
            name, scale = names[key]
            value = parse(properties.get(name))
            if value is not None and value > 0:
                return value * scale
        for tag in osm:
            value = parse(properties.get(tag))
            if value is not None and value > 0:
                return value
        return None

    def storeys(levels: float | None) -> float | None:
        """Levels as metres, at most MAX_HEIGHT (300 levels of 20 m would pass it)."""
        return None if levels is None or levels <= 0 else min(levels * floor_height, MAX_HEIGHT)

    top = read("height", "height", "measuredHeight")
    eaves = read("eaves")
    if eaves is None:
        eaves = storeys(read("levels", "building:levels", "levels"))
    base = read("min_height", "min_height")
    if base is None:
        base = storeys(number(properties.get("building:min_level"))) or 0.0
    roof = length(properties.get("roof:height"))
    if roof is None or roof <= 0:
        roof = storeys(number(properties.get("roof:levels")))
    if top is not None and eaves is not None and roof is None:
        roof = max(0.0, top - eaves)  # both known: the roof is what lies between
    return Heights(top, eaves, base, roof, default)


def tagged_roof(properties: dict[str, Any], roof: Roof) -> Roof:
    """The roof with what the tags add: ``roof:direction`` (degrees or N, NNE, ...) and
    ``roof:orientation`` (along, across)."""
    update: dict[str, Any] = {}
    direction = compass(properties.get("roof:direction"))
    if direction is not None:
        update["direction"] = direction
    orientation = str(properties.get("roof:orientation", "")).strip().lower()
    if orientation in ("along", "across"):
        update["orientation"] = orientation
    return roof.model_copy(update=update) if update else roof


POINTS = ["N", "NNE", "NE", "ENE", "E", "ESE", "SE", "SSE"]
POINTS += ["S", "SSW", "SW", "WSW", "W", "WNW", "NW", "NNW"]


def compass(value: Any) -> float | None:
    """Degrees from a ``roof:direction``: a number, or a compass point (N, NNE, ... NNW)."""
    if value is None or isinstance(value, bool):
        return None
    text = str(value).strip().upper()
    if text in POINTS:
        return POINTS.index(text) * 22.5
    found = number(value)
    return None if found is None else found % 360.0


# CSS colour names OSM mappers use most (osm wiki: Key:colour), and the colours of the
# materials S3DB lists, as a renderer would show them
COLOURS = {
    "white": "#ffffff",
    "black": "#000000",
    "grey": "#808080",
    "gray": "#808080",
    "lightgrey": "#d3d3d3",
    "lightgray": "#d3d3d3",
    "darkgrey": "#a9a9a9",
    "darkgray": "#a9a9a9",
    "silver": "#c0c0c0",
    "red": "#ff0000",
    "darkred": "#8b0000",
    "maroon": "#800000",
    "brown": "#a52a2a",
    "sienna": "#a0522d",
    "tan": "#d2b48c",
    "beige": "#f5f5dc",
    "ivory": "#fffff0",
    "cream": "#fffdd0",
    "wheat": "#f5deb3",
    "orange": "#ffa500",
    "yellow": "#ffff00",
    "gold": "#ffd700",
    "khaki": "#f0e68c",
    "olive": "#808000",
    "green": "#008000",
    "darkgreen": "#006400",
    "lightgreen": "#90ee90",
    "teal": "#008080",
    "blue": "#0000ff",
    "navy": "#000080",
    "lightblue": "#add8e6",
    "skyblue": "#87ceeb",
    "purple": "#800080",
    "pink": "#ffc0cb",
    "salmon": "#fa8072",
    "coral": "#ff7f50",
    "terracotta": "#e2725b",
}
BUILDING_MATERIALS = {
    "brick": "#9c4a32",
    "plaster": "#e8e0d0",
    "concrete": "#b8b5ae",
    "stone": "#c8bca4",
    "sandstone": "#d6c7a1",
    "limestone": "#e3dccb",
    "wood": "#8b6b4a",
    "timber_framing": "#d9cdb4",
    "metal": "#9aa0a6",
    "steel": "#9aa0a6",
    "glass": "#8fb3d9",
    "mirror": "#a9c8e4",
    "cement_block": "#a9a59c",
    "masonry": "#b39b83",
}
ROOF_MATERIALS = {
    "roof_tiles": "#a0522d",
    "tile": "#a0522d",
    "tiles": "#a0522d",
    "slate": "#4a4e54",
    "metal": "#7d8489",
    "tin": "#8c9197",
    "copper": "#6e9e8a",
    "zinc": "#9aa3a8",
    "concrete": "#9e9e9e",
    "asphalt": "#3c3c3c",
    "tar_paper": "#3c3c3c",
    "bitumen": "#3c3c3c",
    "eternit": "#8e8e8e",
    "gravel": "#a8a39a",
    "glass": "#8fb3d9",
    "grass": "#5f8f3a",
    "plants": "#5f8f3a",
    "thatch": "#b59a5b",
    "wood": "#7a5a3a",
    "stone": "#8a8580",
}
_HEX = re.compile(r"#?([0-9a-fA-F]{6}|[0-9a-fA-F]{3})")


def colour(value: Any) -> str | None:
    """``#rrggbb`` from a colour tag: #rgb, #rrggbb (with or without #), or a CSS name."""
    if not isinstance(value, str):
        return None
    text = value.strip().lower().replace(" ", "").replace("_", "")
    if text in COLOURS:
        return COLOURS[text]
    match = _HEX.fullmatch(text)
    if match is None:
        return None
    digits = match.group(1)
    if len(digits) == 3:
        digits = "".join(d * 2 for d in digits)
    return f"#{digits}"


def wall_colour(properties: dict[str, Any]) -> str | None:
    """The walls' colour the tags give: ``building:colour``, else ``building:material``."""
    found = colour(properties.get("building:colour"))
    material = str(properties.get("building:material", "")).strip().lower()
    return found or BUILDING_MATERIALS.get(material)


def roof_colour(properties: dict[str, Any]) -> str | None:
    """The roof's colour the tags give: ``roof:colour``, else ``roof:material``."""
    found = colour(properties.get("roof:colour"))
    material = str(properties.get("roof:material", "")).strip().lower()
    return found or ROOF_MATERIALS.get(material)


def is_part(properties: dict[str, Any]) -> bool:
    """A ``building:part`` feature (a volume of a building, not its outline)."""
    value = properties.get("building:part")
    return value is not None and str(value).strip().lower() not in ("", "no")


def replaced_outlines(footprints: Iterable[Footprint]) -> dict[str, list[str]]:
    """Outlines with ``building:part`` features inside, which replace their volume (see
    :func:`outline_rest`): outline id -> the ids of its parts (a part is inside when a
    point of it surely in it is)."""
    footprints = list(footprints)
    parts = [f for f in footprints if is_part(f.properties)]
    if not parts:
        return {}
    points = [p.parts[0].representative_point() for p in parts]
    tree = STRtree(points)
    replaced: dict[str, list[str]] = {}
    for outline in footprints:
        if is_part(outline.properties):
            continue
        for shape in outline.parts:
            for index in tree.query(shape, predicate="contains"):
                replaced.setdefault(outline.id, []).append(parts[int(index)].id)
    return {key: sorted(set(ids)) for key, ids in replaced.items()}


def outline_rest(
    outline: Polygon, eaves: float, parts: Iterable[tuple[Polygon, float]]
) -> list[Polygon]:
    """What of an outline its parts leave to build: the outline less every part standing
    in its volume (``parts`` gives each part's polygon and base: a base below the
    outline's ``eaves``, less MIN_WALL, is a part from the ground or an overhang), without
    strips narrower than SLIVER (gaps where parts were drawn a little apart) or pieces under
    MIN_AREA. S3DB builds the parts instead of the outline, as mappers draw parts over
    the whole outline; where they drew some (one wing of a station, the middle of a
    church) the rest of the outline still stands, and parts standing on the outline
    (their base at its eaves: upper storeys drawn over a podium the outline is) keep it
    whole under them. Outer rings counter-clockwise, as footprints' are."""
    inside = [part for part, base in parts if base < eaves - MIN_WALL]
    if not inside:
        return [outline]
    rest = outline.difference(shapely.union_all(inside))
    opened = rest.buffer(-SLIVER / 2, join_style="mitre").buffer(SLIVER / 2, join_style="mitre")
    kept = opened.intersection(rest)
    found = [kept] if isinstance(kept, Polygon) else list(getattr(kept, "geoms", []))
    return [
        orient(piece, sign=1.0)
        for piece in found
        if isinstance(piece, Polygon) and piece.area >= MIN_AREA
    ]


def shared_edges(
    footprints: list[Footprint],
    tolerance: float,
    beside: Callable[[str, str], bool] | None = None,
) -> dict[str, Any]:
    """For each footprint, the lines of its outline that lie along another footprint's
    (within ``tolerance`` metres): party walls of terraces and city blocks, and the walls
    between the parts of one building. ``beside(id, other)`` says whether two footprints'
    walls stand side by side at all (see :func:`side_by_side`; None: all do): upper
    storeys drawn as a part over a podium have walls of their own, not party walls.
    Footprint id -> a shapely geometry (absent: none)."""
    shapes = [shape for f in footprints for shape in f.parts]
    owner = [f.id for f in footprints for _ in f.parts]
    tree = STRtree(shapes)
    shared: dict[str, Any] = {}
    for index, shape in enumerate(shapes):
        near = [int(i) for i in tree.query(shape.buffer(tolerance))]
        others = [
            shapes[i]
            for i in near
            if owner[i] != owner[index] and (beside is None or beside(owner[index], owner[i]))
        ]
        if not others:
            continue
        for other in others:
            touching = shape.boundary.intersection(other.buffer(tolerance))
            if touching.is_empty or touching.length < tolerance:
                continue
            before = shared.get(owner[index])
            shared[owner[index]] = touching if before is None else before.union(touching)
    return shared


def side_by_side(one: tuple[float, float], other: tuple[float, float]) -> bool:
    """Do walls from ``one``'s base to its eaves and from ``other``'s stand side by side,
    for MIN_WALL at least (not one volume on top of the other)?"""
    return min(one[1], other[1]) - max(one[0], other[0]) >= MIN_WALL


def party_zone(shared: Any, tolerance: float) -> Any:
    """The area along a footprint's neighbours (``shared``, from :func:`shared_edges`,
    widened by ``tolerance``): a wall mostly inside it is a party wall. None: none."""
    return None if shared is None else shared.buffer(tolerance)


def along(a: tuple[float, float], b: tuple[float, float], zone: Any) -> bool:
    """Is most of the wall from a to b inside the party zone (a party wall)?"""
    length = math.dist(a, b)
    if zone is None or length <= 0:
        return False
    return bool(LineString([a, b]).intersection(zone).length >= 0.5 * length)


def blind(a: tuple[float, float], b: tuple[float, float], shared: Any, tolerance: float) -> bool:
    """Is most of the wall from a to b along a neighbour (a party wall)?"""
    return along(a, b, party_zone(shared, tolerance))
