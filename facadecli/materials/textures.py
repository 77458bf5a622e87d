"""Procedural PBR texture sets: a height field, a colour field and a roughness field over
one square tile of a surface (brick in its bonds, ashlar, render, ...), made with numpy
from a seed, and turned into the three images glTF wants.

Every field is periodic over the tile: units (bricks, blocks, boards, slates) are laid
modulo the tile's width and height, and noise is white noise filtered in the frequency
domain, which wraps by construction. So the left edge of an image continues its right
edge, and the top its bottom: a wall textured in metres shows no seam where one copy of
the tile meets the next.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

Field = np.ndarray  # (n, n) float64, row 0 at the top of the tile (image order)


@dataclass(frozen=True)
class Surface:
    """What a generator draws: height in metres of relief, colour as linear-ish RGB in
    0..1 (before the material's own colour is applied), roughness 0..1 as an offset
    around the material's roughness, metal 0..1."""

    height: Field
    colour: np.ndarray  # (n, n, 3)
    roughness: Field
    metal: Field
    tinted: Field | None = None  # 0..1: how much the material's colour applies (1: all)
    # the relief ambient occlusion reads (None: ``height``): the joints between units, not
    # the grain of their faces, whose pits are too shallow for their width to shade
    cavities: Field | None = None
    # the ambient occlusion itself, 0..1 (None: from ``cavities``, :func:`occlusion`): a
    # room's, which sees the sky through its window alone
    occlusion: Field | None = None


@dataclass(frozen=True)
class TextureSet:
    """The images of a material, as uint8 arrays: base colour (sRGB), tangent-space
    normal, and glTF's packed occlusion (R), roughness (G), metallic (B)."""

    base_colour: np.ndarray
    normal: np.ndarray
    orm: np.ndarray


def noise(
    rng: np.random.Generator,
    n: int,
    scale: float,
    tile: float,
    aniso: tuple[float, float] = (1.0, 1.0),
) -> Field:
    """Periodic smooth noise with features about ``scale`` metres across (``aniso``
    stretches them along x and y), zero mean, unit deviation. Features are at least
    three pixels across: finer noise would alias, and no PNG can compress it."""
    scale = max(scale, 3 * tile / n)
    white = rng.standard_normal((n, n))
    freq = np.fft.fftfreq(n, d=tile / n)  # cycles per metre
    fy, fx = np.meshgrid(freq, freq, indexing="ij")
    radius = np.hypot(fx * scale * aniso[0], fy * scale * aniso[1])
    filtered = np.fft.ifft2(np.fft.fft2(white) * np.exp(-((radius * 2.0) ** 2))).real
    deviation = filtered.std()
    normalised: Field = (filtered - filtered.mean()) / (deviation if deviation > 0 else 1.0)
    return normalised


def blur(field: Field, radius_px: float) -> Field:
    """A periodic Gaussian blur (through the frequency domain, so it wraps too)."""
    n = field.shape[0]
    freq = np.fft.fftfreq(n)
    fy, fx = np.meshgrid(freq, freq, indexing="ij")
    kernel = np.exp(-2.0 * (np.pi * radius_px) ** 2 * (fx**2 + fy**2))
    return np.fft.ifft2(np.fft.fft2(field) * kernel).real


def grid(n: int, tile: float) -> tuple[Field, Field]:
    """Metric coordinates of the pixel centres: x to the right, y up from the tile's
    bottom (row 0 is the top of the image)."""
    step = tile / n
    centres = (np.arange(n) + 0.5) * step
    x, y = np.meshgrid(centres, centres[::-1])
    return x, y


@dataclass(frozen=True)
class Units:
    """Each pixel's unit (brick, block, slate) in a coursed layout: an id unique within
    the tile, the distance to the unit's nearest joint, and the position inside it."""

    ident: np.ndarray  # int
    edge: Field  # metres to the nearest joint line
    u: Field  # 0..1 across the unit
    v: Field  # 0..1 up the unit


def coursed(
    x: Field, y: Field, tile: float, courses: list[tuple[float, list[float], float]]
) -> Units:
    """Units laid in courses from the bottom: each course is (height, lengths of its
    units repeating along it, offset of the first unit). Every course's repeat must
    divide the tile, and the heights must sum to it, so the layout wraps."""
    ident = np.zeros(x.shape, dtype=np.int64)
    edge = np.zeros(x.shape)
    u = np.zeros(x.shape)
    v = np.zeros(x.shape)
    bottom = 0.0
    first = 0
    for height, lengths, offset in courses:
        inside = (y >= bottom) & (y < bottom + height)
        period = float(sum(lengths))
        starts = np.concatenate([[0.0], np.cumsum(lengths)])
        along = np.mod(x[inside] + offset, period)
        index = np.searchsorted(starts, along, side="right") - 1
        start, length = starts[index], np.asarray(lengths)[index]
        repeat = np.floor((x[inside] + offset) / period)
        repeats = max(1, round(tile / period))
        ident[inside] = first + np.mod(repeat, repeats).astype(np.int64) * len(lengths) + index
        dx = along - start
        dy = y[inside] - bottom
        edge[inside] = np.minimum.reduce([dx, length - dx, dy, height - dy])
        u[inside] = dx / length
        v[inside] = dy / height
        first += repeats * len(lengths)
        bottom += height
    return Units(ident, edge, u, v)


def per_unit(rng: np.random.Generator, ident: np.ndarray, spread: float) -> Field:
    """A random value per unit, normal with the given spread."""
    values = rng.standard_normal(int(ident.max()) + 1) * spread
    picked: Field = values[ident]
    return picked


def smoothstep(a: float, b: float, t: Field) -> Field:
    s = np.clip((t - a) / (b - a), 0.0, 1.0)
    return s * s * (3 - 2 * s)


def jointed(
    units: Units,
    rng: np.random.Generator,
    noise_field: Field,
    joint: float,
    recess: float,
    colour_spread: float,
    mortar: tuple[float, float, float],
    bevel: float,
    grain: float = 0.0015,
    mottle: Field | None = None,
) -> Surface:
    """Units with recessed joints of ``joint`` metres: the unit colour varies per unit
    and with noise, the mortar is its own colour, rougher and lower. ``grain`` is the
    relief (metres, one deviation) the noise gives a unit's face: a brick's is rough, a
    dressed stone's smooth. ``mottle`` is the noise the face's colour takes (else
    ``noise_field``'s). Only the joints occlude (:attr:`Surface.cavities`)."""
    face = smoothstep(joint / 2, joint / 2 + bevel, units.edge)  # 0 in the joint, 1 on the face
    mottle = noise_field if mottle is None else mottle
    shade = 1.0 + per_unit(rng, units.ident, colour_spread) + 0.04 * mottle
    hue = per_unit(rng, units.ident, colour_spread * 0.5)
    body = np.stack([shade + hue, shade, shade - hue], axis=-1)
    colour = body * face[..., None] + np.asarray(mortar) * (1 - face[..., None])
    height = recess * face + grain * noise_field * face
    roughness = 0.08 * noise_field + 0.08 * (1 - face)
    return Surface(height, colour, roughness, np.zeros_like(height), face, recess * face)


# --- the kinds of surface ---------------------------------------------------------------

BRICK, HEADER, JOINT = 0.215, 0.1025, 0.01  # metres: a UK brick, its header face, a joint
COURSE = 0.065 + JOINT


def _bricks(bond: str) -> Callable[[int, float, np.random.Generator], Surface]:
    stretcher, header = BRICK + JOINT, HEADER + JOINT

    def make(n: int, tile: float, rng: np.random.Generator) -> Surface:
        x, y = grid(n, tile)
        count = round(tile / COURSE)
        courses = []
        for k in range(count):
            if bond == "stretcher":
                courses.append((COURSE, [stretcher], (k % 2) * stretcher / 2))
            elif bond == "english":
                courses.append(
                    (COURSE, [stretcher], 0.0) if k % 2 == 0 else (COURSE, [header], header / 2)
                )
            else:  # flemish: stretcher and header alternate, headers centred on stretchers
                courses.append((COURSE, [stretcher, header], (k % 2) * (stretcher + header) / 2))
        units = coursed(x, y, tile, courses)
        grain = noise(rng, n, 0.01, tile)
        return jointed(units, rng, grain, JOINT, 0.006, 0.08, (0.78, 0.75, 0.70), 0.003)

    return make


def _ashlar(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    heights = [0.3, 0.4, 0.3, 0.35, 0.45, 0.3, 0.3]
    heights = [h * tile / sum(heights) for h in heights]
    courses = []
    for height in heights:
        parts = rng.uniform(0.5, 1.0, size=max(2, round(tile / 0.7)))
        lengths = list(parts * tile / parts.sum())
        courses.append((height, lengths, float(rng.uniform(0, tile))))
    units = coursed(x, y, tile, courses)
    tooled = noise(rng, n, 0.03, tile)
    # its colour: a sand grain (the finest the picture holds) over a soft cloud about a
    # block's height across, not the tooling's 3 cm blobs (a camouflage close up)
    mottle = 0.6 * noise(rng, n, 0.002, tile) + 0.8 * noise(rng, n, 0.3, tile)
    # a dressed face: 0.3 mm of tooling (was 1.5, with 0.8 mm of grain 5 mm across on
    # top: at 1024 px a face's normals leaned 12 degrees on average, and its pits, as
    # deep as the joints, shaded in the occlusion map: blotches a fifth darker)
    joints = (0.006, 0.004, 0.05, (0.80, 0.78, 0.74), 0.004, 0.0003, mottle)
    surface = jointed(units, rng, tooled, *joints)
    return replace(surface, height=surface.height + 0.0001 * noise(rng, n, 0.005, tile))


def _render(n: int, tile: float, rng: np.random.Generator) -> Surface:
    coarse, fine = noise(rng, n, 0.25, tile), noise(rng, n, 0.004, tile)
    shade = 1.0 + 0.03 * coarse + 0.02 * fine
    colour = np.repeat(shade[..., None], 3, axis=-1)
    # a float finish: its grain a trace of relief (0.03 mm; it was 0.3, and at 1024 px
    # its normals leaned 5 degrees and its pits shaded in the occlusion map, down to
    # 0.59), and nothing recessed to occlude
    height = 0.00003 * fine + 0.0004 * coarse
    flat = np.zeros((n, n))
    return Surface(height, colour, 0.05 * fine, flat, cavities=flat)


def _concrete(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    units = coursed(x, y, tile, [(tile / 2, [tile / 2], 0.0)] * 2)  # formwork panels
    coarse, fine = noise(rng, n, 0.3, tile), noise(rng, n, 0.003, tile)
    line = smoothstep(0.0, 0.004, units.edge)
    ties = np.hypot(units.u - 0.5, units.v - 0.5) * tile / 2 > 0.012  # the tie holes
    shade = 1.0 + 0.05 * coarse + 0.025 * fine + per_unit(rng, units.ident, 0.02)
    colour = np.repeat((shade * (0.9 + 0.1 * line))[..., None], 3, axis=-1)
    # only the formwork lines and the tie holes occlude; the surface's grain is a trace
    # of relief (0.05 mm; it was 0.5, and its pits shaded like the lines, down to 0.41)
    recessed = 0.002 * line + 0.004 * ties - 0.004
    height = recessed + 0.00005 * fine
    return Surface(height, colour, 0.05 * coarse, np.zeros((n, n)), cavities=recessed)


def _timber(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    board = tile / round(tile / 0.15)
    units = coursed(
        x, y, tile, [(board, [tile], float(rng.uniform(0, tile)))] * round(tile / board)
    )
    grain = noise(rng, n, 0.004, tile, aniso=(0.05, 1.0))
    rings = np.sin(40 * units.v + 3 * noise(rng, n, 0.05, tile, aniso=(0.2, 1.0)))
    shade = 1.0 + 0.10 * grain + 0.05 * rings + per_unit(rng, units.ident, 0.08)
    colour = np.stack([shade * 1.02, shade, shade * 0.96], axis=-1)
    lap = units.v * 0.006 + 0.0008 * grain  # each board laps over the one below
    face = smoothstep(0.0, 0.003, units.edge)
    return Surface(lap * face, colour * (0.55 + 0.45 * face[..., None]), 0.06 * grain, 0 * lap)


def _metal(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    seams = coursed(x, y, tile, [(tile, [tile / 2], 0.0)])  # standing seams 0.5 m apart
    brushed = noise(rng, n, 0.002, tile, aniso=(1.0, 0.02))
    seam = np.exp(-((np.minimum(seams.u, 1 - seams.u) * tile / 2 / 0.01) ** 2))
    colour = np.repeat((1.0 + 0.03 * brushed)[..., None], 3, axis=-1)
    height = 0.02 * seam + 0.0002 * brushed
    return Surface(height, colour, 0.06 * brushed, np.ones((n, n)))


def _roof_tiles(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    width, rows = tile / round(tile / 0.2), round(tile / 0.3)
    courses = [(tile / rows, [width], (k % 2) * width / 2) for k in range(rows)]
    units = coursed(x, y, tile, courses)
    profile = np.sin(np.pi * units.u) ** 0.7  # a rounded tile across its width
    shade = 1.0 + per_unit(rng, units.ident, 0.09) + 0.04 * noise(rng, n, 0.02, tile)
    colour = np.stack([shade, shade, shade], axis=-1) * (0.75 + 0.25 * profile[..., None])
    lift = per_unit(rng, units.ident, 0.002)  # no two tiles lie quite alike
    height = 0.02 * profile + 0.015 * (1 - units.v) + lift  # each course laps the one below
    return Surface(height, colour, 0.06 * noise(rng, n, 0.01, tile), np.zeros((n, n)))


def _slate(n: int, tile: float, rng: np.random.Generator) -> Surface:
    x, y = grid(n, tile)
    width, rows = tile / round(tile / 0.25), round(tile / 0.2)
    courses = [(tile / rows, [width], (k % 2) * width / 2) for k in range(rows)]
    units = coursed(x, y, tile, courses)
    cleft = noise(rng, n, 0.01, tile, aniso=(1.0, 0.3))
    face = smoothstep(0.0, 0.002, units.edge)
    shade = 1.0 + per_unit(rng, units.ident, 0.08) + 0.04 * cleft
    colour = np.repeat(shade[..., None], 3, axis=-1) * (0.6 + 0.4 * face[..., None])
    height = 0.006 * (1 - units.v) * face + 0.0006 * cleft  # each slate's tail is thicker
    return Surface(height, colour, 0.07 * cleft, np.zeros((n, n)))


def _gravel(n: int, tile: float, rng: np.random.Generator) -> Surface:
    """Roof ballast: rounded stones of about 18 mm, each its own shade, lying in a bed of
    the shadows between them. The stones are the cells of a jittered grid (each pixel
    belongs to the nearest of the points in its own and the eight neighbouring cells,
    counted modulo the grid so that the tile wraps), domed from their centre."""
    x, y = grid(n, tile)
    count = round(tile / 0.018)
    cell = tile / count
    points = rng.uniform(0.15, 0.85, size=(count, count, 2))
    tones = rng.standard_normal((count * count, 2))
    cx, cy = x / cell, y / cell
    ix, iy = np.floor(cx).astype(np.int64), np.floor(cy).astype(np.int64)
    nearest = np.full(x.shape, np.inf)
    second = np.full(x.shape, np.inf)
    ident = np.zeros(x.shape, dtype=np.int64)
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            jx, jy = np.mod(ix + dx, count), np.mod(iy + dy, count)
            px, py = ix + dx + points[jy, jx, 0], iy + dy + points[jy, jx, 1]
            distance = np.hypot(cx - px, cy - py)
            closer = distance < nearest
            second = np.where(closer, nearest, np.minimum(second, distance))
            ident = np.where(closer, jy * count + jx, ident)
            nearest = np.minimum(nearest, distance)
    edge = (second - nearest) * cell / 2  # metres to the stone's border, about
    face = smoothstep(0.0, 0.004, edge)
    dome = np.sqrt(np.clip(1.0 - (nearest / 0.8) ** 2, 0.0, 1.0))
    height = 0.008 * dome * face
    shade = 1.0 + 0.16 * tones[ident, 0] + 0.05 * noise(rng, n, 0.3, tile)
    hue = 0.04 * tones[ident, 1]
    body = np.stack([shade + hue, shade, shade - hue], axis=-1)
    colour = body * (0.6 + 0.4 * face[..., None]) * (0.9 + 0.1 * dome[..., None])
    return Surface(height, colour, 0.06 * tones[ident, 1], np.zeros((n, n)), cavities=height)


def _membrane(n: int, tile: float, rng: np.random.Generator) -> Surface:
    """Roofing membrane (bitumen felt, or a single-ply sheet): rolls a metre wide laid
    along the tile, each lapping the one before it (a step of 2 mm at its edge), a
    roll's end lapping the next across it, faint wrinkles and a fine mineral grain."""
    x, y = grid(n, tile)
    rolls = max(1, round(tile / 1.0))
    width = tile / rolls
    units = coursed(x, y, tile, [(width, [tile], float(rng.uniform(0, tile)))] * rolls)
    lap = smoothstep(0.0, 0.004, units.v * width)  # 0 at the roll's lapped edge
    end = smoothstep(0.0, 0.004, np.minimum(units.u, 1 - units.u) * tile)
    wrinkles = noise(rng, n, 0.15, tile, aniso=(0.3, 1.0))
    grain = noise(rng, n, 0.004, tile)
    height = 0.002 * lap * end + 0.0006 * wrinkles
    shade = 1.0 + 0.04 * noise(rng, n, 0.4, tile) + 0.03 * grain
    shade = shade + per_unit(rng, units.ident, 0.025)
    colour = np.repeat((shade * (0.8 + 0.2 * lap * end))[..., None], 3, axis=-1)
    seams = 0.002 * lap * end  # only the laps occlude, not the wrinkles
    return Surface(height, colour, 0.05 * grain, np.zeros((n, n)), cavities=seams)


def _glass(n: int, tile: float, rng: np.random.Generator) -> Surface:
    wave = noise(rng, n, 0.4, tile)  # float glass is not quite flat: a faint ripple
    colour = np.ones((n, n, 3))
    return Surface(0.00015 * wave, colour, 0.0 * wave, np.zeros((n, n)))


#: rooms a side of the interiors' atlas (:func:`_rooms`): 4 x 4, sixteen rooms
ROOMS_GRID = 4
#: the share of a room's picture (each side) that is the inner reveal around it: a
#: gutter no window's room reads, so that no room bleeds into its neighbour
ROOM_REVEAL = 0.04
#: where a room's back wall lies in its picture, as shares of it (left, right, bottom,
#: top; the same in every room): round it, the left and right walls, the floor and the
#: ceiling, each a band from the picture's edge (at the window) to the back wall
ROOM_BACK = (0.25, 0.75, 0.28, 0.74)
#: metres from a room's floor to its ceiling: the back wall's height in the picture
ROOM_HEIGHT = 2.7
#: metres across the back wall (its picture's pixels are square)
ROOM_WIDTH = ROOM_HEIGHT * (ROOM_BACK[1] - ROOM_BACK[0]) / (ROOM_BACK[3] - ROOM_BACK[2])

# a room's colours (linear light): back wall and side walls, floor, curtains and blinds
_WALLS = (
    *((0.55, 0.50, 0.42), (0.45, 0.45, 0.43), (0.50, 0.44, 0.34), (0.36, 0.40, 0.38)),
    *((0.62, 0.60, 0.56), (0.42, 0.30, 0.26), (0.30, 0.36, 0.44)),
)
_FLOORS = (
    *((0.22, 0.12, 0.06), (0.30, 0.20, 0.11), (0.12, 0.12, 0.12), (0.28, 0.25, 0.21)),
    *((0.40, 0.30, 0.18), (0.18, 0.20, 0.24)),
)
_CLOTHS = ((0.55, 0.52, 0.45), (0.35, 0.10, 0.08), (0.10, 0.16, 0.28), (0.62, 0.58, 0.50))


def _room(m: int, rng: np.random.Generator) -> tuple[np.ndarray, Field]:
    """One room, ``m`` pixels a side (row 0 the top), drawn as a room box's faces lie on
    it (:data:`ROOM_BACK`): the back wall in the middle, the side walls, floor and
    ceiling as bands round it, each from the window (the picture's edge) to the back
    wall, lit near the window and darker deeper in; a piece of furniture against the back
    wall, sometimes a picture on it; sometimes curtains hung at the window (on the side
    walls next to it); in some the lights on (warmer and brighter, a lamp's glow under the
    ceiling); the inner reveal (:data:`ROOM_REVEAL`) round it, in the dim grey a reveal's
    plaster has. With its ambient occlusion: a room sees the sky through its window
    alone, the less the deeper in (0.95 at the window to 0.8 at the back wall)."""
    centres = (np.arange(m) + 0.5) / m
    s, t = np.meshgrid(centres, centres[::-1])  # 0..1 across, 0..1 up
    a0, a1, b0, b1 = ROOM_BACK
    tint = 1 + rng.uniform(-0.08, 0.08, 3)  # no two rooms painted quite alike
    wall = np.asarray(_WALLS[rng.integers(len(_WALLS))]) * rng.uniform(0.8, 1.15) * tint
    floor = np.asarray(_FLOORS[rng.integers(len(_FLOORS))]) * rng.uniform(0.8, 1.2)
    # how far out of the back wall a pixel lies, towards each side: the largest names the
    # surface it shows (left or right wall, floor, ceiling) and its depth (0 back, 1 window)
    beyond = np.stack([(a0 - s) / a0, (s - a1) / (1 - a1), (b0 - t) / b0, (t - b1) / (1 - b1)])
    side, depth = beyond.argmax(axis=0), np.clip(beyond.max(axis=0), 0.0, 1.0)
    back = beyond.max(axis=0) <= 0
    colour = np.empty((m, m, 3))
    colour[...] = wall * (0.55 + 0.25 * depth)[..., None]  # side walls: lit near the window
    ceiling = (side == 3) & ~back
    colour[ceiling] = wall * 1.1 * (0.5 + 0.4 * depth[ceiling])[..., None]
    below = (side == 2) & ~back
    boards = 0.9 + 0.1 * (np.mod(s * 23.0, 1.0) > 0.08)  # floorboards, running in
    colour[below] = floor * ((0.6 + 0.4 * depth) * boards)[below][..., None]
    colour[back] = wall * 0.75
    if rng.uniform() < 0.4:  # a doorway in the back wall, 0.9 x 2.1 m, to a darker room
        door = float(rng.choice([a0 + 0.04, a1 - 0.04 - 0.9 / ROOM_WIDTH * (a1 - a0)]))
        wide, tall = 0.9 / ROOM_WIDTH * (a1 - a0), 2.1 / ROOM_HEIGHT * (b1 - b0)
        colour[(s > door) & (s < door + wide) & (t > b0) & (t < b0 + tall)] = wall * 0.3
    if rng.uniform() < 0.5:  # a rug on the floor
        rug = np.asarray(_CLOTHS[rng.integers(len(_CLOTHS))]) * 0.6
        lies = below & (depth > 0.2) & (depth < 0.75) & (s > a0 + 0.05) & (s < a1 - 0.05)
        colour[lies] = rug
    # furniture against the back wall: a sideboard, a dresser or a bookcase (metres up)
    x0 = float(rng.uniform(a0 + 0.02, (a0 + a1) / 2))
    x1 = min(a1 - 0.02, x0 + float(rng.uniform(0.15, 0.3)))
    high = float(rng.choice([0.9, 1.3, 1.9])) / ROOM_HEIGHT * (b1 - b0)
    piece = (s > x0) & (s < x1) & (t > b0) & (t < b0 + high)
    shade = np.asarray(_CLOTHS[rng.integers(len(_CLOTHS))]) * 0.45
    colour[piece] = shade * (0.8 + 0.2 * (np.mod((t - b0) / 0.06, 1.0) > 0.15))[piece][..., None]
    if rng.uniform() < 0.6:  # a picture on the back wall, at eye height and above
        px = float(rng.uniform(a0 + 0.05, a1 - 0.15))
        frame = (s > px) & (s < px + 0.1) & (t > b1 - 0.2) & (t < b1 - 0.1)
        colour[frame] = np.asarray(_CLOTHS[rng.integers(len(_CLOTHS))]) * 0.8
    lit = rng.uniform() < 0.3
    if lit:  # the lights on: warmer, brighter, a lamp's glow under the ceiling
        glow = np.exp(-(((s - (a0 + a1) / 2) / 0.25) ** 2 + ((t - b1) / 0.2) ** 2))
        colour = colour * np.array([1.35, 1.2, 0.9]) + 0.5 * glow[..., None] * [1.0, 0.8, 0.5]
    if rng.uniform() < 0.45:  # curtains hung at the window, in folds, on the side walls
        cloth = np.asarray(_CLOTHS[rng.integers(len(_CLOTHS))])
        width = float(rng.uniform(0.3, 0.6))  # of the side walls' depth
        hung = ((side <= 1) & ~back & (depth > 1 - width)) & (t > b0) & (t < b1)
        folds = 0.75 + 0.25 * np.sin(2 * np.pi * depth / 0.12) ** 2
        colour[hung] = (cloth * (1.2 if lit else 1.0)) * folds[hung][..., None]
    # a room by day is darker than the street it looks onto (mid-grey seen through the
    # glass), a lit one less so
    colour = colour * (1.0 if lit else 0.75)
    edge = np.minimum.reduce([s, 1 - s, t, 1 - t])
    colour[edge < ROOM_REVEAL] = (0.16, 0.155, 0.145)
    open_sky: Field = np.where(back, 0.8, 0.8 + 0.15 * depth)
    return colour, open_sky


def _rooms(n: int, tile: float, rng: np.random.Generator) -> Surface:
    """The rooms behind a building's windows: an atlas of :data:`ROOMS_GRID` x
    :data:`ROOMS_GRID` rooms (:func:`_room`), each window's room box showing one of them
    (see :func:`facadecli.geometry.facade.room_uv`). Flat: no relief; occluded as a
    room is from the sky."""
    m = n // ROOMS_GRID
    colour = np.zeros((n, n, 3))
    shade = np.ones((n, n))
    for k in range(ROOMS_GRID * ROOMS_GRID):
        row, column = divmod(k, ROOMS_GRID)  # rows from the bottom, as texture v runs
        top = n - (row + 1) * m
        cell = slice(top, top + m), slice(column * m, (column + 1) * m)
        colour[cell], shade[cell] = _room(m, rng)
    flat = np.zeros((n, n))
    return Surface(flat, colour, flat, flat, cavities=flat, occlusion=shade)


#: kind -> generator(resolution, tile metres, rng)
GENERATORS: dict[str, Callable[[int, float, np.random.Generator], Surface]] = {
    "brick-stretcher": _bricks("stretcher"),
    "brick-flemish": _bricks("flemish"),
    "brick-english": _bricks("english"),
    "ashlar": _ashlar,
    "render": _render,
    "concrete": _concrete,
    "timber": _timber,
    "metal": _metal,
    "roof-tiles": _roof_tiles,
    "slate": _slate,
    "glass": _glass,
    "gravel": _gravel,
    "membrane": _membrane,
    "rooms": _rooms,
}
#: the kinds in the order their random streams are numbered: the first eleven in
#: alphabetical order, the later ones as they came, so that a new kind changes no other
#: kind's pictures
STREAMS = (
    *("ashlar", "brick-english", "brick-flemish", "brick-stretcher", "concrete", "glass"),
    *("metal", "render", "roof-tiles", "slate", "timber"),
    *("gravel", "membrane", "rooms"),
)


def normal_map(height: Field, tile: float) -> np.ndarray:
    """The tangent-space normals of a height field (metres over a tile of ``tile``
    metres), with central differences that wrap: +x right, +y up (glTF's convention)."""
    n = height.shape[0]
    step = tile / n
    dx = (np.roll(height, -1, axis=1) - np.roll(height, 1, axis=1)) / (2 * step)
    dy = (np.roll(height, 1, axis=0) - np.roll(height, -1, axis=0)) / (2 * step)  # row 0 top
    normal = np.stack([-dx, -dy, np.ones_like(height)], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    return normal


def occlusion(height: Field, tile: float) -> Field:
    """Ambient occlusion from the cavities of a height field: how far a pixel lies below
    its neighbourhood's mean (a periodic blur of some 2 cm), 1 = open."""
    n = height.shape[0]
    radius = 0.02 / (tile / n)
    depth = np.maximum(0.0, blur(height, radius) - height)
    open_sky: Field = np.clip(1.0 - depth / 0.004, 0.3, 1.0)
    return open_sky


def srgb(linear: np.ndarray) -> np.ndarray:
    linear = np.clip(linear, 0.0, 1.0)
    encoded: np.ndarray = np.where(
        linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055
    )
    return encoded


def to_bytes(values: np.ndarray) -> np.ndarray:
    quantised: np.ndarray = np.round(np.clip(values, 0.0, 1.0) * 255.0).astype(np.uint8)
    return quantised


def texture_set(
    kind: str,
    resolution: int,
    tile: float,
    seed: int,
    colour: tuple[float, float, float],
    roughness: float,
    metallic: float,
) -> TextureSet:
    """The images of a surface kind over one tile: ``colour`` (linear RGB 0..1) is the
    material's main colour (the bricks', the stone's; joints keep their own), and
    ``roughness``/``metallic`` the means its maps vary around."""
    rng = np.random.default_rng([seed, STREAMS.index(kind)])
    surface = GENERATORS[kind](resolution, tile, rng)
    tinted = np.ones(surface.height.shape) if surface.tinted is None else surface.tinted
    main = np.asarray(colour)
    base = surface.colour * (tinted[..., None] * main + (1 - tinted[..., None]))
    rough = np.clip(roughness + surface.roughness, 0.02, 1.0)
    metal = np.clip(metallic * surface.metal, 0.0, 1.0) if metallic > 0 else surface.metal * 0
    cavities = surface.height if surface.cavities is None else surface.cavities
    ambient = occlusion(cavities, tile) if surface.occlusion is None else surface.occlusion
    # occlusion and roughness in steps of 1/32 and 1/64: finer steps cannot be seen, and
    # would double the image's size
    orm = np.stack(
        [np.round(ambient * 32) / 32, np.round(rough * 64) / 64, metal],
        axis=-1,
    )
    normal = normal_map(surface.height, tile) * 0.5 + 0.5
    return TextureSet(to_bytes(srgb(base)), to_bytes(normal), to_bytes(orm))
