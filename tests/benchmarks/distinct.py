"""Generated façades whose layers each have a pattern of their own, with a planted perfect
layout (every symbol at its preferred size, objective 0): the solver issue's grand hall with
any number of decoration layers, and a palace of distinct layers over any number of bays.
For benchmarks and tests: unlike :mod:`tests.benchmarks.generated`, no two layers share a
pattern, so nothing is aligned once for many layers."""

from __future__ import annotations

GRAND_HALL_PERIODS = (1, 2, 3, 4, 6, 12)  # bays between decorations (divisors of k = 12)


def grand_hall(decorations: int = 4) -> str:
    """The grand hall of the solver issue (base, portal, quoins, shops in their own
    group) with ``decorations`` decoration layers, each repeating every 1, 2, 3, 4, 6 or
    12 of its 12 bays, with symbols and counters of its own."""
    symbols = [
        "Q: 1.0",
        "M: 1.2",
        "N: 1.6",
        "Pl: 0.8",
        "G: 4.4",
        "K: 0.5",
        "Sb: 0.9",
        "Wh: 1.9",
        "Lb: 0.7",
        "R: 0.7",
        "At: 1.8",
        "Portal: 1.2",
        "PortalH: 4.4",
        "Sw: 0.8",
        "Sh: 2.8",
        "ShopH: 4.4",
        "Qs: {size: 1.0, opaque: false}",
    ]
    counters = ["k: {min: 1}", "f: {min: 1}", "s: {min: 1}"]
    patterns = [
        "bays: Q M (N M)^k Q",
        "floors: Pl G K (Sb Wh Lb)^f R At",
        "portal_x: {control: y m y, where: {m: Portal}}",
        "portal_y: {control: Pl u g1, where: {u: PortalH}}",
        "shop_x: Sw (Sh Sw)^s",
        "shop_y: {control: Pl u2 g2, where: {u2: ShopH}}",
        "quoins_x: {control: c r c, where: {c: Qs}}",
    ]
    layers = [
        "{name: base, x: bays, y: floors}",
        "{name: portal, x: portal_x, y: portal_y, offset: 0.15}",
        "{name: quoins, x: quoins_x, y: floors, offset: 0.05}",
        "{name: shops, x: shop_x, y: shop_y, groups: {x: shop}, offset: 0.1}",
    ]
    for i in range(decorations):
        period = GRAND_HALL_PERIODS[i % len(GRAND_HALL_PERIODS)]
        opaque = "" if i % 2 else ", opaque: false"
        symbols += [f"V{i}: {{size: 1.6{opaque}}}", f"H{i}: 1.9"]
        counters += [f"kx{i}: {{min: 1}}", f"ky{i}: {{min: 1}}"]
        run = "N M " * (period - 1)
        patterns += [
            f"px{i}: {{control: Q M ({run}s{i} M)^kx{i} Q, where: {{s{i}: V{i}}}}}",
            f"py{i}: {{control: Pl G K (Sb t{i} Lb)^ky{i} R At, where: {{t{i}: H{i}}}}}",
        ]
        layers.append(f"{{name: deco{i}, x: px{i}, y: py{i}, offset: {0.02 * (i + 1):.2f}}}")
    return _spec(f"grand-hall-{decorations}", 36.8, 22.2, symbols, counters, patterns, layers)


def distinct_palace(layers: int = 24, bays: int = 20, floors: int = 5) -> str:
    """A palace front of ``bays`` window bays and ``floors`` storeys whose ``layers``
    layers each have a pattern of their own: windows, pier ornaments and spacer bands
    repeating every so many bays (a divisor of ``bays``), a centred balcony, over storeys
    or the ground floor only; every symbol fits at its preferred size."""
    e, p, w = 1.2, 0.8, 1.6  # end, pier, window bay
    g, s, r = 4.0, 3.2, 1.4  # ground floor, storey, roof band
    width = round(2 * e + p + bays * (w + p), 6)
    height = round(g + floors * s + r, 6)
    periods = [d for d in range(1, bays + 1) if bays % d == 0][:6]
    symbols = [f"E: {e}", f"P: {p}", f"W: {w}", f"G: {g}", f"S: {s}", f"R: {r}"]
    counters = ["k: {min: 1}", "f: {min: 1}"]
    patterns = ["base_x: E P (W P)^k E", "base_y: G (S)^f R"]
    stack = ["{name: wall, x: base_x, y: base_y}"]
    for i in range(1, layers):
        period = periods[i % len(periods)]
        kind = i % 5
        if kind == 0:  # windows every `period` bays
            symbols.append(f"V{i}: {{size: {w}, opaque: false}}")
            x = f"{{control: a{i} (v{i} t{i})^j{i} b{i}, where: {{v{i}: V{i}}}}}"
        elif kind == 1:  # pier ornaments every `period` piers (a: the end; b: pier, end)
            symbols.append(f"O{i}: {p}")
            x = f"{{control: a{i} (o{i} t{i})^j{i} b{i}, where: {{o{i}: O{i}}}}}"
        elif kind == 2:  # a band of spacers `period` bays long
            symbols += [
                f"N{i}: {{size: {e}, opaque: false}}",
                f"L{i}: {p}",
                f"T{i}: {{size: {round(period * (w + p), 6)}, transparent: true}}",
            ]
            x = f"N{i} L{i} (T{i})^j{i} N{i}"
        elif kind == 3:  # a centred balcony over the middle bay or pier
            symbols.append(f"C{i}: {w if bays % 2 else p}")
            x = f"{{control: y{i} m{i} y{i}, where: {{m{i}: C{i}}}}}"
        else:  # frames of every window, with a sill band of its own
            symbols += [f"F{i}: {w}", f"Q{i}: {{size: {p}, transparent: true}}"]
            x = f"{{control: a{i} Q{i} (f{i} Q{i})^j{i} b{i}, where: {{f{i}: F{i}}}}}"
        if i % 3 == 0:  # the ground floor only
            symbols.append(f"Gy{i}: {g}")
            y = f"{{control: gy{i} h{i}, where: {{gy{i}: Gy{i}}}}}"
        else:  # every storey
            symbols.append(f"Sy{i}: {s}")
            y = f"{{control: g{i} (sy{i})^f{i} r{i}, where: {{sy{i}: Sy{i}}}}}"
            counters.append(f"f{i}: {{min: 1}}")
        if f"j{i}" in x:
            counters.append(f"j{i}: {{min: 1}}")
        patterns += [f"x{i}: {x}", f"y{i}: {y}"]
        stack.append(f"{{name: layer{i}, x: x{i}, y: y{i}, offset: {0.01 * i:.2f}}}")
    name = f"palace-{layers}-distinct-{bays}-bays"
    return _spec(name, width, height, symbols, counters, patterns, stack)


def _spec(
    name: str,
    width: float,
    height: float,
    symbols: list[str],
    counters: list[str],
    patterns: list[str],
    layers: list[str],
) -> str:
    lines = [
        "version: 1",
        f"name: {name}",
        f"canvas: {{width: {width}, height: {height}}}",
        "symbol_defaults: {opaque: true}",
        "symbols:",
        *(f"  {line}" for line in symbols),
        "counters:",
        *(f"  {line}" for line in counters),
        "patterns:",
        *(f"  {line}" for line in patterns),
        "layers:",
        *(f"  - {line}" for line in layers),
    ]
    return "\n".join(lines) + "\n"
