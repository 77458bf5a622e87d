"""Parametric primitives (SPEC 2.8), built in a cell's own frame.

Every primitive fills ``0 <= x <= width``, ``0 <= y <= height`` and ``-thickness <= z <= 0``:
its front face is at z = 0, the façade plane at the shape's depth. Positions are placed
and mirrored later (facade.py). Built with numpy only, so every mesh is deterministic.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import trimesh

from facadecli.geometry.cell import DEFAULT_SEGMENTS, Cell, arch_radius

__all__ = ["DEFAULT_SEGMENTS", "PANES", "PRIMITIVES", "Cell", "asset"]


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
        _block(0, w, 0, f, -t, 0),  # sill
        _block(0, w, h - f, h, -t, 0),  # head
        _block(0, f, f, h - f, -t, 0),  # jambs
        _block(w - f, w, f, h - f, -t, 0),
    ]
    return trimesh.util.concatenate(parts)


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
        _block(0, w, 0, f, -t, 0),
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
    """The pane of an arch: a rectangle up to the springing line and a half disc above."""
    w, h, t, f = cell.width, cell.height, cell.thickness, cell.frame
    radius = arch_radius(w, h, f)
    spring = h - radius
    segments = max(3, cell.segments or DEFAULT_SEGMENTS)
    pane_z = -min(cell.pane, t)
    inner = max(radius - f, 1e-3)
    centre = (w / 2, spring)
    parts = [_block(f, w - f, f, spring, pane_z - 0.01, pane_z)]
    for i in range(segments):
        a0, a1 = math.pi * i / segments, math.pi * (i + 1) / segments
        rim = [(centre[0] + inner * math.cos(a), centre[1] + inner * math.sin(a)) for a in (a0, a1)]
        parts.append(_prism([centre, rim[0], rim[1]], pane_z - 0.01, pane_z))
    return trimesh.util.concatenate(parts)


def _prism(outline: list[tuple[float, float]], z0: float, z1: float) -> trimesh.Trimesh:
    """A convex polygon (counter-clockwise or not) extruded from z0 to z1."""
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
    faces = []
    for i in range(1, n - 1):
        faces.append((n, n + i, n + i + 1))  # front (z1), counter-clockwise seen from +z
        faces.append((0, i + 1, i))  # back
    for i in range(n):
        j = (i + 1) % n
        faces.append((i, j, n + j))
        faces.append((i, n + j, n + i))
    return trimesh.Trimesh(vertices, np.array(faces), process=False)


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
    """A profiled horizontal band: three steps, each standing further out than the one below."""
    w, h, t = cell.width, cell.height, cell.thickness
    return trimesh.util.concatenate(
        [
            _block(0, w, 0, 0.3 * h, -t, -0.4 * t),
            _block(0, w, 0.3 * h, 0.6 * h, -t, -0.2 * t),
            _block(0, w, 0.6 * h, h, -t, 0),
        ]
    )


#: the panes of the primitives that have one, in the shape rule's ``pane_material``
PANES: dict[str, Callable[[Cell], trimesh.Trimesh]] = {"frame": frame_pane, "arch": arch_pane}

PRIMITIVES: dict[str, Callable[[Cell], trimesh.Trimesh]] = {
    "box": box,
    "panel": panel,
    "frame": frame,
    "arch": arch,
    "column": column,
    "ledge": ledge,
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
