"""The front elevation as SVG: visible shapes filled with their material's colour, layers
back to front, and with ``labels`` the symbol names and the alignment's column lines."""

from __future__ import annotations

from collections.abc import Callable
from xml.sax.saxutils import escape

from facadecli.geometry.cell import (
    CORONA,
    Cell,
    Rect,
    arch_radius,
    balcony_slab,
    door_plan,
    railing_plan,
    shutter_plan,
)
from facadecli.geometry.runs import built
from facadecli.layout import BUILTIN_GLASS, PANE_MATERIAL, Layout, Shape
from facadecli.spec.model import Spec

PIXELS_PER_METRE = 40.0
MARGIN = 20.0
FALLBACK_COLOUR = "#bfbfbf"
LABEL_CHAR = 5.4  # pixels a character of a 9 px label takes, at most
LABEL_LINE = 11.0  # pixels a label line takes


def _number(value: float) -> str:
    text = f"{value:.2f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def svg_text(layout: Layout, labels: bool = False) -> str:
    spec = layout.spec
    scale = PIXELS_PER_METRE
    width = layout.width * scale + 2 * MARGIN
    height = layout.height * scale + 2 * MARGIN

    def px(x: float) -> str:
        return _number(MARGIN + x * scale)

    def py(y: float) -> str:  # y runs up in the layout, down in SVG
        return _number(MARGIN + (layout.height - y) * scale)

    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{_number(width)}" '
        f'height="{_number(height)}" viewBox="0 0 {_number(width)} {_number(height)}">',
        f"<title>{escape(spec.name)}: front elevation</title>",
        f'<rect x="0" y="0" width="{_number(width)}" height="{_number(height)}" fill="#ffffff"/>',
        f'<rect x="{px(0)}" y="{py(layout.height)}" width="{_number(layout.width * scale)}" '
        f'height="{_number(layout.height * scale)}" fill="none" stroke="#999999" '
        'stroke-dasharray="4 3"/>',
    ]
    pieces = built(layout.shapes)
    for layer in spec.layers:
        shapes = [s for s in pieces if s.layer == layer.name]
        if not shapes:
            continue
        lines.append(f'<g id="layer-{escape(layer.name)}">')
        for shape in shapes:
            lines.extend(_shape(shape, spec, px, py, scale))
        lines.append("</g>")
    if labels:
        lines.append('<g id="labels" font-family="sans-serif" font-size="9" fill="#c00000">')
        for axis in (layout.x, layout.y):
            for columns in axis.groups.values():
                for boundary in columns.boundaries:
                    if axis.axis == "x":
                        lines.append(
                            f'<line x1="{px(boundary)}" y1="{py(0)}" x2="{px(boundary)}" '
                            f'y2="{py(layout.height)}" stroke="#c00000" stroke-width="0.5" '
                            'stroke-dasharray="2 2"/>'
                        )
                    else:
                        lines.append(
                            f'<line x1="{px(0)}" y1="{py(boundary)}" x2="{px(layout.width)}" '
                            f'y2="{py(boundary)}" stroke="#c00000" stroke-width="0.5" '
                            'stroke-dasharray="2 2"/>'
                        )
        for x, y, text in _labels(layout, scale):
            lines.append(
                f'<text x="{px(x)}" y="{py(y)}" text-anchor="middle" dominant-baseline="middle">'
                f"{escape(text)}</text>"
            )
        lines.append("</g>")
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def _colour(spec: Spec, name: str) -> tuple[str, float]:
    from facadecli.materials import resolve

    material = resolve(spec.materials, name)  # a library material: its colour
    if material is not None:
        return material.color[:7], material.opacity
    if name == PANE_MATERIAL:
        return BUILTIN_GLASS.color, BUILTIN_GLASS.opacity
    return FALLBACK_COLOUR, 1.0


def _fill(spec: Spec, name: str) -> str:
    colour, opacity = _colour(spec, name)
    return f'fill="{colour}"' + (f' fill-opacity="{_number(opacity)}"' if opacity < 1 else "")


