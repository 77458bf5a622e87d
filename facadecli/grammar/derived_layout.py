"""A derivation's pieces as a ``Layout``, for the layout writers (glb, obj, json, svg):
one layer per label, in CMP's z-order, each label a look (a frame, a ledge, a box)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from facadecli.grammar.model import Piece
from facadecli.grammar.split import Axis
from facadecli.grammar.tiling import BACKGROUND, CMP_Z_ORDER

if TYPE_CHECKING:
    from facadecli.layout import Layout

NAME_MAX = 150  # characters of the source's name in a derived layout's name


@dataclass(frozen=True)
class Look:
    mesh: str
    depth: float  # front face out from the wall, in fifteenths of the façade's shorter side
    thickness: float  # in the same units


LOOKS = {  # CMP labels; anything else is a shallow box
    BACKGROUND: Look("box", 0.0, 0.3),
    "window": Look("frame", 0.0, 0.3),
    "door": Look("frame", 0.0, 0.3),
    "shop": Look("frame", 0.0, 0.3),
    "balcony": Look("box", 0.4, 0.7),
    "cornice": Look("ledge", 0.15, 0.45),
    "molding": Look("ledge", 0.1, 0.4),
    "sill": Look("ledge", 0.1, 0.4),
    "pillar": Look("box", 0.1, 0.4),
    "blind": Look("box", 0.02, 0.32),
}
DEFAULT_LOOK = Look("box", 0.05, 0.35)


def _ident(label: str, taken: set[str]) -> str:
    name = re.sub(r"[^A-Za-z0-9_]", "_", label) or "label"
    if not name[0].isalpha():
        name = "L" + name
    base, n = name, 2
    while name in taken:
        name, n = f"{base}_{n}", n + 1
    taken.add(name)
    return name


def pieces_layout(
    pieces: list[Piece], width: float, height: float, name: str, warnings: list[str]
) -> Layout:
    """A ``Layout`` of the pieces, one layer per label, for the layout writers."""
    from facadecli.grammar.palette import label_colour
    from facadecli.layout import Appearance, Layout, Shape
    from facadecli.solver.axis import AxisLayout
    from facadecli.spec.model import Spec

    unit = min(width, height) / 15  # looks are in metres for a façade 15 m on its shorter side
    labels = sorted(
        {p.label for p in pieces}, key=lambda label: (CMP_Z_ORDER.get(label, 99), label)
    )
    taken: set[str] = set()
    idents = {label: _ident(label, taken) for label in labels}
    spec = Spec.model_validate(
        {
            "version": 1,
            "name": name,
            "canvas": {"width": width, "height": height},
            "symbols": {idents[label]: {"label": label} for label in labels},
            "patterns": {idents[label]: idents[label] for label in labels},
            "layers": [
                {"name": idents[label], "x": idents[label], "y": idents[label]} for label in labels
            ],
            "materials": {idents[label]: {"color": label_colour(label)} for label in labels},
        }
    )
    shapes = []
    for p in sorted(pieces, key=lambda p: (labels.index(p.label), p.y0, p.x0)):
        look = LOOKS.get(p.label, DEFAULT_LOOK)
        ident = idents[p.label]
        shapes.append(
            Shape(
                layer=ident,
                x=ident,
                y=ident,
                x0=p.x0,
                x1=p.x1,
                y0=p.y0,
                y1=p.y1,
                z0=round((look.depth - look.thickness) * unit, 6),
                z1=round(look.depth * unit, 6),
                material=ident,
                mesh=look.mesh,
                reflected_x=False,
                reflected_y=False,
                opaque=True,
                look=Appearance(ident, look.mesh, look.depth * unit, look.thickness * unit),
            )
        )
    extents: tuple[tuple[Axis, float], ...] = (("x", width), ("y", height))
    axes = [
        AxisLayout(
            axis,
            extent,
            {},
            {},
            {},
            {},
            {},
            0.0,
            0.0,
            0,
            tuple(w for w in warnings if w.startswith(axis)),
        )
        for axis, extent in extents
    ]
    return Layout(spec, width, height, axes[0], axes[1], tuple(shapes), 0.0)


def safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:NAME_MAX] or "layout"
