"""The front elevation as SVG: visible shapes filled with their material's colour, layers
back to front, and with ``labels`` the symbol names and the alignment's column lines."""

from __future__ import annotations

from xml.sax.saxutils import escape

from facadecli.layout import Layout

PIXELS_PER_METRE = 40.0
MARGIN = 20.0
FALLBACK_COLOUR = "#bfbfbf"


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
    for layer in spec.layers:
        shapes = [s for s in layout.shapes if s.layer == layer.name and s.visible]
        if not shapes:
            continue
        lines.append(f'<g id="layer-{escape(layer.name)}">')
        for shape in shapes:
            material = spec.materials.get(shape.material)
            colour = material.color[:7] if material else FALLBACK_COLOUR
            opacity = material.opacity if material else 1.0
            lines.append(
                f'<rect x="{px(shape.x0)}" y="{py(shape.y1)}" '
                f'width="{_number((shape.x1 - shape.x0) * scale)}" '
                f'height="{_number((shape.y1 - shape.y0) * scale)}" fill="{colour}" '
                + (f'fill-opacity="{_number(opacity)}" ' if opacity < 1 else "")
                + 'stroke="#333333" stroke-width="0.5">'
                f"<title>{escape(shape.layer)}: {escape(shape.x)} x {escape(shape.y)}</title>"
                "</rect>"
            )
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
        for shape in layout.shapes:
            if shape.visible:
                cx = (shape.x0 + shape.x1) / 2
                cy = (shape.y0 + shape.y1) / 2
                lines.append(
                    f'<text x="{px(cx)}" y="{py(cy)}" text-anchor="middle">'
                    f"{escape(shape.x)}{escape(shape.y)}</text>"
                )
        lines.append("</g>")
    lines.append("</svg>")
    return "\n".join(lines) + "\n"