def _shape(
    shape: Shape, spec: Spec, px: Callable[[float], str], py: Callable[[float], str], scale: float
) -> list[str]:
    """A shape as the front view of its mesh, from the same plans as the meshes: a frame's
    bars around its pane, an arch's curve over its pane, a door's leaf, panels and glazing,
    a railing's bars, a shutter's slats, a ledge's corona; anything else its cell."""
    title = f"<title>{escape(shape.layer)}: {escape(shape.x)} x {escape(shape.y)}</title>"
    outline = 'stroke="#333333" stroke-width="0.5"'
    fill = _fill(spec, shape.material)

    def rect(r: Rect, paint: str, extra: str = "") -> str:
        x0, x1, y0, y1 = _placed(shape, r)
        return (
            f'<rect x="{px(x0)}" y="{py(y1)}" width="{_number((x1 - x0) * scale)}" '
            f'height="{_number((y1 - y0) * scale)}" {paint} {outline}>{extra}</rect>'
        )

    w, h = shape.x1 - shape.x0, shape.y1 - shape.y0
    look = shape.look
    cell = Cell.of(shape)
    whole = (0.0, w, 0.0, h)
    if look is None or shape.mesh not in _DRAWN:
        return [rect(whole, fill, title)]
    pane = _fill(spec, look.pane_material)
    if shape.mesh == "door":
        plan = door_plan(cell)
        parts = [f"<g>{title}"]
        parts += [rect(r, fill) for r in plan.frame + plan.leaf + plan.panels]
        if plan.glass is not None:
            parts.append(rect(plan.glass, pane))
        return [*parts, "</g>"]
    if shape.mesh in ("railing", "balcony"):
        slab = balcony_slab(h) if shape.mesh == "balcony" else 0.0
        bars = railing_plan(w, h - slab, look.spacing)
        parts = [f"<g>{title}"]
        if slab:
            parts.append(rect((0.0, w, 0.0, slab), fill))
        parts += [rect((x0, x1, y0 + slab, y1 + slab), fill) for x0, x1, y0, y1 in bars.rails]
        parts += [rect((x0, x1, y0 + slab, y1 + slab), fill) for x0, x1, y0, y1 in bars.bars]
        return [*parts, "</g>"]
    if shape.mesh == "shutter":
        louvres = shutter_plan(cell)
        parts = [rect(whole, fill, title)]
        parts += [rect((x0, x1, y0, y0 + 0.3 * (y1 - y0)), fill) for x0, x1, y0, y1 in louvres.bars]
        return parts
    if shape.mesh == "ledge":
        corona = (0.0, w, CORONA[0] * h, CORONA[1] * h)
        return [rect(whole, fill, title), rect(corona, fill)]
    f = cell.frame
    parts = [rect(whole, fill, title)]
    x0, x1, y0 = shape.x0 + f, shape.x1 - f, shape.y0 + f
    if shape.mesh == "frame":
        parts.append(rect((f, w - f, f, h - f), pane))
        return parts
    radius = arch_radius(w, h, f)
    spring = shape.y1 - radius
    inner = max(radius - f, 1e-3)
    centre = (shape.x0 + shape.x1) / 2
    path = (
        f"M {px(x0)} {py(y0)} L {px(x1)} {py(y0)} L {px(x1)} {py(spring)} "
        f"L {px(centre + inner)} {py(spring)} "
        f"A {_number(inner * scale)} {_number(inner * scale)} 0 0 0 "
        f"{px(centre - inner)} {py(spring)} L {px(x0)} {py(spring)} Z"
    )
    parts.append(f'<path d="{path}" {pane} {outline}/>')
    return parts


_DRAWN = frozenset({"frame", "arch", "door", "railing", "balcony", "shutter", "ledge"})


def _placed(shape: Shape, part: Rect) -> Rect:
    """A rectangle of a cell's plan on the façade, mirrored as the shape's mesh is."""
    x0, x1, y0, y1 = part
    w, h = shape.x1 - shape.x0, shape.y1 - shape.y0
    if shape.reflected_x:
        x0, x1 = w - x1, w - x0
    if shape.reflected_y:
        y0, y1 = h - y1, h - y0
    return (shape.x0 + x0, shape.x0 + x1, shape.y0 + y0, shape.y0 + y1)


def _labels(layout: Layout, scale: float) -> list[tuple[float, float, str]]:
    """Symbol names of the visible shapes, front layers first, each where it fits: a label
    that would overlap one already placed moves up or down its cell by a line, or is left
    out, so labels never print over each other."""
    line = LABEL_LINE / scale
    front = {layer.name: -i for i, layer in enumerate(layout.spec.layers)}
    placed: list[tuple[float, float, float, float]] = []
    found = []
    for shape in sorted(
        (s for s in layout.shapes if s.visible),
        key=lambda s: (front[s.layer], s.x0, s.y0),
    ):
        text = f"{shape.x}{shape.y}"
        half_width = LABEL_CHAR * len(text) / scale / 2
        cx, cy = (shape.x0 + shape.x1) / 2, (shape.y0 + shape.y1) / 2
        for step in (0, 1, -1, 2, -2):
            y = cy + step * line
            box = (cx - half_width, cx + half_width, y - line / 2, y + line / 2)
            if box[2] < shape.y0 or box[3] > shape.y1:
                continue
            if not any(_overlap(box, other) for other in placed):
                placed.append(box)
                found.append((cx, y, text))
                break
    return found


def _overlap(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]
