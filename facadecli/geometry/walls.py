"""The walls of a layer as one mesh per material and depth: no seams between cells.

Wall cells side by side were boxes of their own, each placed by its node: the front faces
of two neighbours met along an edge whose two copies differed in the last digits (a cell's
width is rounded, its position is not), and their side faces stood back to back between
them. A renderer showed a faint line along every such edge. Here the boxes of one layer,
material and depth are one surface instead: every corner is one vertex shared by the cells
that meet there, and the faces between two cells of the group are left out.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import trimesh

DIGITS = 6  # coordinates are rounded to a micrometre: the cells' own rounding (Cell.of)

Rect = tuple[float, float, float, float]  # x0, x1, y0, y1 in the layer's frame


def wall_mesh(cells: Sequence[Rect], z0: float, z1: float) -> trimesh.Trimesh:
    """The union of boxes from ``z0`` to ``z1`` over the cells (rectangles of a layer's grid,
    which meet edge to edge): their fronts and backs, and the sides where no other cell of
    the group meets them along the whole edge. Outward-facing, every vertex shared."""
    rects = [tuple(round(v, DIGITS) for v in cell) for cell in cells]
    z0, z1 = round(z0, DIGITS), round(z1, DIGITS)
    lefts = {(x0, y0, y1) for x0, _, y0, y1 in rects}
    rights = {(x1, y0, y1) for _, x1, y0, y1 in rects}
    bottoms = {(y0, x0, x1) for x0, x1, y0, _ in rects}
    tops = {(y1, x0, x1) for x0, x1, _, y1 in rects}
    index: dict[tuple[float, float, float], int] = {}
    faces: list[tuple[int, int, int]] = []

    def at(x: float, y: float, z: float) -> int:
        return index.setdefault((x, y, z), len(index))

    def quad(corners: list[tuple[float, float, float]]) -> None:
        """Two triangles over four corners given counter-clockwise seen from outside."""
        a, b, c, d = (at(*corner) for corner in corners)
        faces.extend([(a, b, c), (a, c, d)])

    for x0, x1, y0, y1 in rects:
        quad([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)])  # front, +z
        quad([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)])  # back, -z
        if (x0, y0, y1) not in rights:  # no cell of the group on its left
            quad([(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)])  # -x
        if (x1, y0, y1) not in lefts:
            quad([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)])  # +x
        if (y0, x0, x1) not in tops:  # nothing of the group below it
            quad([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)])  # -y
        if (y1, x0, x1) not in bottoms:
            quad([(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)])  # +y
    vertices = np.array(list(index), dtype=float).reshape(-1, 3)
    return trimesh.Trimesh(vertices, np.array(faces).reshape(-1, 3), process=False)
