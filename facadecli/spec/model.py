"""The spec model (SPEC section 1): frozen pydantic models, unknown keys rejected.

These models check each value on its own (types, ranges, names). Checks that need the
whole spec (unknown symbols in patterns, counters on both axes, ...) live in
:mod:`facadecli.spec.check`, which also knows where in the file each value came from.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Discriminator,
    Field,
    StringConstraints,
    Tag,
    field_validator,
    model_validator,
)

from facadecli.limits import CANVAS_MAX, COUNT_MAX, LENGTH_MAX

NAME_RE = r"^[A-Za-z0-9_.-]+$"
IDENT_RE = r"^[A-Za-z_][A-Za-z0-9_]*$"
COLOR_RE = r"^#(?:[0-9a-fA-F]{6}|[0-9a-fA-F]{8})$"

#: Built-in parametric meshes; anything else in ``mesh`` is a file path next to the spec.
BUILTIN_MESHES = (
    "box",
    "panel",
    "frame",
    "arch",
    "column",
    "ledge",
    "door",
    "railing",
    "balcony",
    "shutter",
)

Ident = Annotated[str, StringConstraints(pattern=IDENT_RE)]
# every length within LENGTH_MAX (a depth of 1e21 m would make a model 1e21 m deep)
Length = Annotated[float, Field(ge=-LENGTH_MAX, le=LENGTH_MAX, allow_inf_nan=False)]
PositiveLength = Annotated[float, Field(gt=0, le=LENGTH_MAX, allow_inf_nan=False)]
NonNegativeLength = Annotated[float, Field(ge=0, le=LENGTH_MAX, allow_inf_nan=False)]
Count = Annotated[int, Field(ge=0, le=COUNT_MAX)]
Unit = Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)]
EMISSIVE_MOST = 10.0  # a material's emissive: a room lit by day is 2 or 3 times its colour


class Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)


def _shorthand_schema(shorthand: dict[str, Any]) -> Any:
    """JSON-schema hook: the model also accepts a bare scalar (``A: 0.6``, ``n: 3``)."""

    def extend(schema: dict[str, Any]) -> None:
        full = dict(schema)
        schema.clear()
        schema["anyOf"] = [shorthand, full]

    return extend


CanvasLength = Annotated[float, Field(gt=0, le=CANVAS_MAX, allow_inf_nan=False)]


class Canvas(Model):
    """The façade's extent in metres."""

    width: CanvasLength
    height: CanvasLength


class Qualifiers(Model):
    """Default qualifiers for every symbol (SPEC 2.4)."""

    opaque: bool = False
    attached: bool = False
    unoccludable: bool = False
    transparent: bool = False


class Symbol(Model):
    """A symbol: preferred size, hard bounds, qualifiers. ``A: 0.6`` is ``A: {size: 0.6}``."""

    model_config = ConfigDict(
        json_schema_extra=_shorthand_schema({"type": "number", "exclusiveMinimum": 0})
    )

    size: PositiveLength | None = None
    min: NonNegativeLength | None = None
    max: PositiveLength | None = None
    opaque: bool | None = None
    attached: bool | None = None
    unoccludable: bool | None = None
    transparent: bool | None = None
    label: str | None = None

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value: Any) -> Any:
        if value is None:
            return {}
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return {"size": value}
        return value

    @model_validator(mode="after")
    def _bounds(self) -> Symbol:
        if self.min is not None and self.max is not None and self.min > self.max:
            raise ValueError(f"min {self.min} is greater than max {self.max}")
        if self.size is not None:
            if self.min is not None and self.min > self.size:
                raise ValueError(f"min {self.min} is greater than size {self.size}")
            if self.max is not None and self.size > self.max:
                raise ValueError(f"size {self.size} is greater than max {self.max}")
        return self

    def qualifiers(self, defaults: Qualifiers) -> Qualifiers:
        """This symbol's qualifiers, with unset ones taken from ``defaults``."""
        return Qualifiers(
            opaque=defaults.opaque if self.opaque is None else self.opaque,
            attached=defaults.attached if self.attached is None else self.attached,
            unoccludable=defaults.unoccludable if self.unoccludable is None else self.unoccludable,
            transparent=defaults.transparent if self.transparent is None else self.transparent,
        )


class Counter(Model):
    """A named counter shared by every pattern naming it. ``n: 3`` fixes it to 3."""

    model_config = ConfigDict(
        json_schema_extra=_shorthand_schema({"type": "integer", "minimum": 0})
    )

    min: Count = 0
    max: Count | None = None

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, value: Any) -> Any:
        if isinstance(value, int) and not isinstance(value, bool):
            return {"min": value, "max": value}
        return value

    @model_validator(mode="after")
    def _bounds(self) -> Counter:
        if self.max is not None and self.min > self.max:
            raise ValueError(f"min {self.min} is greater than max {self.max}")
        return self

    @property
    def fixed(self) -> bool:
        return self.max == self.min

    @property
    def bounds(self) -> tuple[int, int | None]:
        return self.min, self.max


class SubstitutedPattern(Model):
    """A control pattern whose placeholders are replaced by content patterns (SPEC 2.3)."""

    control: str
    where: Annotated[dict[Ident, str], Field(min_length=1)]


def _pattern_kind(value: Any) -> str:
    return "text" if isinstance(value, str) else "substituted"


PatternDef = Annotated[
    Annotated[str, Tag("text")] | Annotated[SubstitutedPattern, Tag("substituted")],
    Discriminator(_pattern_kind),
]


class LayerMask(Model):
    """Symbols whose shapes a layer shows (SPEC 2.5); a missing list shows all."""

    x: list[Ident] | None = None
    y: list[Ident] | None = None


