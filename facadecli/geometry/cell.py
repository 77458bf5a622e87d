"""What a shape's geometry is sized from, shared by the meshes and the SVG elevation (no
mesh library needed to read it)."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from facadecli.layout import Shape

DEFAULT_SEGMENTS = 12
Rect = tuple[float, float, float, float]  # x0, x1, y0, y1 in a cell's own frame


@dataclass(frozen=True)
class Cell:
    """What a primitive is sized from: the cell and the shape rule's parameters."""

    width: float
    height: float
    thickness: float
    frame_width: float | None = None
    pane_depth: float | None = None
    segments: int | None = None
    sill: float | None = None
    panels: int | None = None
    glazing: float | None = None
    spacing: float | None = None

    @classmethod
    def of(cls, shape: Shape) -> Cell:
        """The cell of a placed shape, with its rule's parameters."""
        look = shape.look
        assert look is not None
        parameters = {name: getattr(look, name) for name in PARAMETERS}
        return cls(
            width=round(shape.x1 - shape.x0, 6),
            height=round(shape.y1 - shape.y0, 6),
            thickness=round(shape.z1 - shape.z0, 6),
            **parameters,
        )

    @property
    def frame(self) -> float:
        """Frame width: the rule's, or a tenth of the smaller side (at most 12 cm)."""
        default = min(0.12, 0.1 * min(self.width, self.height))
        wanted = self.frame_width if self.frame_width is not None else default
        return max(1e-3, min(wanted, 0.45 * min(self.width, self.height)))

    @property
    def pane(self) -> float:
        """How far the pane sits behind the frame's front."""
        return self.pane_depth if self.pane_depth is not None else max(0.02, 0.5 * self.thickness)


#: a cell's parameters beyond its size: the shape rule's, by the same names
PARAMETERS = tuple(f.name for f in fields(Cell) if f.name not in ("width", "height", "thickness"))
CORONA = (0.6, 0.9)  # where a ledge's vertical front runs, as shares of its height


def balcony_slab(height: float) -> float:
    """How thick a balcony's floor slab is: 15 cm, at most a fifth of its cell's height."""
    return min(0.15, 0.2 * height)


def arch_radius(width: float, height: float, frame: float) -> float:
    """The radius of an arch's outer curve: a semicircle as wide as its cell, when it fits."""
    return min(width / 2, height - frame)


@dataclass(frozen=True)
class DoorPlan:
    """A door's front view: frame (jambs and head, no sill: a door reaches the floor), the
    leaf around its glazing, raised panels on the leaf, and the glazing if any."""

    frame: list[Rect]
    leaf: list[Rect]
    panels: list[Rect]
    glass: Rect | None


def door_plan(cell: Cell) -> DoorPlan:
    """The parts of a door: ``panels`` rows of raised panels (two columns on a leaf 0.8 m
    wide or more) below an upper ``glazing`` share of the leaf in glass."""
    w, h, f = cell.width, cell.height, cell.frame
    frame = [(0.0, f, 0.0, h - f), (w - f, w, 0.0, h - f), (0.0, w, h - f, h)]
    top = h - f
    stile = min(0.12, 0.15 * (w - 2 * f), 0.15 * top)
    glazed = (cell.glazing or 0.0) * (top - 2 * stile)
    glass: Rect | None = None
    solid_top = top
    if glazed > 1e-3:
        low = top - stile - glazed
        glass = (f + stile, w - f - stile, low, top - stile)
        leaf = [
            (f, w - f, 0.0, low),
            (f, f + stile, low, top - stile),
            (w - f - stile, w - f, low, top - stile),
            (f, w - f, top - stile, top),
        ]
        solid_top = low
    else:
        leaf = [(f, w - f, 0.0, top)]
    rows = cell.panels if cell.panels is not None else 2
    columns = 2 if w - 2 * f >= 0.8 else 1
    gap = stile / 2
    x0, x1, y0, y1 = f + stile, w - f - stile, stile, solid_top - stile
    panels: list[Rect] = []
    if rows and x1 - x0 > columns * gap and y1 - y0 > rows * gap:
        pw = (x1 - x0 - (columns - 1) * gap) / columns
        ph = (y1 - y0 - (rows - 1) * gap) / rows
        for row in range(rows):
            for col in range(columns):
                px, py = x0 + col * (pw + gap), y0 + row * (ph + gap)
                panels.append((px, px + pw, py, py + ph))
    return DoorPlan(frame, leaf, panels, glass)


@dataclass(frozen=True)
class BarPlan:
    """A railing's front view: posts and rails, and the bars between them."""

    rails: list[Rect] = field(default_factory=list)
    bars: list[Rect] = field(default_factory=list)


def railing_plan(length: float, height: float, spacing: float | None) -> BarPlan:
    """Posts at both ends, a handrail on top, a bottom rail 8 cm up and square bars every
    ``spacing`` metres (12 cm by default: a child's head must not pass)."""
    post = min(0.05, 0.2 * length)
    rail = min(0.05, 0.1 * height)
    bottom = min(0.08, 0.2 * height)
    rails = [
        (0.0, post, 0.0, height),
        (length - post, length, 0.0, height),
        (post, length - post, height - rail, height),
        (post, length - post, bottom, bottom + rail / 2),
    ]
    step = spacing if spacing is not None else 0.12
    inner = length - 2 * post
    count = max(0, round(inner / step) - 1)
    bar = min(0.02, 0.4 * step)
    bars = []
    for i in range(count):
        centre = post + (i + 1) * inner / (count + 1)
        bars.append((centre - bar / 2, centre + bar / 2, bottom + rail / 2, height - rail))
    return BarPlan(rails, bars)


def shutter_plan(cell: Cell) -> BarPlan:
    """A louvred shutter's front view: stiles and rails around slats ``spacing`` apart
    (6 cm by default); each slat's rectangle is the band it covers seen head-on."""
    w, h = cell.width, cell.height
    stile = min(0.06, 0.12 * w, 0.12 * h)
    rails = [
        (0.0, stile, 0.0, h),
        (w - stile, w, 0.0, h),
        (stile, w - stile, 0.0, stile),
        (stile, w - stile, h - stile, h),
    ]
    step = cell.spacing if cell.spacing is not None else 0.06
    count = max(0, int((h - 2 * stile) / step))
    pitch = (h - 2 * stile) / count if count else 0.0
    slats = [(stile, w - stile, stile + i * pitch, stile + (i + 1) * pitch) for i in range(count)]
    return BarPlan(rails, slats)
