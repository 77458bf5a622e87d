"""``facade infer``'s pipeline, without the writing: read a labelled layout, snap and
regularise it (as ``facade grammar`` does), find its grids, write them as a layered spec,
and check the spec: solved at the input's size it must give the input back (the
intersection over union of every label, on a raster), and it must solve at other widths.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facadecli.errors import FacadeError, SpecError
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.inputs import BACKGROUND, LabelledLayout
from facadecli.grammar.run import Options, Progress, no_progress, tidy_layout
from facadecli.grammar.tiling import Tiling, tile
from facadecli.infer.layers import BAND, Grid, grids, to_edges
from facadecli.infer.spec_text import Spread, ident, layer_names, spec_text
from facadecli.layout import Layout
from facadecli.spec.model import Spec

RASTER = 400  # samples along each axis of the IoU raster
WIDTHS = (0.7, 1.5)  # other widths the spec must solve at, as shares of the input's


@dataclass
class Inference:
    source: str
    layout: LabelledLayout  # snapped and regularised
    tiling: Tiling
    grids: list[Grid]
    text: str  # the spec
    checks: dict[str, object] = field(default_factory=dict)

    def report(self) -> dict[str, object]:
        lines = [line for line in self.text.splitlines() if line.strip()[:1] not in ("", "#")]
        return {
            "source": self.source,
            "canvas": {"width": self.layout.width, "height": self.layout.height},
            "rectangles": sum(r.label != BACKGROUND for r in self.layout.rects),
            "layers": len(self.grids) + 1,
            "spec_lines": len(lines),
            **self.checks,
        }


def infer(
    path: Path, name: str, options: Options | None = None, progress: Progress = no_progress
) -> Inference:
    """The spec of a labelled layout (``options``: its size, snap and tolerance);
    ``progress`` is told each stage as it starts."""
    options = options or Options()
    tidied = tidy_layout(path, options, Deadline(options.time_limit, str(path)), progress)
    regular = tidied.layout
    if not any(r.label != BACKGROUND for r in regular.rects):
        raise SpecError.at(str(path), None, None, "no elements", "label some elements")
    progress("finding the grids of each label")
    found = [to_edges(grid, regular.width, regular.height) for grid in grids(regular)]
    spread = size_spread(regular, tidied.snapped)
    text = spec_text(ident(name), regular.width, regular.height, found, path.name, spread)
    return Inference(path.name, regular, tile(regular, tolerance=0.0), found, text)


def size_spread(regular: LabelledLayout, snapped: LabelledLayout) -> Spread:
    """For each label's regularised element size along each axis, the least and greatest
    size the elements made that size had before regularising (hand annotation's jitter:
    the range a derived façade may size them in). Only for elements, not for bands across
    a good share of the façade (``BAND``): those grow and shrink with it."""
    spread: dict[tuple[str, str, float], tuple[float, float]] = {}
    for tidy, raw in zip(regular.rects, snapped.rects, strict=True):
        if tidy.label == BACKGROUND:
            continue
        for axis, size, before, extent in (
            ("x", tidy.x1 - tidy.x0, raw.x1 - raw.x0, regular.width),
            ("y", tidy.y1 - tidy.y0, raw.y1 - raw.y0, regular.height),
        ):
            if size > BAND * extent:
                continue  # a band across the façade is as wide as the façade makes it
            key = (axis, tidy.label, round(size, 6))
            low, high = spread.get(key, (size, size))
            spread[key] = (min(low, before), max(high, before))
    return spread


def check(inference: Inference, spec: Spec, progress: Progress = no_progress) -> dict[str, object]:
    """Solve the spec at the input's size and at other widths (see the module)."""
    from facadecli.solve import retarget, solve

    progress("checking: solving the spec at the input's size")
    checks: dict[str, object] = {}
    try:
        layout = solve(spec)
    except FacadeError as error:
        checks["solves"] = False
        checks["error"] = str(error)
        return checks
    labels = sorted({r.label for r in inference.layout.rects} | {BACKGROUND})
    drawn = _raster_of_layout(layout, spec, inference, labels)
    given = _raster_of_tiling(inference.tiling, labels)
    iou = {}
    for k, label in enumerate(labels):
        union = np.count_nonzero((drawn == k) | (given == k))
        if union:
            iou[label] = round(float(np.count_nonzero((drawn == k) & (given == k)) / union), 4)
    checks["solves"] = True
    checks["iou"] = iou
    checks["iou_min"] = min(iou.values())
    retargets = []
    for share in WIDTHS:
        width = round(inference.layout.width * share, 4)
        entry: dict[str, object] = {"width": width, "height": inference.layout.height}
        progress(f"checking: solving it {width:g} m wide")
        try:
            solve(retarget(spec, width, inference.layout.height))
            entry["solves"] = True
        except FacadeError as error:
            entry["solves"] = False
            entry["error"] = str(error)
        retargets.append(entry)
    checks["retargets"] = retargets
    return checks


def _samples(extent: float) -> np.ndarray:
    return (np.arange(RASTER) + 0.5) * extent / RASTER


def _raster_of_tiling(tiling: Tiling, labels: list[str]) -> np.ndarray:
    """The label of the tiling at every sample (rows bottom up)."""
    xs, ys = _samples(tiling.xs[-1]), _samples(tiling.ys[-1])
    columns = np.clip(np.searchsorted(tiling.xs, xs, side="right") - 1, 0, len(tiling.xs) - 2)
    rows = np.clip(np.searchsorted(tiling.ys, ys, side="right") - 1, 0, len(tiling.ys) - 2)
    index = {label: k for k, label in enumerate(labels)}
    cells = np.array([[index[label] for label in row] for row in tiling.labels])
    return cells[np.ix_(rows, columns)]


def _raster_of_layout(
    layout: Layout, spec: Spec, inference: Inference, labels: list[str]
) -> np.ndarray:
    """The label of the solved layout's front-most element at every sample: a layer is its
    grid's label; its spacers, and the wall, are the background."""
    index = {label: k for k, label in enumerate(labels)}
    xs, ys = _samples(inference.layout.width), _samples(inference.layout.height)
    raster = np.full((RASTER, RASTER), index[BACKGROUND])
    names = ["wall", *layer_names(inference.grids)]
    label_of = {"wall": BACKGROUND} | {
        n: g.label for n, g in zip(names[1:], inference.grids, strict=True)
    }
    order = {n: k for k, n in enumerate(names)}
    shapes = sorted(layout.shapes, key=lambda s: order.get(s.layer, 0))
    for shape in shapes:
        if spec.qualifiers(shape.x).transparent or spec.qualifiers(shape.y).transparent:
            continue
        columns = (xs >= shape.x0) & (xs < shape.x1)
        rows = (ys >= shape.y0) & (ys < shape.y1)
        raster[np.ix_(rows, columns)] = index[label_of.get(shape.layer, BACKGROUND)]
    return raster
