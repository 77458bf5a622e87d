"""The city manifest (SPEC 5): footprints, default and per-rule façades, heights, roofs.

A manifest is read like a spec (positions, hints, exit 2), and every façade spec it names
is loaded and checked before any building is started.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, StringConstraints

from facadecli.city.footprints import MAX_HEIGHT, building_height, number
from facadecli.errors import Problem, SpecError
from facadecli.spec import load_spec
from facadecli.spec.load import validate_model
from facadecli.spec.model import NAME_RE, Model, Spec
from facadecli.spec.source import Path as DataPath
from facadecli.spec.source import SourceMap, read_document

ROOF_TYPES = ("flat", "shed", "gable", "hip")
SUPPORTED_ROOFS = ROOF_TYPES


class Roof(Model):
    type: Literal["flat", "shed", "gable", "hip"] = "flat"
    pitch: Annotated[float, Field(gt=0, lt=90)] = 30.0  # degrees, for sloped roofs
    parapet: Annotated[float, Field(ge=0, le=5)] = 0.0  # metres of wall above a flat roof


class Range(Model):
    min: float | None = None
    max: float | None = None


Height = Annotated[float, Field(gt=0, le=MAX_HEIGHT, allow_inf_nan=False)]  # metres


class Defaults(Model):
    facade: str
    height: Height = 9.0
    floor_height: Annotated[float, Field(gt=0, le=20, allow_inf_nan=False)] = 3.0
    roof: Roof = Roof()
    min_facade_width: Annotated[float, Field(ge=0)] = 2.0


class Rule(Model):
    when: dict[str, str | float | bool | Range]
    facade: str | None = None
    roof: Roof | None = None
    height: Height | None = None


class Manifest(Model):
    version: Literal[1]
    name: Annotated[str, StringConstraints(pattern=NAME_RE, max_length=200)]
    footprints: str
    defaults: Defaults
    rules: list[Rule] = Field(default_factory=list)


@dataclass(frozen=True)
class City:
    """A manifest with its files resolved and its façade specs loaded."""

    manifest: Manifest
    folder: Path
    footprints: Path
    specs: dict[str, Spec]  # by the path the manifest gives

    def choose(self, properties: dict[str, Any]) -> tuple[str, Roof, float]:
        """(façade spec path, roof, height) for a building: the first matching rule wins;
        else the feature's own OSM ``roof:shape`` (and ``roof:angle``); else the defaults."""
        defaults = self.manifest.defaults
        facade, roof = defaults.facade, _tagged_roof(properties) or defaults.roof
        height = building_height(properties, defaults.height, defaults.floor_height)
        for rule in self.manifest.rules:
            if all(_matches(properties, key, want) for key, want in rule.when.items()):
                facade = rule.facade or facade
                roof = rule.roof or roof
                height = rule.height or height
                break
        return facade, roof, height


RoofType = Literal["flat", "shed", "gable", "hip"]
OSM_ROOFS: dict[str, RoofType] = {
    "flat": "flat",
    "skillion": "shed",
    "lean_to": "shed",
    "gabled": "gable",
    "hipped": "hip",
    "pyramidal": "hip",
}


def _tagged_roof(properties: dict[str, Any]) -> Roof | None:
    kind = OSM_ROOFS.get(str(properties.get("roof:shape", "")).strip().lower())
    if kind is None:
        return None
    angle = number(properties.get("roof:angle"))
    return Roof(type=kind, pitch=angle if angle is not None and 0 < angle < 90 else 30.0)


def _matches(properties: dict[str, Any], key: str, want: str | float | bool | Range) -> bool:
    value = properties.get(key)
    if value is None and key == "levels":
        value = properties.get("building:levels")
    if isinstance(want, Range):
        found = number(value)
        return (
            found is not None
            and (want.min is None or found >= want.min)
            and (want.max is None or found <= want.max)
        )
    if isinstance(want, bool) or isinstance(value, bool):
        return value == want
    if isinstance(want, float) or isinstance(value, (int, float)):
        return number(value) == number(want)
    return str(value) == str(want)


def load_city(path: Path) -> City:
    """Read and check a manifest and everything it names; raises SpecError (exit 2)."""
    try:
        raw = path.read_bytes()
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
    roofs: list[tuple[DataPath, Roof]] = [(("defaults", "roof"), manifest.defaults.roof)]
    facades: list[tuple[DataPath, str]] = [(("defaults", "facade"), manifest.defaults.facade)]
    for index, rule in enumerate(manifest.rules):
        if rule.facade is not None:
            facades.append((("rules", index, "facade"), rule.facade))
        if rule.roof is not None:
            roofs.append((("rules", index, "roof"), rule.roof))
    for where, roof in roofs:
        if roof.type not in SUPPORTED_ROOFS:
            problems.append(
                source.problem(
                    (*where, "type"),
                    f"roof type '{roof.type}' is not supported yet",
                    "use 'flat' (with a parapet)",
                )
            )
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
