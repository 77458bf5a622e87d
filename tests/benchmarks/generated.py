"""A generated many-layer façade for benchmarks: a palace front in the manner of the
paper's 26-layer Tonhalle, with as many layers as asked for and a canvas to match."""

from __future__ import annotations

# (name, x pattern, y pattern, mask y, offset): cycled through to make N layers
TEMPLATES = [
    ("wall", "wall_x", "storeys", None, 0.0),
    ("glass", "wall_x", "storeys", "[G, F]", -0.15),
    ("frames", "wall_x", "storeys", "[G, F]", 0.02),
    ("sills", "wall_x", "storeys", "[V]", 0.05),
    ("pilasters", "pilasters_x", "storeys", "[G, V, F]", 0.08),
    ("quoins", "quoins_x", "storeys", None, 0.1),
    ("balcony", "balcony_x", "storeys", "[V]", 0.3),
    ("cornice", "wall_x", "cornice_y", None, 0.2),
    ("plinth", "plinth_x", "storeys", "[Z]", 0.12),
    ("shutters", "wall_x", "storeys", "[F]", 0.06),
    ("ledges", "wall_x", "ledges_y", None, 0.15),
    ("bays", "bays_x", "storeys", "[G]", 0.04),
]


def generated_spec(layers: int = 24, bays: int = 7) -> str:
    """YAML text of a façade with ``layers`` layers and ``bays`` window bays."""
    width = 1.0 + bays * 2.4
    body = [
        "version: 1",
        f"name: palace-{layers}-layers",
        f"canvas: {{width: {width:.1f}, height: 15.6}}",
        "symbol_defaults: {opaque: true}",
        "symbols:",
        "  E: 1.0",
        "  W: {size: 1.4, unoccludable: true}",
        "  Lp: {size: 1.0, opaque: false}",
        "  Sp: {size: 1.4, transparent: true}",
        "  R: 1.4",
        "  M: 1.4",
        "  K: {size: 0.5, opaque: false}",
        "  Z: 0.6",
        "  G: 3.6",
        "  V: 1.0",
        "  F: 2.2",
        "  T: 1.2",
        "  L: 0.3",
        "  N: 1.0",
        "counters: {n: {min: 1}, k: {min: 1, max: 3}, j: 1}",
        "patterns:",
        '  wall_x: "E (W E)^n"',
        '  storeys: "Z G (V F)^+ T"',
        "  pilasters_x: {control: \"y m y\", where: {m: \"(Lp Sp)^k Lp\"}}",
        "  quoins_x: {control: \"q e q\", where: {q: \"K\"}}",
        "  balcony_x: {control: \"yb m c m^-1 yb\", where: {m: \"(R E)^j\", c: \"M\"}}",
        "  cornice_y: {control: \"h t\", where: {t: \"T\"}}",
        "  ledges_y: {control: \"z g (l f)^+ u\", where: {l: \"V\"}}",
        "  plinth_x: {control: \"p\", where: {p: \"N^*\"}}",
        "  bays_x: {control: \"s w s\", where: {w: \"(E W)^2 E\"}}",
        "layers:",
    ]
    for index in range(layers):
        name, x, y, mask, offset = TEMPLATES[index % len(TEMPLATES)]
        suffix = f"-{index // len(TEMPLATES)}" if index >= len(TEMPLATES) else ""
        visible = f", visible: {{y: {mask}}}" if mask else ""
        body.append(
            f"  - {{name: {name}{suffix}, x: {x}, y: {y}{visible}, offset: {offset + index * 0.001:.3f}}}"
        )
    return "\n".join(body) + "\n"
