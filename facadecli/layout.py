"""Both axes -> the layout: letters of every layer, shapes (outer product, masks,
transparency, appearance rules) and occlusion flags (SPEC 2.5, 2.8)."""

from __future__ import annotations

import itertools
import math
from dataclasses import MISSING, dataclass, fields

import numpy as np

from facadecli.solver.axis import AxisLayout, PlacedLetter
from facadecli.spec.model import Layer, Material, ShapeRule, Spec

DEFAULT_MATERIAL = "default"  # the built-in neutral grey when no material is named
PANE_MATERIAL = "glass"  # the panes of frames and arches: the spec's glass, else this one
BUILTIN_GLASS = Material(
    color="#a9c8e4", metallic=0.0, roughness=0.05, opacity=0.35, transmission=0.9
)


@dataclass(frozen=True)
class Appearance:
    material: str
    mesh: str
    depth: float
    thickness: float
    frame_width: float | None = None
    pane_depth: float | None = None
    segments: int | None = None
    pane_material: str = PANE_MATERIAL
    sill: float | None = None
    panels: int | None = None
    glazing: float | None = None
    spacing: float | None = None


@dataclass(frozen=True)
class Shape:
    layer: str
    x: str
    y: str
    x0: float
    x1: float
    y0: float
    y1: float
    z0: float
    z1: float
    material: str
    mesh: str
    reflected_x: bool
    reflected_y: bool
    opaque: bool  # covers its whole cell (both symbols opaque, material not see-through)
    visible: bool = True  # False when hidden behind opaque shapes of layers in front
    look: Appearance | None = None  # the rule's parameters, for the geometry

    def hidden(self) -> Shape:
        """The shape marked hidden (made field by field: ``replace`` is slow for thousands)."""
        return Shape(
            self.layer,
            self.x,
            self.y,
            self.x0,
            self.x1,
            self.y0,
            self.y1,
            self.z0,
            self.z1,
            self.material,
            self.mesh,
            self.reflected_x,
            self.reflected_y,
            self.opaque,
            False,
            self.look,
        )


@dataclass(frozen=True)
class Layout:
    """A solved façade."""

    spec: Spec
    width: float
    height: float
    x: AxisLayout
    y: AxisLayout
    shapes: tuple[Shape, ...]
    time_ms: float

    @property
    def counters(self) -> dict[str, int]:
        return {**self.x.counters, **self.y.counters}

    @property
    def warnings(self) -> tuple[str, ...]:
        return self.x.warnings + self.y.warnings

    def letters(self, layer: int, axis: str) -> tuple[PlacedLetter, ...]:
        return (self.x if axis == "x" else self.y).letters.get(layer, ())


def appearance(spec: Spec, layer: Layer, x: str, y: str) -> Appearance:
    """The last matching rule wins, field by field: defaults, global rules, layer rules."""
    defaults = spec.defaults
    current: dict[str, object] = {  # the parameters' own defaults, then the spec's
        **{f.name: f.default for f in fields(Appearance) if f.default is not MISSING},
        "material": defaults.material or DEFAULT_MATERIAL,
        "mesh": defaults.mesh,
        "depth": defaults.depth,
        "thickness": defaults.thickness,
    }
    for rule in (*spec.shapes, *layer.shapes):
        if _matches(rule, x, y):
            for name in current:
                value = getattr(rule, name)
                if value is not None:
                    current[name] = value
    return Appearance(**current)  # type: ignore[arg-type]


def _matches(rule: ShapeRule, x: str, y: str) -> bool:
    return rule.match.x in ("*", x) and rule.match.y in ("*", y)


def _shown(layer: Layer, x: PlacedLetter, y: PlacedLetter) -> bool:
    if x.transparent or y.transparent:
        return False
    mask = layer.visible
    if mask is None:
        return True
    return (mask.x is None or x.symbol in mask.x) and (mask.y is None or y.symbol in mask.y)


