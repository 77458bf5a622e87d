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

import itertools
import math
import re
from collections.abc import Callable, Container, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import shapely
from shapely import STRtree
from shapely.geometry import LineString, Point, Polygon
from shapely.geometry.polygon import orient

from facadecli.city.footprints import MAX_HEIGHT, MIN_AREA, Footprint, length, number
from facadecli.city.manifest import OSM_ROOFS, Roof
from facadecli.city.roofs import Segment, roof_height

MIN_WALL = 0.5  # metres: a roof taller than its building leaves at least this much wall
SLIVER = 1.0  # metres: what parts leave of an outline narrower than this is a gap in the drawing
ROOF_SHARE = 0.5  # of a building's height, at most, for a roof no tag gives a height
MIN_ROOF = 1.0  # metres: a guessed roof lower than this is flat (OSM2World's one-level roof)


@dataclass(frozen=True)
class Heights:
    """What the tags (and the manifest) say of a building's heights, before its geometry."""

    top: float | None  # the top of the roof (OSM ``height``), if known
    eaves: float | None  # the top of the walls, if known (levels x floor height)
    base: float  # the bottom of the walls (``min_height``)
    roof: float | None  # the roof's own height (``roof:height``, ``roof:levels``), if tagged
    default: float  # the top when nothing else says
    # metres of wall a roof the manifest guesses (no roof:shape, no roof height) leaves:
    # a storey; 0 where the tags or a rule give the roof
    storey: float = 0.0


POST = 0.25  # metres: the side of a square post under a roof on posts
Post = tuple[float, float, float, float]  # a square post: its middle (x, y), base and top


