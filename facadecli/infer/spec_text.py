"""A layered spec, as YAML text, from the grids of a labelled layout.

- The wall: the background, one opaque letter per cell between two consecutive edges of
  any element (so every element's edges are the wall's), along x and along y.
- One layer per grid, back to front: along each axis its word is the elements' sizes with
  the wall's cells between them; the layer's mask shows its elements only. Each layer is
  an alignment group of its own (SPEC 2.6): its word alone covers the canvas, so nothing
  is left to align, and the layers hold together through their shared symbols (the
  wall's cells, the elements' sizes), which the sizing QP gives one size each. Cells of
  one size share a symbol, and so do elements: equal gaps and mirrored margins stay equal
  when the spec is retargeted.
- Symbols have the sizes measured (in metres, to a tenth of a millimetre); elements are
  opaque (their shapes cover their cells). No symbol is unoccludable: every layer's
  cells between its elements stand in front of the layers behind it.
- Meshes and materials by label (frames for windows and shop fronts, doors, ledges for
  sills, cornices and mouldings, balconies, shutters for blinds, boxes for the rest),
  colours from the label palette; every layer says in a comment where it came from.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

from facadecli.grammar.palette import label_colour
from facadecli.infer.layers import Grid, Span, cuts

DECIMALS = 4  # of a metre in the sizes written
TOLERANCE = 0.01  # m: the solver's tolerance (sizes are written rounded)
MESHES = {  # CMP labels; anything else is a box
    "window": ("frame", 0.1),
    "door": ("door", 0.12),
    "shop": ("frame", 0.12),
    "sill": ("ledge", 0.12),
    "cornice": ("ledge", 0.3),
    "molding": ("ledge", 0.15),
    "balcony": ("balcony", 0.9),
    "blind": ("shutter", 0.06),
    "pillar": ("box", 0.2),
    "deco": ("box", 0.08),
}
DEFAULT_MESH = ("box", 0.1)
STEP = 0.02  # m: each layer stands this much further out than the one behind it


@dataclass
class _Symbols:
    """Symbol names by kind and size: one symbol per distinct size of a kind."""

    prefix: str
    sizes: dict[float, str]

    def of(self, size: float) -> str:
        key = round(size, 6)
        name = self.sizes.get(key)
        if name is None:
            name = self.sizes[key] = f"{self.prefix}{len(self.sizes) + 1}"
        return name


def ident(label: str) -> str:
    """A label as a name a spec accepts."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", label) or "label"
    return name if name[0].isalpha() else "L" + name


def _word(spans: tuple[Span, ...], edges: list[float], element: _Symbols, spacer: _Symbols) -> str:
    """Elements and, between them, a spacer per cell of the wall (so no letter is ever
    split: every row steps from one edge of the wall to the next with the others)."""
    letters = []
    starts = {a: (a, b) for a, b in spans}
    inside = None
    for a, b in itertools.pairwise(edges):
        if inside is not None:
            if b >= inside[1]:
                inside = None
            continue
        if a in starts:
            inside = starts[a]
            letters.append(element.of(inside[1] - inside[0]))
            if b >= inside[1]:
                inside = None
        else:
            letters.append(spacer.of(b - a))
    return " ".join(letters)


def _cells(edges: list[float], cell: _Symbols) -> str:
    return " ".join(cell.of(b - a) for a, b in itertools.pairwise(edges))


def _overlaps(grid: Grid, other: Grid) -> bool:
    return any(
        a < d and c < b and e < h and g < f
        for (a, b), (c, d) in itertools.product(grid.columns, other.columns)
        for (e, f), (g, h) in itertools.product(grid.rows, other.rows)
    )


