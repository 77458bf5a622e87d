"""A generated many-layer façade for benchmarks: a palace front in the manner of the
paper's 26-layer Tonhalle. As there, most layers share the wall's rhythm (glass, frames,
sills, shutters, ledges, cornice, each masked to its storeys), and the rest are the
ornaments laid over it (pilasters, quoins, a central balcony, a plinth, a bay)."""

from __future__ import annotations

# (name, x pattern, y pattern, mask of y symbols, offset), back to front
WALL_LAYERS = [
    ("wall", "wall_x", "storeys", None, 0.0),
    ("glass", "wall_x", "storeys", "[G, F]", -0.15),
    ("frames", "wall_x", "storeys", "[G, F]", 0.02),
    ("sills", "wall_x", "storeys", "[V]", 0.05),
    ("shutters", "wall_x", "storeys", "[F]", 0.06),
    ("cornice", "wall_x", "cornice_y", None, 0.2),
    ("ledges", "wall_x", "ledges_y", None, 0.15),
]
ORNAMENTS = [
    ("plinth", "plinth_x", "storeys", "[Z]", 0.12),
    ("pilasters", "pilasters_x", "storeys", "[G, V, F]", 0.08),
    ("quoins", "quoins_x", "storeys", None, 0.1),
    ("balcony", "balcony_x", "storeys", "[V]", 0.3),
    ("bay", "bays_x", "storeys", "[G]", 0.04),
]


MATERIALS = {"render": "#e8dcc4", "glass": "#8fb3d9", "stone": "#b9a88a", "iron": "#3a3a3a"}


def generated_spec(layers: int = 24, bays: int = 7) -> str:
    """YAML text of a façade with ``layers`` layers and ``bays`` window bays: about half
    the layers on the wall's rhythm, the other half ornaments, repeated as needed."""
    width = 1.0 + bays * 2.4
    body = [
        "version: 1",
        f"name: palace-{layers}-layers",
        f"canvas: {{width: {width:.1f}, height: 15.6}}",
        "symbol_defaults: {opaque: true}",
        "symbols:",
        "  E: 1.0",
        "  W: 1.4",
        "  Lp: {size: 1.0, opaque: false}",
        "  Sp: {size: 1.4, transparent: true}",
        "  R: 1.4",
        "  M: 1.4",
        "  K: {size: 0.5, opaque: false}",
        "  N: 1.0",
        "  Q: {size: 1.4, transparent: true}",
        "  Z: 0.6",
        "  G: 3.6",
        "  V: 1.0",
        "  F: 2.2",
        "  T: 1.2",
        "counters: {n: {min: 1}, k: {min: 1, max: 3}, j: 1, f: {min: 1}}",
        "patterns:",
        '  wall_x: "E (W E)^n"',
        '  storeys: "Z G (V F)^f T"',
        '  pilasters_x: {control: "y m y", where: {m: "(Lp Sp)^k Lp"}}',
        '  quoins_x: {control: "q e q", where: {q: "K"}}',
        '  balcony_x: {control: "yb m c m^-1 yb", where: {m: "(R E)^j", c: "M"}}',
        '  cornice_y: {control: "h t", where: {t: "T"}}',
        '  ledges_y: {control: "z g (l x)^f u", where: {l: "V"}}',
        '  plinth_x: {control: "b (g b)^n", where: {b: "N"}}',
        '  bays_x: {control: "s w s", where: {w: "(Q E)^2 Q"}}',
        "defaults: {material: render}",
    ]
    wall_count = min(len(WALL_LAYERS), max(1, layers // 2))
    chosen = [WALL_LAYERS[i] for i in range(wall_count)]
    for index in range(layers - wall_count):
        name, x, y, mask, offset = ORNAMENTS[index % len(ORNAMENTS)]
        copy = index // len(ORNAMENTS)
        chosen.append((f"{name}-{copy}" if copy else name, x, y, mask, offset + 0.01 * copy))
    while len(chosen) < layers:  # more wall layers than templates: extra shutters
        chosen.insert(wall_count, (f"shutters-{len(chosen)}", "wall_x", "storeys", "[F]", 0.07))
    body.append("materials:")
    body.extend(f'  {name}: {{color: "{colour}"}}' for name, colour in MATERIALS.items())
    body.append("shapes:")
    for symbol, material in (
        ("W", "glass"),
        ("Lp", "stone"),
        ("K", "stone"),
        ("R", "iron"),
        ("M", "iron"),
        ("N", "stone"),
        ("T", "stone"),
    ):
        axis = "y" if symbol == "T" else "x"
        body.append(f"  - {{match: {{{axis}: {symbol}}}, material: {material}}}")
    body.append("layers:")
    for name, x, y, mask, offset in chosen:
        visible = f", visible: {{y: {mask}}}" if mask else ""
        body.append(f"  - {{name: {name}, x: {x}, y: {y}{visible}, offset: {offset:.3f}}}")
    return "\n".join(body) + "\n"