@dataclass(frozen=True)
class Volume:
    """One part of a building: walls from ``base`` to ``eaves`` around ``part``, and the
    roof on them (its ``height`` set: the roof's top is ``eaves + roof.height``).
    ``still``: its party walls, as segments, where the roof does not slope down but
    runs on to the wall (roofs.py's fixed walls; :func:`.building.party_volumes` finds
    them, for the glb's roofs and the CityJSON's alike); ``above``: the taller parts
    standing on it, which its roof leaves out (:func:`roof_outlines`)."""

    part: Polygon
    base: float
    eaves: float
    roof: Roof
    still: tuple[Segment, ...] = ()
    posts: tuple[Post, ...] = ()  # a roof on posts: its posts (:func:`roof_solid`)
    above: Any = None  # the taller parts standing on it (a tower on a podium), shapely

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
    as a part of its own, lifted above the default: the tag wins over the guess). A
    guessed roof (``heights.storey`` set) on walls no levels give leaves them a storey,
    and is flat where that leaves it less than MIN_ROOF: a one-storey shed is not half
    roof."""
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
        if heights.storey > 0 and heights.eaves is None:  # a guess on walls no levels set
            # the walls keep a storey, else no roof
            rise = min(rise, top - heights.base - heights.storey)
            rise = rise if rise >= MIN_ROOF else 0.0
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
    if top is None and eaves is None and roof_only(properties):
        eaves = floor_height  # a roof on posts one storey high, not the default building
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


# the 148 colour names of CSS (CSS Color Module Level 4, as OSM's Key:colour takes them)
COLOURS = {
    "aliceblue": "#f0f8ff",
    "antiquewhite": "#faebd7",
    "aqua": "#00ffff",
    "aquamarine": "#7fffd4",
    "azure": "#f0ffff",
    "beige": "#f5f5dc",
    "bisque": "#ffe4c4",
    "black": "#000000",
    "blanchedalmond": "#ffebcd",
    "blue": "#0000ff",
    "blueviolet": "#8a2be2",
    "brown": "#a52a2a",
    "burlywood": "#deb887",
    "cadetblue": "#5f9ea0",
    "chartreuse": "#7fff00",
    "chocolate": "#d2691e",
    "coral": "#ff7f50",
    "cornflowerblue": "#6495ed",
    "cornsilk": "#fff8dc",
    "crimson": "#dc143c",
    "cyan": "#00ffff",
    "darkblue": "#00008b",
    "darkcyan": "#008b8b",
    "darkgoldenrod": "#b8860b",
    "darkgray": "#a9a9a9",
    "darkgreen": "#006400",
    "darkgrey": "#a9a9a9",
    "darkkhaki": "#bdb76b",
    "darkmagenta": "#8b008b",
    "darkolivegreen": "#556b2f",
    "darkorange": "#ff8c00",
    "darkorchid": "#9932cc",
    "darkred": "#8b0000",
    "darksalmon": "#e9967a",
    "darkseagreen": "#8fbc8f",
    "darkslateblue": "#483d8b",
    "darkslategray": "#2f4f4f",
    "darkslategrey": "#2f4f4f",
    "darkturquoise": "#00ced1",
    "darkviolet": "#9400d3",
    "deeppink": "#ff1493",
    "deepskyblue": "#00bfff",
    "dimgray": "#696969",
    "dimgrey": "#696969",
    "dodgerblue": "#1e90ff",
    "firebrick": "#b22222",
    "floralwhite": "#fffaf0",
    "forestgreen": "#228b22",
    "fuchsia": "#ff00ff",
    "gainsboro": "#dcdcdc",
    "ghostwhite": "#f8f8ff",
    "gold": "#ffd700",
    "goldenrod": "#daa520",
    "gray": "#808080",
    "green": "#008000",
    "greenyellow": "#adff2f",
    "grey": "#808080",
    "honeydew": "#f0fff0",
    "hotpink": "#ff69b4",
    "indianred": "#cd5c5c",
    "indigo": "#4b0082",
    "ivory": "#fffff0",
    "khaki": "#f0e68c",
    "lavender": "#e6e6fa",
    "lavenderblush": "#fff0f5",
    "lawngreen": "#7cfc00",
    "lemonchiffon": "#fffacd",
    "lightblue": "#add8e6",
    "lightcoral": "#f08080",
    "lightcyan": "#e0ffff",
    "lightgoldenrodyellow": "#fafad2",
    "lightgray": "#d3d3d3",
    "lightgreen": "#90ee90",
    "lightgrey": "#d3d3d3",
    "lightpink": "#ffb6c1",
    "lightsalmon": "#ffa07a",
    "lightseagreen": "#20b2aa",
    "lightskyblue": "#87cefa",
    "lightslategray": "#778899",
    "lightslategrey": "#778899",
    "lightsteelblue": "#b0c4de",
    "lightyellow": "#ffffe0",
    "lime": "#00ff00",
    "limegreen": "#32cd32",
    "linen": "#faf0e6",
    "magenta": "#ff00ff",
    "maroon": "#800000",
    "mediumaquamarine": "#66cdaa",
    "mediumblue": "#0000cd",
    "mediumorchid": "#ba55d3",
    "mediumpurple": "#9370db",
    "mediumseagreen": "#3cb371",
    "mediumslateblue": "#7b68ee",
    "mediumspringgreen": "#00fa9a",
    "mediumturquoise": "#48d1cc",
    "mediumvioletred": "#c71585",
    "midnightblue": "#191970",
    "mintcream": "#f5fffa",
    "mistyrose": "#ffe4e1",
    "moccasin": "#ffe4b5",
    "navajowhite": "#ffdead",
    "navy": "#000080",
    "oldlace": "#fdf5e6",
    "olive": "#808000",
    "olivedrab": "#6b8e23",
    "orange": "#ffa500",
    "orangered": "#ff4500",
    "orchid": "#da70d6",
    "palegoldenrod": "#eee8aa",
    "palegreen": "#98fb98",
    "paleturquoise": "#afeeee",
    "palevioletred": "#db7093",
    "papayawhip": "#ffefd5",
    "peachpuff": "#ffdab9",
    "peru": "#cd853f",
    "pink": "#ffc0cb",
    "plum": "#dda0dd",
    "powderblue": "#b0e0e6",
    "purple": "#800080",
    "rebeccapurple": "#663399",
    "red": "#ff0000",
    "rosybrown": "#bc8f8f",
    "royalblue": "#4169e1",
    "saddlebrown": "#8b4513",
    "salmon": "#fa8072",
    "sandybrown": "#f4a460",
    "seagreen": "#2e8b57",
    "seashell": "#fff5ee",
    "sienna": "#a0522d",
    "silver": "#c0c0c0",
    "skyblue": "#87ceeb",
    "slateblue": "#6a5acd",
    "slategray": "#708090",
    "slategrey": "#708090",
    "snow": "#fffafa",
    "springgreen": "#00ff7f",
    "steelblue": "#4682b4",
    "tan": "#d2b48c",
    "teal": "#008080",
    "thistle": "#d8bfd8",
    "tomato": "#ff6347",
    "turquoise": "#40e0d0",
    "violet": "#ee82ee",
    "wheat": "#f5deb3",
    "white": "#ffffff",
    "whitesmoke": "#f5f5f5",
    "yellow": "#ffff00",
    "yellowgreen": "#9acd32",
}
COLOURS |= {"cream": "#fffdd0", "terracotta": "#e2725b"}  # names mappers use beside them
# the colours of the materials S3DB lists, as a renderer would show them
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


ON_POSTS = ("roof", "carport")  # building values for a roof on posts


def roof_only(properties: dict[str, Any]) -> bool:
    """``building=roof`` or ``building=carport`` (or such a ``building:part``): a roof on
    posts, no walls (a carport, a petrol station's canopy, a platform roof)."""
    return any(
        str(properties.get(key, "")).strip().lower() in ON_POSTS
        for key in ("building", "building:part")
    )


MIN_EDGE = 0.05  # metres: shorter edges are slivers, merged into the next wall


def roof_outlines(block: Volume) -> list[tuple[Polygon, tuple[Segment, ...]]]:
    """Where a volume's roof goes, and the walls it stands still at: the part less the
    taller parts standing on it (``above``: a tower on a podium), whose walls join the
    party walls; the part whole when that leaves too little. The one rule for the glb's
    roofs and the CityJSON's solids (which close the rest at the eaves)."""
    part, party, above = block.part, block.still, block.above
    if above is None or above.is_empty:
        return [(part, tuple(party))]
    rest = part.difference(above)
    pieces = [rest] if isinstance(rest, Polygon) else list(getattr(rest, "geoms", []))
    pieces = [orient(p, sign=1.0) for p in pieces if isinstance(p, Polygon) and p.area >= 1.0]
    if not pieces:
        return [(part, tuple(party))]
    edge = part.boundary
    found = []
    for piece in pieces:
        cut = [
            (a, b)
            for ring in (piece.exterior, *piece.interiors)
            for a, b in itertools.pairwise((p[0], p[1]) for p in ring.coords)
            if edge.distance(Point((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)) > MIN_EDGE
        ]
        found.append((piece, (*party, *cut)))
    return found


def roof_solid(block: Volume, thickness: float, posts: tuple[Post, ...] = ()) -> Volume:
    """The solid of a roof on posts: the roof on a slab ``thickness`` thick under its
    eaves (its underside a ceiling open to the air), not walls down to the ground; the
    ``posts`` it stands on."""
    return replace(block, base=max(block.base, block.eaves - thickness), posts=posts)


def tag_problems(properties: dict[str, Any]) -> list[str]:
    """What of a feature's S3DB tags is not understood, a sentence each (the building is
    built without it): roof shapes S3DB does not list,
    colours that are neither #rgb, #rrggbb nor a CSS name, unknown materials, roof
    directions, orientations and angles that are not one."""
    problems = []

    def shown(key: str) -> str:
        text = str(properties[key])
        return f"{key} '{text if len(text) <= 40 else text[:37] + '...'}'"

    shape = properties.get("roof:shape")
    if shape is not None and str(shape).strip():
        name = str(shape).strip().lower()
        if name not in OSM_ROOFS:
            problems.append(
                f"{shown('roof:shape')} is not a roof shape of Simple 3D Buildings: "
                "the manifest's roof instead"
            )
    for key in ("building:colour", "roof:colour"):
        if properties.get(key) is not None and colour(properties[key]) is None:
            problems.append(
                f"{shown(key)} is not a colour (#rrggbb, #rgb or one of the 148 CSS names): ignored"
            )
    for key, known in (
        ("building:material", BUILDING_MATERIALS),
        ("roof:material", ROOF_MATERIALS),
    ):
        value = properties.get(key)
        if value is not None and str(value).strip().lower() not in known:
            problems.append(f"{shown(key)} is not a material known here: ignored")
    if (
        properties.get("roof:direction") is not None
        and compass(properties["roof:direction"]) is None
    ):
        problems.append(f"{shown('roof:direction')} is not degrees or a compass point: ignored")
    orientation = properties.get("roof:orientation")
    if orientation is not None and str(orientation).strip().lower() not in ("along", "across"):
        problems.append(f"{shown('roof:orientation')} is not 'along' or 'across': ignored")
    angle = properties.get("roof:angle")
    if angle is not None and not (0 < (number(angle) or 0) < 90):
        problems.append(f"{shown('roof:angle')} is not an angle between 0 and 90°: 30° instead")
    return problems


# tags a part without them takes from its outline, as OSM2World does: each on its own,
# but the heights only together (a part with levels of its own keeps them, and does not
# take the outline's height)
INHERITED = (
    "building:colour",
    "building:material",
    "roof:colour",
    "roof:material",
    "roof:shape",
    "roof:height",
    "roof:angle",
    "roof:levels",
    "roof:direction",
    "roof:orientation",
)
INHERITED_HEIGHTS = ("height", "building:levels", "levels")


def outline_of(replaced: dict[str, list[str]]) -> dict[str, str]:
    """Part id -> the id of its outline (``replaced``: outline id -> its parts' ids, from
    :func:`replaced_outlines`); a part in several outlines is the first's by id."""
    parent: dict[str, str] = {}
    for key in sorted(replaced):
        for part in replaced[key]:
            parent.setdefault(part, key)
    return parent


def inherited(footprints: Iterable[Footprint], replaced: dict[str, list[str]]) -> list[Footprint]:
    """The footprints with every part given the tags of its outline (``replaced``:
    outline id -> its parts' ids, from :func:`replaced_outlines`) that it lacks; a part
    in several outlines takes from the first by id."""
    footprints = list(footprints)
    by_id = {footprint.id: footprint for footprint in footprints}
    parent = outline_of(replaced)
    found = []
    for footprint in footprints:
        outline = by_id.get(parent.get(footprint.id, ""))
        if outline is None:
            found.append(footprint)
            continue
        own, theirs = footprint.properties, outline.properties
        keys = [key for key in INHERITED if key not in own and key in theirs]
        if not any(key in own for key in INHERITED_HEIGHTS):
            keys += [key for key in INHERITED_HEIGHTS if key in theirs]
        if not keys:
            found.append(footprint)
            continue
        properties = {**own, **{key: theirs[key] for key in keys}}
        found.append(replace(footprint, properties=properties))
    return found


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
    (within ``tolerance`` metres) standing outside it: party walls of terraces and city
    blocks, and the walls between the parts of one building (a part inside another, or
    flush with its outline, has no neighbour outside those walls). ``beside(id, other)``
    says whether two footprints' walls stand side by side at all (see :func:`side_by_side`
    and :func:`screens`; None: all do): upper storeys drawn as a part over a podium have
    walls of their own, not party walls.
    Footprint id -> a shapely geometry (absent: none); :func:`party_lines` as they come."""
    return dict(party_lines(footprints, tolerance, beside))


def party_lines(
    footprints: list[Footprint],
    tolerance: float,
    beside: Callable[[str, str], bool] | None = None,
    only: Container[str] | None = None,
) -> Iterator[tuple[str, Any]]:
    """:func:`shared_edges` footprint by footprint, in their order: its id and its lines,
    for those that have any (a caller may take them as they come, not all at once);
    with ``only``, for the footprints of those ids alone (the others still neighbours)."""
    shapes = [shape for f in footprints for shape in f.parts]
    owner = [f.id for f in footprints for _ in f.parts]
    tree = STRtree(shapes)
    found: tuple[str, Any] | None = None  # the footprint's lines so far
    for index, shape in enumerate(shapes):
        if found is not None and found[0] != owner[index]:
            yield found
            found = None
        if only is not None and owner[index] not in only:
            continue
        # by their place in the input, not the tree's order (which depends on every
        # shape in it): the lines are united in the same order whatever else was read
        near = sorted(int(i) for i in tree.query(shape.buffer(tolerance)))
        others = [
            shapes[i]
            for i in near
            if owner[i] != owner[index] and (beside is None or beside(owner[index], owner[i]))
        ]
        for other in others:  # the neighbour outside the wall, not under or over it
            beyond = other.difference(shape.buffer(tolerance / 2, join_style="mitre"))
            if beyond.is_empty:
                continue
            touching = shape.boundary.intersection(beyond.buffer(tolerance, join_style="mitre"))
            if touching.is_empty or touching.length < tolerance:
                continue
            found = (owner[index], touching if found is None else found[1].union(touching))
    if found is not None:
        yield found


SCREEN = 0.5  # of a wall's height: a neighbour this high, at least, makes it a party wall


def reach(heights: Heights) -> float:
    """How high a building stands, from its tags alone (no roof geometry): its top, else
    its eaves and tagged roof, else the default."""
    if heights.top is not None:
        return heights.top
    if heights.eaves is not None:
        return heights.eaves + (heights.roof or 0.0)
    return max(heights.default, heights.base + MIN_WALL)


def screens(one: Heights, other: Heights) -> bool:
    """Does ``other``, standing along a wall of ``one``, make it a party wall? When it
    stands SCREEN of the wall's height at least: a podium only hides the foot of a
    tower's walls, which keep their façades; a neighbour one storey lower keeps the
    fire wall blind."""
    return reach(other) - one.base >= SCREEN * (reach(one) - one.base)


Podiums = tuple[list[tuple[int, int]], list[Polygon], list[str]]


def podiums(footprints: list[Footprint], heights: dict[str, Heights]) -> Podiums:
    """Which footprints stand on which: (pairs (lower, taller) of indices into the
    footprints' parts, the parts, their footprints' ids), the taller with most of its
    area in the lower's outline, its base below the lower's top and its top above it: a
    tower part on a podium part, whatever their tags call them."""
    shapes = [shape for f in footprints for shape in f.parts]
    owner = [f.id for f in footprints for _ in f.parts]
    tree = STRtree(shapes)
    pairs = []
    for index, shape in enumerate(shapes):
        me = heights[owner[index]]
        for i in sorted(int(i) for i in tree.query(shape)):
            other = heights[owner[i]]
            if owner[i] == owner[index] or reach(other) <= reach(me) + MIN_WALL:
                continue
            if other.base >= reach(me) or shapes[i].area >= shape.area:
                continue
            if shapes[i].intersection(shape).area >= 0.5 * shapes[i].area:
                pairs.append((index, i))
    return pairs, shapes, owner


def standing_on(footprints: list[Footprint], heights: dict[str, Heights]) -> dict[str, Any]:
    """For each footprint, the taller footprints standing on it (:func:`podiums`), whose
    walls its roof must leave out. Footprint id -> a shapely geometry (absent: none)."""
    found: dict[str, list[Polygon]] = {}
    pairs, shapes, owner = podiums(footprints, heights)
    for low, high in pairs:
        found.setdefault(owner[low], []).append(shapes[high])
    return {key: shapely.union_all(parts) for key, parts in found.items()}


def lifted(
    footprints: list[Footprint], heights: dict[str, Heights], roofs: dict[str, Roof]
) -> dict[str, Heights]:
    """The heights of the footprints standing on a lower one (:func:`podiums`), their
    base lifted to the lower one's eaves (its walls' top, the top of a flat roof): a
    tower part drawn from the ground inside a podium part has walls and façades only
    above the podium, none inside it. A part with a ``min_height`` above that keeps it;
    one standing on several takes the highest. Footprint id -> its new heights (only
    those that change)."""
    parts = {f.id: f.parts for f in footprints}
    bases: dict[str, float] = {}
    pairs, shapes, owner = podiums(footprints, heights)
    for low, high in pairs:
        under = volume(shapes[low], heights[owner[low]], roofs[owner[low]]).eaves
        bases[owner[high]] = max(bases.get(owner[high], heights[owner[high]].base), under)
    found = {}
    for key, base in sorted(bases.items()):
        lifted_heights = replace(heights[key], base=base)
        walls = [volume(part, lifted_heights, roofs[key]) for part in parts[key]]
        if base > heights[key].base and all(w.eaves - w.base >= MIN_WALL for w in walls):
            found[key] = lifted_heights
    return found


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
