"""Parametric primitives (SPEC 2.8), built in a cell's own frame.

Every primitive fills ``0 <= x <= width``, ``0 <= y <= height`` and ``-thickness <= z <= 0``:
its front face is at z = 0, the façade plane at the shape's depth. Positions are placed
and mirrored later (facade.py). Built with numpy only, so every mesh is deterministic.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import mapbox_earcut
import numpy as np
import trimesh

from facadecli.geometry.cell import (
    CORONA,
    DEFAULT_SEGMENTS,
    BarPlan,
    Cell,
    arch_radius,
    balcony_slab,
    door_plan,
    railing_plan,
    shutter_plan,
)

__all__ = ["DEFAULT_SEGMENTS", "PANES", "PRIMITIVES", "Cell", "asset", "open_box", "recess"]

RECESS_DEPTH = 0.12  # metres from the back of a window's glass to the plate behind it
# metres from the back of a window's glass to the back wall of the room behind it (a
# ``rooms`` interior), where the wall leaves room (:func:`.rooms.room_depth`)
ROOM_DEPTH = 1.2


def _block(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> trimesh.Trimesh:
    """An axis-aligned box between the given bounds."""
    box = trimesh.creation.box(extents=(x1 - x0, y1 - y0, max(z1 - z0, 1e-4)))
    box.apply_translation(((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2))
    return box


def box(cell: Cell) -> trimesh.Trimesh:
    return _block(0, cell.width, 0, cell.height, -cell.thickness, 0)


def panel(cell: Cell) -> trimesh.Trimesh:
    """A thin quad facing the viewer."""
    vertices = np.array(
        [(0, 0, 0), (cell.width, 0, 0), (cell.width, cell.height, 0), (0, cell.height, 0)],
        dtype=float,
    )
    return trimesh.Trimesh(vertices, np.array([(0, 1, 2), (0, 2, 3)]), process=False)


def frame(cell: Cell) -> trimesh.Trimesh:
    """A window or door frame: four bars (its pane is :func:`frame_pane`)."""
    w, h, t, f = cell.width, cell.height, cell.thickness, cell.frame
    parts = [
        _sill(cell),
        _block(0, w, h - f, h, -t, 0),  # head
        _block(0, f, f, h - f, -t, 0),  # jambs
        _block(w - f, w, f, h - f, -t, 0),
    ]
    return trimesh.util.concatenate(parts)


def _sill(cell: Cell) -> trimesh.Trimesh:
    """The bottom bar of a frame or an arch, standing ``sill`` metres proud of its front."""
    return _block(0, cell.width, 0, cell.frame, -cell.thickness, cell.sill or 0.0)


def frame_pane(cell: Cell) -> trimesh.Trimesh:
    """The pane of a frame, 1 cm thick, recessed ``pane_depth`` behind its front."""
    w, h, t, f = cell.width, cell.height, cell.thickness, cell.frame
    pane_z = -min(cell.pane, t)
    return _block(f, w - f, f, h - f, pane_z - 0.01, pane_z)


def arch(cell: Cell) -> trimesh.Trimesh:
    """A frame whose top is a round arch (a semicircle as wide as the cell, when it fits)."""
    w, h, t, f = cell.width, cell.height, cell.thickness, cell.frame
    radius = arch_radius(w, h, f)
    spring = h - radius  # where the arch starts
    segments = max(3, cell.segments or DEFAULT_SEGMENTS)
    parts = [
        _sill(cell),
        _block(0, f, f, spring, -t, 0),
        _block(w - f, w, f, spring, -t, 0),
    ]
    centre = (w / 2, spring)
    inner = max(radius - f, 1e-3)
    ring = []
    for i in range(segments):
        a0 = math.pi * i / segments
        a1 = math.pi * (i + 1) / segments
        outer_points = [
            (centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)) for a in (a0, a1)
        ]
        inner_points = [
            (centre[0] + inner * math.cos(a), centre[1] + inner * math.sin(a)) for a in (a0, a1)
        ]
        ring.append(
            _prism([outer_points[0], outer_points[1], inner_points[1], inner_points[0]], -t, 0)
        )
        ring.append(_spandrel(outer_points, h, t))
    for x0, x1 in ((0.0, centre[0] - radius), (centre[0] + radius, w)):
        if x1 - x0 > 1e-9:  # an arch lower than half its width leaves strips at the sides
            ring.append(_block(x0, x1, spring, h, -t, 0))
    return trimesh.util.concatenate(parts + ring)


def _spandrel(chord: list[tuple[float, float]], top: float, t: float) -> trimesh.Trimesh:
    """The wall between one segment of an arch's outer edge and the top of its cell, so
    the arch fills its cell (no open corners above a round top)."""
    (xa, ya), (xb, yb) = chord
    outline = [(xa, ya), (xb, yb)]
    outline += [
        point
        for point in ((xb, top), (xa, top))
        if abs(point[1] - (yb if point[0] == xb else ya)) > 1e-9
    ]
    return _prism(outline, -t, 0)


def arch_pane(cell: Cell) -> trimesh.Trimesh:
    """The pane of an arch: one flat piece, a rectangle up to the springing line and the
    inside of the curve above it (no seams to show through the glass)."""
    w, h, t, f = cell.width, cell.height, cell.thickness, cell.frame
    radius = arch_radius(w, h, f)
    spring = h - radius
    segments = max(3, cell.segments or DEFAULT_SEGMENTS)
    pane_z = -min(cell.pane, t)
    inner = max(radius - f, 1e-3)
    centre = w / 2
    curve = [
        (
            centre + inner * math.cos(math.pi * i / segments),
            spring + inner * math.sin(math.pi * i / segments),
        )
        for i in range(segments + 1)
    ]
    outline = [(f, f), (w - f, f), (w - f, spring), *curve, (f, spring)]
    unique = [p for i, p in enumerate(outline) if i == 0 or math.dist(p, outline[i - 1]) > 1e-9]
    if math.dist(unique[0], unique[-1]) <= 1e-9:
        unique.pop()
    return _prism(unique, pane_z - 0.01, pane_z)


def _prism(outline: list[tuple[float, float]], z0: float, z1: float) -> trimesh.Trimesh:
    """A simple polygon (convex or not, either winding) extruded from z0 to z1."""
    points = np.array(outline, dtype=float)
    area = 0.5 * np.sum(
        points[:, 0] * np.roll(points[:, 1], -1) - np.roll(points[:, 0], -1) * points[:, 1]
    )
    if area < 0:
        points = points[::-1]
    n = len(points)
    bottom = np.column_stack([points, np.full(n, z0)])
    top = np.column_stack([points, np.full(n, z1)])
    vertices = np.vstack([bottom, top])
    if n == 3 or _convex(points):
        caps = [(0, i, i + 1) for i in range(1, n - 1)]
    else:
        flat = mapbox_earcut.triangulate_float64(points, np.array([n], dtype=np.uint32))
        caps = [(int(flat[i]), int(flat[i + 1]), int(flat[i + 2])) for i in range(0, len(flat), 3)]
    faces = []
    for a, b, c in caps:
        faces.append((n + a, n + b, n + c))  # front (z1), counter-clockwise seen from +z
        faces.append((a, c, b))  # back
    for i in range(n):
        j = (i + 1) % n
        faces.append((i, j, n + j))
        faces.append((i, n + j, n + i))
    return trimesh.Trimesh(vertices, np.array(faces), process=False)


def _convex(points: np.ndarray) -> bool:
    edges = np.roll(points, -1, axis=0) - points
    turns = edges[:, 0] * np.roll(edges[:, 1], -1) - edges[:, 1] * np.roll(edges[:, 0], -1)
    return bool(np.all(turns >= -1e-12))


# a cyclic change of axes (x, y, z) <- (z, x, y): a prism built along z runs along x
_ALONG_X = np.array([(0, 0, 1, 0), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 0, 1)], dtype=float)


def _extrude_x(profile: list[tuple[float, float]], x0: float, x1: float) -> trimesh.Trimesh:
    """A profile given as (y, z) points, extruded along x from x0 to x1."""
    mesh = _prism(profile, x0, x1)
    mesh.apply_transform(_ALONG_X)
    return mesh


def column(cell: Cell) -> trimesh.Trimesh:
    """A round column standing in the cell, as wide as the cell (its depth follows)."""
    radius = cell.width / 2
    cylinder = trimesh.creation.cylinder(
        radius=radius, height=cell.height, sections=max(6, cell.segments or 16)
    )
    cylinder.apply_transform(trimesh.transformations.rotation_matrix(-math.pi / 2, (1, 0, 0)))
    cylinder.apply_translation((radius, cell.height / 2, -radius))
    return cylinder


def ledge(cell: Cell) -> trimesh.Trimesh:
    """A moulded horizontal band, one profile extruded along the cell (runs of ledges along
    a floor are merged into one before they are built, see :mod:`.runs`): a fillet, a cove
    out to a corona, a sloped top that sheds rain; its back fills the cell. Its ends are
    capped: the grooves the profile leaves in its cell (under the cove, over the slope)
    are closed by a thin return at both ends, so at a façade's free end, where the wall
    behind the band is culled, no notch lets the sky through."""
    w = cell.width
    parts = [_extrude_x(ledge_profile(cell), 0.0, w)]
    cap = min(LEDGE_CAP, w / 4)
    for groove in ledge_grooves(cell):
        parts += [_extrude_x(groove, 0.0, cap), _extrude_x(groove, w - cap, w)]
    return trimesh.util.concatenate(parts)


LEDGE_CAP = 0.01  # metres: how thick the returns closing a ledge's grooves at its ends are


def ledge_grooves(cell: Cell) -> list[list[tuple[float, float]]]:
    """What the profile leaves empty of its cell's section, as (y, z) outlines: the cove
    under the corona and the wedge over the sloped top."""
    profile = ledge_profile(cell)
    h = cell.height
    top = [profile[2], profile[3], (h, 0.0)]  # the slope's end, the corona's top, the corner
    bottom = [*profile[4:], (0.0, 0.0)]  # the corona's foot, the cove, the fillet, the corner
    return [top, bottom]


def ledge_profile(cell: Cell) -> list[tuple[float, float]]:
    """The outline of a ledge as (y, z) points, counter-clockwise seen from +x."""
    h, t = cell.height, cell.thickness
    segments = max(2, (cell.segments or DEFAULT_SEGMENTS) // 2)
    low, high = CORONA[0] * h, CORONA[1] * h
    cove = [
        (low - 0.4 * h * math.cos(a), -0.55 * t + 0.5 * t * math.sin(a))
        for a in (0.5 * math.pi * i / segments for i in range(segments + 1))
    ]
    return [
        (0.0, -t),
        (h, -t),
        (h, -0.2 * t),
        (high, 0.0),
        (low, 0.0),
        *cove[::-1][1:],
        (0.0, -0.55 * t),
    ]


def door(cell: Cell) -> trimesh.Trimesh:
    """A door: jambs and head like a frame's (no sill), a leaf recessed ``pane_depth`` with
    ``panels`` rows of raised panels, and the upper ``glazing`` share of it open for glass
    (the glass is :func:`door_pane`)."""
    plan = door_plan(cell)
    t = cell.thickness
    front = -min(cell.pane, t)
    back = max(front - 0.04, -t)
    parts = [_block(*r, -t, 0) for r in plan.frame]
    parts += [_block(*r, back, front) for r in plan.leaf]
    parts += [_block(*r, front, min(front + 0.015, 0.0)) for r in plan.panels]
    return trimesh.util.concatenate(parts)


def door_pane(cell: Cell) -> trimesh.Trimesh | None:
    """The glass of a glazed door, inside its leaf; None for a door with no glazing."""
    glass = door_plan(cell).glass
    if glass is None:
        return None
    front = -min(cell.pane, cell.thickness)
    back = max(front - 0.04, -cell.thickness)
    middle = (front + back) / 2
    return _block(*glass, middle - 0.005, middle + 0.005)


def _bars(plan: BarPlan, z0: float, z1: float, bar_depth: float) -> list[trimesh.Trimesh]:
    """Rails at full depth, bars ``bar_depth`` deep in the middle of it."""
    middle = (z0 + z1) / 2
    parts = [_block(*r, z0, z1) for r in plan.rails]
    parts += [_block(*r, middle - bar_depth / 2, middle + bar_depth / 2) for r in plan.bars]
    return parts


def railing(cell: Cell) -> trimesh.Trimesh:
    """A railing as high as its cell: end posts, handrail, bottom rail and square bars every
    ``spacing`` metres; you see through it."""
    t = max(cell.thickness, 0.01)
    plan = railing_plan(cell.width, cell.height, cell.spacing)
    return trimesh.util.concatenate(_bars(plan, -t, 0, min(0.02, t)))


def balcony(cell: Cell) -> trimesh.Trimesh:
    """A balcony standing ``thickness`` out of the wall: a floor slab at the bottom of the
    cell and a railing along its front and both sides, up to the top of the cell."""
    w, h, t = cell.width, cell.height, max(cell.thickness, 0.01)
    slab = balcony_slab(h)
    depth = min(0.05, t / 4)  # of the railing
    parts = [_block(0, w, 0, slab, -t, 0)]
    front = railing_plan(w, h - slab, cell.spacing)
    for part in _bars(front, -depth, 0, min(0.02, depth)):
        part.apply_translation((0, slab, 0))
        parts.append(part)
    side = railing_plan(t - depth, h - slab, cell.spacing)
    for x in (0.0, w - depth):
        for part in _bars(side, -depth, 0, min(0.02, depth)):  # built along x, turned onto z
            part.apply_transform(_SIDEWAYS)
            part.apply_translation((x, slab, -t))
            parts.append(part)
    return trimesh.util.concatenate(parts)


# a quarter turn about y: what ran along +x runs along +z (and its front faces -x)
_SIDEWAYS = np.array([(0, 0, -1, 0), (0, 1, 0, 0), (1, 0, 0, 0), (0, 0, 0, 1)], dtype=float)


def shutter(cell: Cell) -> trimesh.Trimesh:
    """A louvred shutter filling its cell: stiles and rails as deep as the cell around
    slats ``spacing`` apart in its front 5 cm, each tilted to shed rain, and a board
    behind them, so the shutter is closed from every side."""
    t = max(cell.thickness, 0.01)
    louvre = min(0.05, 0.8 * t)
    plan = shutter_plan(cell)
    parts = [_block(*r, -t, 0) for r in plan.rails]
    x0, x1, y0, y1 = plan.rails[2][0], plan.rails[2][1], plan.rails[2][3], plan.rails[3][2]
    parts.append(_block(x0, x1, y0, y1, max(-t, -louvre - 0.01), -louvre))
    for x0, x1, y0, y1 in plan.bars:
        board = min(0.01, 0.2 * (y1 - y0))
        profile = [
            (y0, -0.1 * louvre),
            (y0 + board, -0.1 * louvre),
            (y1 + board, -0.9 * louvre),
            (y1, -0.9 * louvre),
        ]
        parts.append(_extrude_x(profile, x0, x1))
    return trimesh.util.concatenate(parts)


def recess(glass: trimesh.Trimesh, depth: float = RECESS_DEPTH) -> trimesh.Trimesh:
    """The dark recess behind a window's glass (in the glass's frame), open towards the
    glass: a back plate ``depth`` behind the back of the glass, as large as the glass seen
    head-on, and four reveals from it up to the glass (:func:`open_box`). A ray that
    passes the glass meets the front of one of them, so the street behind a façade never
    shows through its windows."""
    (x0, y0, z0), (x1, y1, _) = glass.bounds
    return open_box((x0, y0, z0 - depth), (x1, y1, z0))


def open_box(low: Sequence[float], high: Sequence[float]) -> trimesh.Trimesh:
    """A box between the corners ``low`` and ``high`` open at its front (towards +z), seen
    from inside: a back plate and four sides, each a quad facing into it (five quads, ten
    triangles, eight corners); nothing faces away from the opening, where no one can see
    it. A dark recess (:func:`recess`) and a room behind a window
    (:func:`.rooms.rooms`: its sides the room's side walls, floor and ceiling)."""
    (x0, y0, back), (x1, y1, z0) = low, high
    corners = np.array(
        [(x, y, z) for z in (back, z0) for y in (y0, y1) for x in (x0, x1)], dtype=float
    )  # 0-3 the back plate's corners, 4-7 the opening's (x fastest, then y)
    quads = [
        (0, 1, 3, 2),  # the back plate, facing the opening (+z)
        (0, 2, 6, 4),  # the left side, facing right (+x)
        (1, 5, 7, 3),  # the right side, facing left (-x)
        (0, 4, 5, 1),  # the bottom, facing up (+y)
        (2, 3, 7, 6),  # the top, facing down (-y)
    ]
    faces = np.array([f for a, b, c, d in quads for f in ((a, b, c), (a, c, d))], dtype=np.int64)
    return trimesh.Trimesh(corners, faces, process=False)


#: meshes that are glass all over when their material is see-through: backed like a pane
GLAZED = frozenset({"box", "panel"})

#: the panes of the primitives that have one, in the shape rule's ``pane_material``
PANES: dict[str, Callable[[Cell], trimesh.Trimesh | None]] = {
    "frame": frame_pane,
    "arch": arch_pane,
    "door": door_pane,
}

PRIMITIVES: dict[str, Callable[[Cell], trimesh.Trimesh]] = {
    "box": box,
    "panel": panel,
    "frame": frame,
    "arch": arch,
    "column": column,
    "ledge": ledge,
    "door": door,
    "railing": railing,
    "balcony": balcony,
    "shutter": shutter,
}


def asset(mesh: trimesh.Trimesh, cell: Cell) -> trimesh.Trimesh:
    """A loaded mesh scaled into the cell (x, y to the cell, z to the thickness)."""
    fitted = mesh.copy()
    low, high = fitted.bounds
    extent = np.where(high - low > 1e-9, high - low, 1.0)
    scale = np.array([cell.width, cell.height, max(cell.thickness, 1e-3)]) / extent
    fitted.apply_translation(-low)
    fitted.apply_scale(1.0)  # keep trimesh's caches coherent before the non-uniform scale
    matrix = np.diag([*scale, 1.0])
    fitted.apply_transform(matrix)
    fitted.apply_translation((0, 0, -cell.thickness))
    return fitted
