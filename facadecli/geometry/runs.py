"""Shapes as they are built: a run of profiles along a floor is one piece.

A ledge in every cell of a string-course row would be a row of boxes with a seam and two
end faces per cell; laid side by side with the same section, they are one profile
extruded along the whole run instead. Used by the meshes and the SVG elevation alike, so
both draw the same pieces. No mesh library needed.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from facadecli.layout import Shape

#: meshes whose cells side by side join into one piece: their section is the same along x
CONTINUOUS = frozenset({"ledge"})
TOUCH = 1e-6  # metres: cells closer than this are side by side


def built(shapes: Iterable[Shape]) -> list[Shape]:
    """The visible shapes in the layout's order, with each run of continuous ones side by
    side in a layer (same rows, depth, material and parameters) joined into one shape that
    spans the run, in the place of the run's first cell."""
    visible = [s for s in shapes if s.visible]
    run_of: dict[int, int] = {}  # index of a continuous shape -> index of its run's first
    ends: dict[tuple[object, ...], tuple[int, float]] = {}  # section -> (first, right end)
    joined: dict[int, Shape] = {}  # a run's first index -> the shape of the whole run
    runs = [i for i, s in enumerate(visible) if s.mesh in CONTINUOUS]
    for i in sorted(runs, key=lambda i: (visible[i].x0, i)):
        shape = visible[i]
        section: tuple[object, ...] = (shape.layer, shape.y0, shape.y1, shape.z0, shape.z1)
        section += (shape.material, shape.mesh, shape.look, shape.reflected_y)
        first, end = ends.get(section, (-1, 0.0))
        if first < 0 or abs(end - shape.x0) >= TOUCH:
            first = i
            joined[i] = replace(shape, reflected_x=False)  # a profile reads the same mirrored
        else:
            joined[first] = replace(joined[first], x1=shape.x1)
        run_of[i] = first
        ends[section] = (first, shape.x1)
    result = []
    for i, shape in enumerate(visible):
        if i not in run_of:
            result.append(shape)
        elif run_of[i] == i:
            result.append(joined[i])
    return result