def build_shapes(spec: Spec, x: AxisLayout, y: AxisLayout) -> tuple[Shape, ...]:
    shapes: list[Shape] = []
    for index, layer in enumerate(spec.layers):
        if not layer.enabled:
            continue
        looks: dict[tuple[str, str], Appearance] = {}  # a layer repeats a few symbols
        for row in y.letters.get(index, ()):
            for column in x.letters.get(index, ()):
                if not _shown(layer, column, row):
                    continue
                look = looks.get((column.symbol, row.symbol))
                if look is None:
                    look = looks[column.symbol, row.symbol] = appearance(
                        spec, layer, column.symbol, row.symbol
                    )
                front = layer.offset + look.depth
                material = spec.materials.get(look.material)
                see_through = material is not None and material.opacity < 1.0
                shapes.append(
                    Shape(
                        layer=layer.name,
                        x=column.symbol,
                        y=row.symbol,
                        x0=column.start,
                        x1=column.end,
                        y0=row.start,
                        y1=row.end,
                        z0=round(front - look.thickness, 6),
                        z1=round(front, 6),
                        material=look.material,
                        mesh=look.mesh,
                        reflected_x=column.reflected,
                        reflected_y=row.reflected,
                        opaque=spec.qualifiers(column.symbol).opaque
                        and spec.qualifiers(row.symbol).opaque
                        and not see_through,
                        look=look,
                    )
                )
    return _cull(shapes)


# meshes that fill their whole cell, from the depth given here up to their front: only
# they can hide what is behind them (a frame, an arch or a column leaves gaps to see through)
SOLID_BACK = {"box": "z0", "ledge": "z0", "panel": "z1"}


def _cull(shapes: list[Shape]) -> tuple[Shape, ...]:
    """Mark shapes hidden from every viewpoint in front: their cell is covered by opaque,
    solid shapes of later layers that stand flush on them (no gap between, so no oblique
    view sees behind them). A shape behind one that stands proud stays."""
    order = {name: i for i, name in enumerate(dict.fromkeys(s.layer for s in shapes))}
    solids = [
        (s.x0, s.x1, s.y0, s.y1, s.z1, order[s.layer], getattr(s, SOLID_BACK[s.mesh]), s)
        for s in shapes
        if s.opaque and s.mesh in SOLID_BACK
    ]
    if not solids:
        return tuple(shapes)
    grid = _Grid(solids)
    alike: dict[tuple[float, float, float, float], list[_Solid]] = {}  # by rectangle
    for solid in solids:
        alike.setdefault(solid[:4], []).append(solid)
    result = []
    for shape in shapes:
        layer, z, left, right, low, high = (
            order[shape.layer],
            shape.z1,
            shape.x0,
            shape.x1,
            shape.y0,
            shape.y1,
        )
        if any(  # most often a shape is hidden by one as large as itself
            o[5] > layer and o[4] >= z and o[6] <= z + 1e-9
            for o in alike.get((left, right, low, high), ())
        ):
            result.append(shape.hidden())
            continue
        occluders = []
        for near in grid.near(left, right, low, high):
            for x0, x1, y0, y1, front, o_layer, back, o in near:
                if o_layer <= layer:
                    break  # the rest are behind it (filed front to back)
                flush = front >= z and back <= z + 1e-9
                if flush and x0 < right and x1 > left and y0 < high and y1 > low:
                    occluders.append(o)
        hidden = bool(occluders) and _covered(shape, occluders)
        result.append(shape.hidden() if hidden else shape)
    return tuple(result)


# a solid shape: x0, x1, y0, y1, front, its layer's place (back to front), the depth its
# mesh fills from, and the shape
_Solid = tuple[float, float, float, float, float, int, float, Shape]


