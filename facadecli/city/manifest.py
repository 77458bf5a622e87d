"""The city manifest (SPEC 5): footprints, default and per-rule façades, heights, roofs.

A manifest is read like a spec (positions, hints, exit 2), and every façade spec it names
is loaded and checked before any building is started.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, StringConstraints

from facadecli.city.footprints import MAX_HEIGHT, number
from facadecli.errors import Problem, SpecError
from facadecli.files import read_prefix
from facadecli.limits import SPEC_BYTES_MAX
from facadecli.spec import load_spec
from facadecli.spec.load import validate_model
from facadecli.spec.model import COLOR_RE, NAME_RE, Model, Spec
from facadecli.spec.source import Path as DataPath
from facadecli.spec.source import SourceMap, read_document

RoofType = Literal[
    "flat",
    "shed",
    "gable",
    "hip",
    "pyramidal",
    "half_hip",
    "side_hip",
    "dutch_gable",
    "crosspitched",
    "sawtooth",
    "butterfly",
    "gambrel",
    "bellcast",
    "mansard",
    "saltbox",
    "dome",
    "round",
    "onion",
    "zakomar",
]


class Roof(Model):
    """A roof over every part of a footprint (OSM Simple 3D Buildings' roof shapes).

    ``pitch`` sets the slope of pitched roofs unless ``height`` (metres from the eaves to
    the top) is given; ``direction`` (compass degrees the main slope faces, downhill) turns
    shed and saltbox roofs and the ridge of gabled ones (the ridge runs across it);
    ``orientation`` puts the ridge along the footprint's long side (the default) or across.
    """

    type: RoofType = "flat"
    pitch: Annotated[float, Field(gt=0, lt=90)] = 30.0  # degrees, for sloped roofs
    height: Annotated[float, Field(gt=0, le=MAX_HEIGHT, allow_inf_nan=False)] | None = None
    direction: Annotated[float, Field(ge=0, lt=360, allow_inf_nan=False)] | None = None
    orientation: Literal["along", "across"] = "along"
    parapet: Annotated[float, Field(ge=0, le=5)] = 0.0  # metres of wall above a flat roof


Height = Annotated[float, Field(gt=0, le=MAX_HEIGHT, allow_inf_nan=False)]  # metres


class Range(Model):
    min: float | None = None
    max: float | None = None


ANY = "*"  # a rule's ``when`` value matching any value a feature's tag has (not "no")
Colours = Literal["tags", "spec"]  # who colours the walls and roof: the OSM tags, or the spec
Side = Literal["front", "back", "side"]


class WallRule(Model):
    """A façade spec for some walls of a building: ``side`` (front: the longest free wall
    and those facing its way; back: facing the other way; side: the rest), ``facing``
    (compass degrees the wall looks at, a range: 135 to 225 is south), ``length`` (metres).
    Every condition given must hold; the first rule that matches wins."""

    side: Side | list[Side] | None = None
    facing: Range | None = None
    length: Range | None = None
    facade: str

    def matches(self, side: str, facing: float, length: float) -> bool:
        sides = [self.side] if isinstance(self.side, str) else self.side
        return (
            (sides is None or side in sides)
            and (self.facing is None or _within(facing, self.facing))
            and (self.length is None or _within(length, self.length))
        )


def _within(value: float, bounds: Range) -> bool:
    return (bounds.min is None or value >= bounds.min) and (
        bounds.max is None or value <= bounds.max
    )


class Defaults(Model):
    facade: str
    height: Height = 9.0  # the top of the roof, when a feature has no height and no levels
    floor_height: Annotated[float, Field(gt=0, le=20, allow_inf_nan=False)] = 3.0
    roof: Roof = Roof()
    min_facade_width: Annotated[float, Field(ge=0)] = 2.0
    # a façade for the walls a building's own does not fit (too low, or too short, for any
    # layout of it), before they are left plain
    fallback_facade: str | None = None
    colours: Colours = "tags"
    walls: list[WallRule] = Field(default_factory=list)  # façades for some walls
    variants: Annotated[int, Field(ge=1, le=8)] = 1  # layouts a wall length may take
    palette: list[Annotated[str, StringConstraints(pattern=COLOR_RE)]] = Field(
        default_factory=list
    )  # wall colours a building may take (when its tags give none)
    party_wall_tolerance: Annotated[float, Field(ge=0, le=5, allow_inf_nan=False)] = 0.3
    # degrees: footprint edges this close to straight are one wall (0: every node a corner)
    collinear_angle: Annotated[float, Field(ge=0, le=20, allow_inf_nan=False)] = 3.0


class Rule(Model):
    when: dict[str, str | float | bool | Range]
    facade: str | None = None
    roof: Roof | None = None
    height: Height | None = None
    colours: Colours | None = None
    walls: list[WallRule] | None = None  # instead of the defaults' walls
    variants: Annotated[int, Field(ge=1, le=8)] | None = None
    palette: list[Annotated[str, StringConstraints(pattern=COLOR_RE)]] | None = None


class Source(Model):
    """A property holding a number, and the factor to metres (or levels)."""

    name: Annotated[str, StringConstraints(min_length=1, max_length=200)]
    scale: Annotated[float, Field(gt=0, allow_inf_nan=False)] = 1.0


class Properties(Model):
    """Where a dataset that is not OSM keeps heights and levels: ``height`` (the top of the
    roof), ``eaves`` (the top of the walls: the roof goes on top), ``levels`` (below the
    roof), ``min_height`` (the bottom of the walls)."""

    height: Source | None = None
    eaves: Source | None = None
    levels: Source | None = None
    min_height: Source | None = None

    def names(self) -> dict[str, tuple[str, float]]:
        return {
            key: (source.name, source.scale)
            for key in ("height", "eaves", "levels", "min_height")
            if (source := getattr(self, key)) is not None
        }


class Manifest(Model):
    version: Literal[1]
    name: Annotated[str, StringConstraints(pattern=NAME_RE, max_length=200)]
    footprints: str
    defaults: Defaults
    rules: list[Rule] = Field(default_factory=list)
    properties: Properties = Properties()
    seed: Annotated[int, Field(ge=0)] = 0  # varies each building's picks, reproducibly
    tiles: Annotated[float, Field(gt=0, le=100_000, allow_inf_nan=False)] | None = None  # m


@dataclass(frozen=True)
class City:
    """A manifest with its files resolved and its façade specs loaded."""

    manifest: Manifest
    folder: Path
    footprints: Path
    specs: dict[str, Spec]  # by the path the manifest gives

    def choose(self, properties: dict[str, Any]) -> Choice:
        """What a building gets: the first matching rule wins; else the feature's own OSM
        ``roof:shape`` (and ``roof:angle``); else the defaults (the roof a guess)."""
        defaults = self.manifest.defaults
        tagged = _tagged_roof(properties)
        facade, roof = defaults.facade, tagged or defaults.roof
        height, colours, walls = None, defaults.colours, defaults.walls
        variants, palette = defaults.variants, defaults.palette
        guessed = tagged is None  # the defaults' roof, unless a rule gives one
        for rule in self.manifest.rules:
            if all(_matches(properties, key, want) for key, want in rule.when.items()):
                facade = rule.facade or facade
                roof = rule.roof or roof
                height = rule.height
                colours = rule.colours or colours
                walls = rule.walls if rule.walls is not None else walls
                variants = rule.variants or variants
                palette = rule.palette if rule.palette is not None else palette
                guessed = guessed and rule.roof is None
                break
        return Choice(
            facade, roof, height, colours, tuple(walls), variants, tuple(palette), guessed
        )


@dataclass(frozen=True)
class Choice:
    """The manifest's choice for one building."""

    facade: str  # the spec's path, as the manifest gives it
    roof: Roof
    height: float | None  # the top of the roof a rule sets, if one does
    colours: str  # "tags" or "spec"
    walls: tuple[WallRule, ...] = ()  # façades for some walls, the first match wins
    variants: int = 1  # layouts a wall may take; each building picks one by its seed
    palette: tuple[str, ...] = ()  # wall colours a building may take
    guessed_roof: bool = False  # the defaults' roof: no roof:shape tag, no rule's roof


OSM_ROOFS: dict[str, RoofType] = {  # roof:shape -> the roof built
    "flat": "flat",
    "skillion": "shed",
    "lean_to": "shed",
    "gabled": "gable",
    "hipped": "hip",
    "side_hipped": "side_hip",
    "hipped-and-gabled": "dutch_gable",
    "pyramidal": "pyramidal",
    "cone": "pyramidal",
    "half-hipped": "half_hip",
    "half_hipped": "half_hip",
    "side_half-hipped": "half_hip",
    "gambrel": "gambrel",
    "bellcast_gable": "bellcast",
    "mansard": "mansard",
    "saltbox": "saltbox",
    # a gable whose ridge is moved off the middle, both eaves at one height: the ridge
    # as the saltbox has it, a third of the depth in, the long slope facing roof:direction
    "gabled_height_moved": "saltbox",
    "crosspitched": "crosspitched",
    "sawtooth": "sawtooth",
    "butterfly": "butterfly",
    "dome": "dome",
    "round": "round",
    "onion": "onion",
    "zakomar": "zakomar",
}


def _tagged_roof(properties: dict[str, Any]) -> Roof | None:
    name = str(properties.get("roof:shape", "")).strip().lower()
    kind = OSM_ROOFS.get(name)
    if kind is None:
        return None
    angle = number(properties.get("roof:angle"))
    return Roof(type=kind, pitch=angle if angle is not None and 0 < angle < 90 else 30.0)


def _matches(properties: dict[str, Any], key: str, want: str | float | bool | Range) -> bool:
    value = properties.get(key)
    if value is None and key == "levels":
        value = properties.get("building:levels")
    if want == ANY:  # the tag is there, with a value other than "no"
        return value is not None and str(value).strip().lower() not in ("", "no")
    if isinstance(want, Range):
        found = number(value)
        return found is not None and _within(found, want)
    if isinstance(want, bool) or isinstance(value, bool):
        return value == want
    if isinstance(want, float) or isinstance(value, (int, float)):
        return number(value) == number(want)
    return str(value) == str(want)


def load_city(path: Path) -> City:
    """Read and check a manifest and everything it names; raises SpecError (exit 2)."""
    try:
        raw = read_prefix(path, SPEC_BYTES_MAX)  # past the limit: read_document says where
    except OSError as error:
        raise SpecError.at(
            str(path), None, None, f"cannot read: {error.strerror}", "check the path"
        ) from None
    document = read_document(raw, str(path))
    manifest = validate_model(Manifest, document.data, document.source, "version, name, ...")
    source = document.source
    folder = path.parent
    problems: list[Problem] = []
    footprints = folder / manifest.footprints
    if not footprints.is_file():
        problems.append(
            source.problem(
                ("footprints",),
                f"no footprints file '{manifest.footprints}'",
                "give a GeoJSON path relative to the manifest",
            )
        )
    facades: list[tuple[DataPath, str]] = [(("defaults", "facade"), manifest.defaults.facade)]
    if manifest.defaults.fallback_facade is not None:
        facades.append((("defaults", "fallback_facade"), manifest.defaults.fallback_facade))
    for index, wall in enumerate(manifest.defaults.walls):
        facades.append((("defaults", "walls", index, "facade"), wall.facade))
    for index, rule in enumerate(manifest.rules):
        if rule.facade is not None:
            facades.append((("rules", index, "facade"), rule.facade))
        for position, wall in enumerate(rule.walls or []):
            facades.append((("rules", index, "walls", position, "facade"), wall.facade))
    specs: dict[str, Spec] = {}
    for where, facade in facades:
        if facade in specs:
            continue
        try:
            specs[facade] = load_spec(folder / facade)
        except SpecError as error:
            problems.append(_named_spec_problem(source, where, facade, error))
    if problems:
        raise SpecError(problems)
    return City(manifest, folder, footprints, specs)


def _named_spec_problem(
    source: SourceMap, where: DataPath, facade: str, error: SpecError
) -> Problem:
    first = error.problems[0]
    more = f" and {len(error.problems) - 1} more" if len(error.problems) > 1 else ""
    return source.problem(
        where,
        f"façade spec '{facade}' is not usable: {first}{more}",
        f"fix the spec, or check it with 'facade validate {facade}'",
    )
