"""Both axes -> the layout: letters of every layer, shapes (outer product, masks,
transparency, appearance rules) and occlusion flags (SPEC 2.5, 2.8)."""

from __future__ import annotations

import itertools
import math
import statistics
from dataclasses import MISSING, dataclass, fields

import numpy as np

from facadecli.solver.axis import AxisLayout, PlacedLetter
from facadecli.spec.model import Layer, Material, ShapeRule, Spec

DEFAULT_MATERIAL = "default"  # the built-in neutral grey when no material is named
PANE_MATERIAL = "glass"  # the panes of frames and arches: the spec's glass, else this one
BUILTIN_GLASS = Material(
    color="#a9c8e4", metallic=0.0, roughness=0.05, opacity=0.35, transmission=0.9
)
INTERIOR_MATERIAL = "interior"  # the dark recess behind every window: the spec's, else this
BUILTIN_INTERIOR = Material(color="#26282c", metallic=0.0, roughness=0.95)
# the rooms of the ground floor (a ``rooms`` interior), lit as a shop or a room is at
# street level: the spec's, else its interior giving off LIT_INTERIOR of its colour
LIT_INTERIOR_MATERIAL = "interior-lit"
LIT_INTERIOR = 1.2


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


def _shown(layer: Layer, letters: tuple[PlacedLetter, ...], axis: str) -> list[PlacedLetter]:
    """A layer's letters on one axis that may make shapes: not transparent, and in the
    layer's mask on that axis if it has one (a shape is shown iff both its letters are)."""
    mask = layer.visible
    allowed = None if mask is None else getattr(mask, axis)
    return [
        letter
        for letter in letters
        if not letter.transparent and (allowed is None or letter.symbol in allowed)
    ]


def build_shapes(spec: Spec, x: AxisLayout, y: AxisLayout) -> tuple[Shape, ...]:
    # each shape's fields first, as a tuple in Shape's order (without visible and look)
    # and its look: the cull reads them, then each Shape is made once, hidden or not
    made: list[tuple[_Fields, Appearance]] = []
    for index, layer in enumerate(spec.layers):
        if not layer.enabled:
            continue
        # what a pair of symbols looks like: a layer repeats a few
        looks: dict[tuple[str, str], tuple[Appearance, float, float, bool]] = {}
        columns = _shown(layer, x.letters.get(index, ()), "x")
        for row in _shown(layer, y.letters.get(index, ()), "y"):
            for column in columns:
                found = looks.get((column.symbol, row.symbol))
                if found is None:
                    found = looks[column.symbol, row.symbol] = _look(
                        spec, layer, column.symbol, row.symbol
                    )
                look, z0, z1, opaque = found
                fields: _Fields = (
                    layer.name,
                    column.symbol,
                    row.symbol,
                    column.start,
                    column.end,
                    row.start,
                    row.end,
                    z0,
                    z1,
                    look.material,
                    look.mesh,
                    column.reflected,
                    row.reflected,
                    opaque,
                )
                made.append((fields, look))
    hidden = _hidden([fields for fields, _ in made])
    return tuple(
        Shape(*fields, not hide, look) for (fields, look), hide in zip(made, hidden, strict=True)
    )


def _look(spec: Spec, layer: Layer, x: str, y: str) -> tuple[Appearance, float, float, bool]:
    """A pair of symbols' appearance in a layer, its depths (back, front) and whether it
    covers its whole cell (both symbols opaque, the material not see-through)."""
    look = appearance(spec, layer, x, y)
    front = layer.offset + look.depth
    material = spec.materials.get(look.material)
    see_through = material is not None and material.opacity < 1.0
    opaque = spec.qualifiers(x).opaque and spec.qualifiers(y).opaque and not see_through
    return look, round(front - look.thickness, 6), round(front, 6), opaque


# meshes that fill their whole cell, from the depth given here up to their front: only
# they can hide what is behind them (a frame, an arch or a column leaves gaps to see through)
SOLID_BACK = {"box": "z0", "ledge": "z0", "panel": "z1"}
_BACK_FIELD = {"z0": 7, "z1": 8}  # where those depths are in a shape's fields

# a shape's fields in Shape's order, up to opaque (the cull reads them before the shape is
# made): layer, x, y, x0, x1, y0, y1, z0, z1, material, mesh, reflected x and y, opaque
_Fields = tuple[str, str, str, float, float, float, float, float, float, str, str, bool, bool, bool]


def cull(shapes: list[Shape]) -> tuple[Shape, ...]:
    """The shapes, those hidden from every viewpoint in front marked so (see _hidden)."""
    fields: list[_Fields] = [
        (
            s.layer,
            s.x,
            s.y,
            s.x0,
            s.x1,
            s.y0,
            s.y1,
            s.z0,
            s.z1,
            s.material,
            s.mesh,
            s.reflected_x,
            s.reflected_y,
            s.opaque,
        )
        for s in shapes
    ]
    hidden = _hidden(fields)
    return tuple(s.hidden() if h else s for s, h in zip(shapes, hidden, strict=True))


