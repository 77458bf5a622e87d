"""A town cut into regions, planned one at a time (run.py): what keeps a client's memory
flat whatever the size of the town.

The features' boxes (footprints.py's survey) are cut in two, again and again, across
the longer side of their middles' spread at their median, until a region holds
REGION features at most: squares of about as many buildings each, however dense the
town. A region is planned with every feature around it its buildings depend on
(:func:`around`): what is within ``margin`` of its features' extent, then within
``margin`` of that one's, RINGS times over. Every chain of what a building's task
depends on stays within it: its party walls and their neighbours' heights and roofs
(a neighbour within the tolerance, its outline, the parts standing on it), the nodes
straightening keeps (a neighbour's vertex within the tolerance), the entrances it
shares (the other holders' walls, so their neighbours too): four links at most, each
within ``margin`` of the last, so the buildings of the region are planned as planning
the whole town at once plans them. Pure functions of the boxes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

REGION = 512  # features a region holds at most (the features around it are read too)
RINGS = 6  # times the features around a region are widened by the margin (four needed)


def regions(boxes: Any, size: int = REGION) -> list[Any]:
    """The places of the boxes (numpy (n, 4): x0, y0, x1, y1) cut into regions of at
    most ``size`` each (each ascending), by their middles (see the module)."""
    middles = np.column_stack(((boxes[:, 0] + boxes[:, 2]) / 2, (boxes[:, 1] + boxes[:, 3]) / 2))
    found = []
    todo = [np.arange(len(boxes))]
    while todo:
        places = todo.pop()
        if len(places) <= max(1, size):
            if len(places):
                found.append(np.sort(places))
            continue
        spread = middles[places].max(axis=0) - middles[places].min(axis=0)
        axis = 0 if spread[0] >= spread[1] else 1
        order = places[np.lexsort((places, middles[places, axis]))]  # ties by their place
        half = len(order) // 2
        todo += [order[half:], order[:half]]  # the lower half first
    return found


def around(boxes: Any, core: Any, margin: float, rings: int = RINGS) -> Any:
    """The places (ascending) of the boxes a region's planning reads: those within
    ``margin`` of the extent of the region's ``core`` (its places), then of that set's
    extent, ``rings`` times (see the module). The core is among them."""
    chosen = core
    for _ in range(rings):
        x0, y0 = boxes[chosen, 0].min() - margin, boxes[chosen, 1].min() - margin
        x1, y1 = boxes[chosen, 2].max() + margin, boxes[chosen, 3].max() + margin
        hit = (boxes[:, 0] <= x1) & (boxes[:, 2] >= x0) & (boxes[:, 1] <= y1) & (boxes[:, 3] >= y0)
        chosen = np.flatnonzero(hit)
    return chosen


def extent(boxes: Any, places: Any, margin: float) -> tuple[float, float, float, float]:
    """The box around the boxes at ``places``, widened by ``margin``."""
    return (
        float(boxes[places, 0].min()) - margin,
        float(boxes[places, 1].min()) - margin,
        float(boxes[places, 2].max()) + margin,
        float(boxes[places, 3].max()) + margin,
    )