def spec_text(name: str, width: float, height: float, found: list[Grid], source: str) -> str:
    """The spec (see the module)."""
    xs, ys = cuts(found, width, "x"), cuts(found, height, "y")
    wall_x, wall_y = _Symbols("wx", {}), _Symbols("wy", {})
    elements: dict[str, tuple[_Symbols, _Symbols]] = {}
    patterns = {"wall_x": _cells(xs, wall_x), "wall_y": _cells(ys, wall_y)}
    layers: list[tuple[str, Grid]] = []
    masks: dict[str, tuple[list[str], list[str]]] = {}
    for layer, grid in zip(layer_names(found), found, strict=True):
        base = ident(grid.label)
        symbols = elements.setdefault(
            grid.label, (_Symbols(f"{base}_w", {}), _Symbols(f"{base}_h", {}))
        )
        patterns[f"{layer}_x"] = _word(grid.columns, xs, symbols[0], wall_x)
        patterns[f"{layer}_y"] = _word(grid.rows, ys, symbols[1], wall_y)
        masks[layer] = (
            sorted({symbols[0].of(b - a) for a, b in grid.columns}),
            sorted({symbols[1].of(b - a) for a, b in grid.rows}),
        )
        layers.append((layer, grid))
    out = [
        f"# Inferred by `facade infer` from {source}: a wall and {len(layers)} layers, each",
        "# a label's elements on a grid (its columns x its rows), back to front. Between",
        "# its elements a layer holds the wall's cells (wx, wy), and shows its elements only.",
        "version: 1",
        f"name: {name}",
        f"canvas: {{width: {_number(width)}, height: {_number(height)}}}",
        "symbol_defaults: {opaque: true}",
        f"solver: {{tolerance: {TOLERANCE}}}",
        "symbols:",
    ]
    for names, label in ((wall_x, "wall"), (wall_y, "wall")):
        out += [f"  {n}: {{size: {_number(s)}, label: {label}}}" for s, n in names.sizes.items()]
    for label, pair in elements.items():
        for names in pair:
            for size, symbol in names.sizes.items():
                out.append(f"  {symbol}: {{size: {_number(size)}, label: {label}}}")
    out.append("patterns:")
    out += [f'  {pattern}: "{word}"' for pattern, word in patterns.items()]
    out.append("layers:")
    out += [
        "  - name: wall  # the background, cut at every element's edges",
        "    x: wall_x",
        "    y: wall_y",
        "    shapes: [{material: wall, mesh: box, thickness: 0.3}]",
    ]
    for k, (layer, grid) in enumerate(layers, start=1):
        mesh, thickness = MESHES.get(grid.label, DEFAULT_MESH)
        rows = ", ".join(f"{_number(a)}-{_number(b)}" for a, b in grid.rows)
        out += [
            f"  - name: {layer}  # {grid.elements} {grid.label} of the input: "
            f"{len(grid.columns)} columns, rows at y = {rows}",
            f"    x: {layer}_x",
            f"    y: {layer}_y",
            f"    visible: {{x: [{', '.join(masks[layer][0])}], "
            f"y: [{', '.join(masks[layer][1])}]}}",
            f"    groups: {{x: {layer}, y: {layer}}}",
            f"    offset: {_number(STEP * k)}",
            f"    shapes: [{{material: {ident(grid.label)}, mesh: {mesh}, "
            f"thickness: {thickness}}}]",
        ]
    out.append("materials:")
    out.append(f'  wall: {{color: "{label_colour("facade")}"}}')
    out += [f'  {ident(label)}: {{color: "{label_colour(label)}"}}' for label in elements]
    return "\n".join(out) + "\n"


def layer_names(found: list[Grid]) -> list[str]:
    """A name for each grid's layer: its label, numbered from the second grid of a label
    on (``wall`` is the background's)."""
    taken: dict[str, int] = {"wall": 1}
    names = []
    for grid in found:
        base = ident(grid.label)
        taken[base] = taken.get(base, 0) + 1
        names.append(base if taken[base] == 1 else f"{base}_{taken[base]}")
    return names


def _number(value: float) -> str:
    text = f"{round(value, DECIMALS):.{DECIMALS}f}".rstrip("0").rstrip(".")
    return text if text not in ("", "-0") else "0"