class Groups(Model):
    """Alignment group of a layer's horizontal and vertical pattern (SPEC 2.6)."""

    x: Ident = "default"
    y: Ident = "default"


class ShapeMatch(Model):
    """Which shapes a rule applies to: symbols on each axis, ``*`` for any."""

    x: str = "*"
    y: str = "*"


class ShapeRule(Model):
    """Appearance of the shapes a rule matches; later rules win, field by field."""

    match: ShapeMatch = ShapeMatch()
    material: MaterialName | None = None  # a name under materials, or a library material
    mesh: str | None = None
    depth: Length | None = None
    thickness: NonNegativeLength | None = None
    frame_width: PositiveLength | None = None  # frame and arch: width of the frame's bars
    pane_depth: NonNegativeLength | None = None  # pane recess
    segments: Annotated[int, Field(ge=3, le=128)] | None = None  # arch and column smoothness
    pane_material: MaterialName | None = None  # frame, arch, door: the pane's (default: glass)
    sill: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] | None = None  # frame, arch
    panels: Annotated[int, Field(ge=0, le=12)] | None = None  # door: rows of raised panels
    glazing: Annotated[float, Field(ge=0, le=0.9, allow_inf_nan=False)] | None = None  # door
    spacing: Annotated[float, Field(ge=0.03, le=2, allow_inf_nan=False)] | None = None  # bars


class Layer(Model):
    """One layer: the outer product of a horizontal and a vertical word."""

    name: Annotated[str, StringConstraints(pattern=NAME_RE)]
    x: str
    y: str
    visible: LayerMask | None = None
    groups: Groups = Groups()
    offset: Length = 0.0
    enabled: bool = True
    shapes: list[ShapeRule] = []


MaterialName = Annotated[str, StringConstraints(pattern=r"^[A-Za-z_][A-Za-z0-9_-]*$")]


class Material(Model):
    """A PBR material (glTF metallic-roughness); with ``library``, a material of the
    library whose fields set here replace the library's."""

    library: MaterialName | None = None  # a library material to start from (brick-flemish)
    color: Annotated[str, StringConstraints(pattern=COLOR_RE)] = "#bfbfbf"
    metallic: Unit = 0.0
    roughness: Unit = 0.8
    opacity: Unit = 1.0
    transmission: Unit = 0.0  # light passing through (glass): KHR_materials_transmission
    texture: str | None = None  # a PNG or JPEG next to the spec, tinted by color
    texture_size: PositiveLength = 1.0  # metres of façade one copy of the texture covers
    scale: PositiveLength = 1.0  # library: its texture's size in metres, times this
    resolution: Literal[64, 128, 256, 512, 1024] = 512  # library: pixels a side
    seed: Annotated[int, Field(ge=0, le=2**32 - 1)] = 0  # library: its texture's random choices
    ior: Annotated[float, Field(ge=1, le=3, allow_inf_nan=False)] | None = None  # glass: 1.5
    # light it gives off, times its colour (a lit room): glTF's emissiveFactor, over 1 with
    # KHR_materials_emissive_strength
    emissive: Annotated[float, Field(ge=0, le=EMISSIVE_MOST, allow_inf_nan=False)] = 0.0

    @model_validator(mode="after")
    def _library_fields(self) -> Material:
        if self.library is not None and self.texture is not None:
            raise ValueError("a library material draws its own texture: drop 'texture'")
        if self.library is None:
            library_only = {"scale", "resolution", "seed"} & self.model_fields_set
            if library_only:
                field = sorted(library_only)[0]
                raise ValueError(f"'{field}' applies to a library material: add 'library:'")
        return self


class Defaults(Model):
    """Appearance of shapes no rule sets (SPEC 2.8)."""

    mesh: str = "box"
    material: MaterialName | None = None
    thickness: NonNegativeLength = 0.2
    depth: Length = 0.0


class Solver(Model):
    """Solver options."""

    tolerance: NonNegativeLength = 0.0
    time_limit: Annotated[float, Field(gt=0, le=86_400)] = 10.0
    seed: Annotated[int, Field(ge=0)] = 0


class Spec(Model):
    """A façade spec (SPEC section 1)."""

    model_config = ConfigDict(
        title="facadecli façade spec",
        json_schema_extra={"$schema": "https://json-schema.org/draft/2020-12/schema"},
    )

    version: Literal[1]
    name: Annotated[str, StringConstraints(pattern=NAME_RE, max_length=200)]
    canvas: Canvas
    symbol_defaults: Qualifiers = Qualifiers()
    symbols: Annotated[dict[Ident, Symbol], Field(min_length=1)]
    counters: dict[Ident, Counter] = {}
    patterns: Annotated[dict[Ident, PatternDef], Field(min_length=1)]
    layers: Annotated[list[Layer], Field(min_length=1)]
    shapes: list[ShapeRule] = []
    materials: dict[Ident, Material] = {}
    defaults: Defaults = Defaults()
    solver: Solver = Solver()

    @field_validator("canvas")
    @classmethod
    def _finite_canvas(cls, canvas: Canvas) -> Canvas:
        if not (math.isfinite(canvas.width) and math.isfinite(canvas.height)):
            raise ValueError("canvas sizes must be finite")
        return canvas

    @cached_property
    def _qualifiers(self) -> dict[str, Qualifiers]:
        return {name: s.qualifiers(self.symbol_defaults) for name, s in self.symbols.items()}

    def qualifiers(self, symbol: str) -> Qualifiers:
        """Qualifiers of a symbol; undeclared symbols (placeholders) take the defaults."""
        return self._qualifiers.get(symbol, self.symbol_defaults)

    def size(self, symbol: str) -> float | None:
        """Preferred size of a symbol, None for an unsized one (a placeholder)."""
        declared = self.symbols.get(symbol)
        return declared.size if declared else None