class _Grid:
    """Solid shapes filed by the cells of a grid over the façade that they overlap, to find
    those near a rectangle without looking at all of them."""

    LARGE = 16  # a shape over more cells than this is looked at for every rectangle

    def __init__(self, solids: list[_Solid]):
        self.x0, self.y0 = min(s[0] for s in solids), min(s[2] for s in solids)
        # cells about as large as a typical shape, so that a shape overlaps a few (and at
        # most 2 sqrt(n) cells a side)
        count = 2 * math.sqrt(len(solids))
        width, height = max(s[1] for s in solids) - self.x0, max(s[3] for s in solids) - self.y0
        self.dx = max(float(np.median([s[1] - s[0] for s in solids])), width / count, 1e-6)
        self.dy = max(float(np.median([s[3] - s[2] for s in solids])), height / count, 1e-6)
        self.cells: dict[tuple[int, int], list[_Solid]] = {}
        self.large: list[_Solid] = []
        for solid in sorted(solids, key=lambda solid: -solid[5]):  # front to back
            cells = self._cells(*solid[:4])
            if len(cells) > self.LARGE:
                self.large.append(solid)
                continue
            for cell in cells:
                self.cells.setdefault(cell, []).append(solid)

    def _cells(self, x0: float, x1: float, y0: float, y1: float) -> list[tuple[int, int]]:
        xs = range(max(0, int((x0 - self.x0) / self.dx)), int((x1 - self.x0) / self.dx) + 1)
        ys = range(max(0, int((y0 - self.y0) / self.dy)), int((y1 - self.y0) / self.dy) + 1)
        return [(i, j) for i in xs for j in ys]

    def near(self, x0: float, x1: float, y0: float, y1: float) -> list[list[_Solid]]:
        """The lists of solids, each front to back, filed in the cells the rectangle
        overlaps (one filed in several of them comes once for each), and the large ones."""
        lists = [self.cells[cell] for cell in self._cells(x0, x1, y0, y1) if cell in self.cells]
        return [*lists, self.large] if self.large else lists


def _covered(shape: Shape, occluders: list[Shape]) -> bool:
    """Is the shape's rectangle inside the union of the occluders' rectangles?"""
    xs = sorted(
        {
            shape.x0,
            shape.x1,
            *(min(max(o.x0, shape.x0), shape.x1) for o in occluders),
            *(min(max(o.x1, shape.x0), shape.x1) for o in occluders),
        }
    )
    ys = sorted(
        {
            shape.y0,
            shape.y1,
            *(min(max(o.y0, shape.y0), shape.y1) for o in occluders),
            *(min(max(o.y1, shape.y0), shape.y1) for o in occluders),
        }
    )
    for xa, xb in itertools.pairwise(xs):
        for ya, yb in itertools.pairwise(ys):
            if xb - xa < 1e-9 or yb - ya < 1e-9:
                continue
            cx, cy = (xa + xb) / 2, (ya + yb) / 2
            if not any(o.x0 <= cx <= o.x1 and o.y0 <= cy <= o.y1 for o in occluders):
                return False
    return True


def uncovered_area(layout: Layout) -> float:
    """Area of the canvas that no shape of any layer covers: a hole in the façade.

    Each axis is aligned on its own, so a lower layer may make room on one axis for a
    layer that does not cover that room on the other axis (SPEC 2.4's per-axis rule);
    this finds such holes in the plane."""
    boxes = np.array([(s.x0, s.x1, s.y0, s.y1) for s in layout.shapes]).reshape(-1, 4)
    xs = np.unique(np.concatenate([[0.0, layout.width], boxes[:, 0], boxes[:, 1]]))
    ys = np.unique(np.concatenate([[0.0, layout.height], boxes[:, 2], boxes[:, 3]]))
    i0, i1 = np.searchsorted(xs, boxes[:, 0]), np.searchsorted(xs, boxes[:, 1])
    j0, j1 = np.searchsorted(ys, boxes[:, 2]), np.searchsorted(ys, boxes[:, 3])
    # every shape adds one to the cells it covers: corners of a difference table, summed
    counts = np.zeros((len(xs), len(ys)), dtype=np.int64)
    np.add.at(counts, (i0, j0), 1)
    np.add.at(counts, (i1, j0), -1)
    np.add.at(counts, (i0, j1), -1)
    np.add.at(counts, (i1, j1), 1)
    covered = counts.cumsum(axis=0).cumsum(axis=1)[:-1, :-1] > 0
    areas = np.outer(np.diff(xs), np.diff(ys))
    return float(areas[~covered].sum())