def _hidden(shapes: list[_Fields]) -> list[bool]:
    """Which shapes (their fields, in Shape's order) are hidden from every viewpoint in
    front: their cell is covered by opaque, solid shapes of later layers that stand flush
    on them (no gap between, so no oblique view sees behind them). A shape behind one
    that stands proud stays."""
    order = {name: i for i, name in enumerate(dict.fromkeys(s[0] for s in shapes))}
    solids: list[_Solid] = [
        (s[3], s[4], s[5], s[6], s[8], order[s[0]], float(s[_BACK_FIELD[SOLID_BACK[s[10]]]]))
        for s in shapes
        if s[13] and s[10] in SOLID_BACK
    ]
    if not solids:
        return [False] * len(shapes)
    grid = _Grid(solids)
    alike: dict[tuple[float, float, float, float], list[_Solid]] = {}  # by rectangle
    for solid in solids:
        alike.setdefault(solid[:4], []).append(solid)
    result = []
    for shape in shapes:
        layer, z = order[shape[0]], shape[8]
        rectangle = left, right, low, high = shape[3], shape[4], shape[5], shape[6]
        if any(  # most often a shape is hidden by one as large as itself
            o[5] > layer and o[4] >= z and o[6] <= z + 1e-9 for o in alike.get(rectangle, ())
        ):
            result.append(True)
            continue
        occluders = []
        for near in grid.near(left, right, low, high):
            for x0, x1, y0, y1, front, o_layer, back in near:
                if o_layer <= layer:
                    break  # the rest are behind it (filed front to back)
                flush = front >= z and back <= z + 1e-9
                if flush and x0 < right and x1 > left and y0 < high and y1 > low:
                    occluders.append((x0, x1, y0, y1))
        result.append(bool(occluders) and _covered(rectangle, occluders))
    return result


# a solid shape: x0, x1, y0, y1, front, its layer's place (back to front), and the depth
# its mesh fills from
_Solid = tuple[float, float, float, float, float, int, float]


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
        self.dx = max(statistics.median(s[1] - s[0] for s in solids), width / count, 1e-6)
        self.dy = max(statistics.median(s[3] - s[2] for s in solids), height / count, 1e-6)
        self.cells: dict[tuple[int, int], list[_Solid]] = {}
        self.large: list[_Solid] = []
        ordered = sorted(solids, key=lambda solid: -solid[5])  # front to back
        # the cells of every solid at once (as _cells finds them, at numpy's speed)
        box = np.array([solid[:4] for solid in ordered])
        i0 = np.maximum(0, ((box[:, 0] - self.x0) / self.dx).astype(int)).tolist()
        i1 = ((box[:, 1] - self.x0) / self.dx).astype(int).tolist()
        j0 = np.maximum(0, ((box[:, 2] - self.y0) / self.dy).astype(int)).tolist()
        j1 = ((box[:, 3] - self.y0) / self.dy).astype(int).tolist()
        cells = self.cells
        for solid, a, b, c, d in zip(ordered, i0, i1, j0, j1, strict=True):
            if (b - a + 1) * (d - c + 1) > self.LARGE:
                self.large.append(solid)
                continue
            for i in range(a, b + 1):
                for j in range(c, d + 1):
                    found = cells.get((i, j))
                    if found is None:
                        cells[i, j] = [solid]
                    else:
                        found.append(solid)

    def _cells(self, x0: float, x1: float, y0: float, y1: float) -> list[tuple[int, int]]:
        xs = range(max(0, int((x0 - self.x0) / self.dx)), int((x1 - self.x0) / self.dx) + 1)
        ys = range(max(0, int((y0 - self.y0) / self.dy)), int((y1 - self.y0) / self.dy) + 1)
        return [(i, j) for i in xs for j in ys]

    def near(self, x0: float, x1: float, y0: float, y1: float) -> list[list[_Solid]]:
        """The lists of solids, each front to back, filed in the cells the rectangle
        overlaps (one filed in several of them comes once for each), and the large ones."""
        lists = [self.cells[cell] for cell in self._cells(x0, x1, y0, y1) if cell in self.cells]
        return [*lists, self.large] if self.large else lists


def _covered(
    rectangle: tuple[float, float, float, float],
    occluders: list[tuple[float, float, float, float]],
) -> bool:
    """Is the rectangle (x0, x1, y0, y1) inside the union of the occluders' rectangles?"""
    x0, x1, y0, y1 = rectangle
    xs = sorted(
        {
            x0,
            x1,
            *(min(max(o[0], x0), x1) for o in occluders),
            *(min(max(o[1], x0), x1) for o in occluders),
        }
    )
    ys = sorted(
        {
            y0,
            y1,
            *(min(max(o[2], y0), y1) for o in occluders),
            *(min(max(o[3], y0), y1) for o in occluders),
        }
    )
    for xa, xb in itertools.pairwise(xs):
        for ya, yb in itertools.pairwise(ys):
            if xb - xa < 1e-9 or yb - ya < 1e-9:
                continue
            cx, cy = (xa + xb) / 2, (ya + yb) / 2
            if not any(o[0] <= cx <= o[1] and o[2] <= cy <= o[3] for o in occluders):
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
