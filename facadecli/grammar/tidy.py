"""Regularising, the second stage of ``facade grammar`` and ``facade infer``: the layout
read (options checked first), stretched to its size, its edges snapped and its repeated
elements given one size (:mod:`facadecli.grammar.regularize`), with the defaults of its
kind. The work is bounded before it starts: ``CELLS_MAX`` cells of the snapped tiling."""

from __future__ import annotations

from pathlib import Path

from facadecli.errors import SpecError
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.inputs import LabelledLayout
from facadecli.grammar.model import Options, Progress, Tidied, check_options, no_progress
from facadecli.grammar.read import read_layout, resize
from facadecli.grammar.regularize import regularize
from facadecli.grammar.tiling import snap_and_count
from facadecli.limits import LAYOUT_CELLS_MAX

# How much each kind of input is tidied, as fractions of the façade's size: edges closer
# than ``snap`` become one, and repeated elements closer in size than ``tolerance`` get one
# size. CMP annotations are drawn by hand on photographs (a few pixels off); plain lists may
# be measured or detected; facadecli layouts are exact.
TIDY = {"cmp": (0.005, 0.01), "plain": (0.001, 0.005), "report": (0.0, 0.0)}
CELLS_MAX = LAYOUT_CELLS_MAX  # cells of the snapped tiling (a plain list at its snap)


def check_cells(path: Path, layout: LabelledLayout, snap: float) -> None:
    """The tiling of the (snapped) layout has at most ``CELLS_MAX`` cells."""
    columns = len({0.0, layout.width, *(v for r in layout.rects for v in (r.x0, r.x1))}) - 1
    rows = len({0.0, layout.height, *(v for r in layout.rects for v in (r.y0, r.y1))}) - 1
    if columns * rows > CELLS_MAX:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"the tiling would have {columns:,} x {rows:,} cells; at most {CELLS_MAX:,}",
            f"join nearby edges with a larger --snap (now {snap:g}), or give fewer rectangles",
        )


def tidy_layout(
    path: Path, options: Options, deadline: Deadline, progress: Progress = no_progress
) -> Tidied:
    """Read a labelled layout (``options`` checked first), stretch it to ``options.size``,
    snap it and regularise it, with the defaults of its kind (``TIDY``)."""
    check_options(options)
    progress("reading")
    layout, kind = read_layout(path)
    if not layout.rects:
        raise SpecError.at(str(path), None, None, "no rectangles", "label some elements")
    warnings = read_warnings(kind, options)
    if options.size is not None:
        layout = resize(layout, *options.size)
    snap = options.snap if options.snap is not None else TIDY[kind][0]
    tolerance = options.tolerance if options.tolerance is not None else TIDY[kind][1]
    progress(f"snapping {len(layout.rects)} rectangles")
    snapped, snapping = snap_and_count(layout, snap, deadline)
    check_cells(path, snapped, snap)
    progress("regularising")
    regular, regularization = regularize(snapped, tolerance, deadline=deadline, drawn=layout)
    return Tidied(regular, snapping, regularization, snapped, layout, warnings)


def read_warnings(kind: str, options: Options) -> tuple[str, ...]:
    """What a user should know of the input as read: a CMP annotation has no real size
    (the unit square its XML is drawn on), so without ``--size`` the façade is read as
    1 x 1 m, its spec is in those metres, and what the tidy-up keeps or drops at a
    millimetre or a centimetre is a share of it a real façade never has."""
    if kind == "cmp" and options.size is None:
        return (
            "a CMP annotation has no size: read as a 1 x 1 m façade (give its real size, "
            "e.g. --size 15x12, for a spec in metres and the tidy-up's limits to fit it)",
        )
    return ()
