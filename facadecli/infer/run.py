"""``facade infer``'s pipeline, without the writing: read a labelled layout, snap and
regularise it (as ``facade grammar`` does), put it on one structure (``structure``: sizes,
columns, rows and pitches shared), find its grids, write them as a layered spec,
and check the spec: solved at the input's size it is compared with the raw annotation
(``grammar.fidelity``: IoU per label, elements lost or fused) and with the tidied layout it
was written from (``iou``), and it must solve at other widths.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from facadecli.errors import FacadeError, SpecError
from facadecli.grammar.deadline import Deadline
from facadecli.grammar.fidelity import Fidelity, fidelity
from facadecli.grammar.inputs import BACKGROUND, LabelledLayout, Rect
from facadecli.grammar.model import Options, Progress, Tidied, no_progress
from facadecli.grammar.tidy import tidy_layout
from facadecli.grammar.tiling import Tiling, tile
from facadecli.infer.bays import FEW_BAYS, Bays, find_bays, in_bays, inside, kept
from facadecli.infer.floors import ALIKE, by_floors
from facadecli.infer.layers import BAND, Grid, grids, to_edges
from facadecli.infer.spec_text import Spread, floor_run, ident, layer_names, spec_text
from facadecli.infer.structure import structured
from facadecli.layout import Layout
from facadecli.spec.model import Spec

WIDTHS = (0.7, 1.5)  # other widths the spec must solve at, as shares of the input's
RECUT_KEEP = 0.001  # of the mean IoU against the annotation at 1x: the most the grids'
# re-cut by floor may lose (a layer on the floors writes every floor as its last, so a
# floor drawn off it moves; a counter's tie may solve otherwise), else they stay as cut


@dataclass
class Inference:
    source: str
    layout: LabelledLayout  # snapped, regularised and structured (``infer.structure``)
    tiling: Tiling
    grids: list[Grid]
    text: str  # the spec
    checks: dict[str, object] = field(default_factory=dict)
    raw: LabelledLayout | None = None  # as read (stretched to the size); None: ``layout``
    fidelity: Fidelity | None = None  # the spec solved at the input's size vs ``raw``
    bays: str = ""  # how the x words follow the bays (``infer.bays``), or why they do not
    unshared: bool = False  # the bays are not shared: each layer has its own x word
    warnings: tuple[str, ...] = ()  # about the input as read (``grammar.tidy.read_warnings``)

    def report(self) -> dict[str, object]:
        lines = [line for line in self.text.splitlines() if line.strip()[:1] not in ("", "#")]
        return {
            "source": self.source,
            "canvas": {"width": self.layout.width, "height": self.layout.height},
            "rectangles": sum(r.label != BACKGROUND for r in self.layout.rects),
            "layers": len(self.grids) + 1,
            "spec_lines": len(lines),
            "bays": self.bays,
            "warnings": list(self.warnings),
            **self.checks,
        }


def infer(
    path: Path, name: str, options: Options | None = None, progress: Progress = no_progress
) -> Inference:
    """The spec of a labelled layout (``options``: its size, snap and tolerance);
    ``progress`` is told each stage as it starts."""
    options = options or Options()
    tidied = tidy_layout(path, options, Deadline(options.time_limit, str(path)), progress)
    regular = structured(tidied.layout, tidied.raw)
    if not any(r.label != BACKGROUND for r in regular.rects):
        raise SpecError.at(str(path), None, None, "no elements", "label some elements")
    progress("finding the bays and the grids of each label")
    bays = find_bays(regular, tidied.raw)
    cut = _layered(regular, bays, by_floor=True)
    before = _layered(regular, bays, by_floor=False)
    chosen, was = _inference(path, name, tidied, *cut), _inference(path, name, tidied, *before)
    if chosen.text != was.text:  # the re-cut by floor is kept only as faithful at 1x
        progress("checking the grids cut by floor against the annotation")
        now_fidelity, was_fidelity = at_input_size(chosen), at_input_size(was)
        if was_fidelity is not None and (
            now_fidelity is None or not kept(was_fidelity, now_fidelity, RECUT_KEEP)
        ):
            chosen = was
    return chosen


def _layered(
    regular: LabelledLayout, bays: Bays | str, by_floor: bool
) -> tuple[LabelledLayout, list[Grid], Bays | str, float]:
    """The layout the spec is written from, its grids and its bays (or why they are not
    shared): the bays' layout and grids where every layer standing in the bays shows alike
    in the bays of a kind, else the structure's; ``by_floor``: the grids re-cut by floor
    (``_cut``), or, where that leaves a layer unlike in the bays, as cut before; and how
    far a layer's floors may be off its last to follow the openings' (``floors.Floors``:
    ``ALIKE`` by floor, else to ``floors.EPS``)."""
    alike = ALIKE if by_floor else 0.0
    if isinstance(bays, Bays):
        found = _cut(bays.layout, bays.apart, by_floor)
        if by_floor and _unlike(bays, found):
            found = _cut(bays.layout, bays.apart)
        if not _unlike(bays, found):
            return bays.layout, found, bays, alike
        bays = "a label's elements stand unlike in the bays of a kind"
    return regular, _cut(regular, frozenset(), by_floor), bays, alike


def _inference(
    path: Path,
    name: str,
    tidied: Tidied,
    regular: LabelledLayout,
    found: list[Grid],
    bays: Bays | str,
    alike: float,
) -> Inference:
    """The spec written from ``regular``'s grids ``found`` (``bays``: see ``_layered``)."""
    spread = size_spread(regular, tidied.snapped)
    text = spec_text(
        ident(name), regular.width, regular.height, found, path.name, spread, bays, alike
    )
    tiling = tile(regular, tolerance=0.0)
    note = bays.describe() if isinstance(bays, Bays) else f"not shared: {bays}"
    unshared = isinstance(bays, str) and bays != FEW_BAYS
    return Inference(
        path.name,
        regular,
        tiling,
        found,
        text,
        raw=tidied.raw,
        bays=note,
        unshared=unshared,
        warnings=tidied.warnings,
    )


def at_input_size(inference: Inference) -> Fidelity | None:
    """The spec solved at the input's size against the annotation (``grammar.fidelity``),
    or None where it does not solve there."""
    from facadecli.solve import solve
    from facadecli.spec import parse_spec

    spec = parse_spec(inference.text, inference.source)
    try:
        layout = solve(spec)
    except FacadeError:
        return None
    return fidelity(inference.raw or inference.layout, solved_layout(layout, spec, inference))


def _cut(layout: LabelledLayout, apart: frozenset[int], by_floor: bool = False) -> list[Grid]:
    """The layout's grids (``layers.grids``; ``apart``: the rectangles off the bays), with
    bands reaching the façade's edges; ``by_floor``: each label's re-cut by the openings'
    floors where they have a run (``floors.by_floors``), so that what stands alike on every
    floor is one layer that follows them. Where that leaves a layer unlike in the bays of
    a kind (its columns a subset of a kind's bays), the bays take the grids as cut."""
    found = grids(layout, apart=apart)
    run = floor_run(found, layout.height) if by_floor else None
    if run is not None:
        found = by_floors(found, run[1])
    return [to_edges(grid, layout.width, layout.height) for grid in found]


def _unlike(bays: Bays, found: list[Grid]) -> bool:
    """Whether a layer standing in the bays shows unlike in the bays of a kind."""
    return any(inside(bays, g) and not g.apart and not in_bays(bays, g) for g in found)


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
    solved = solved_layout(layout, spec, inference)
    progress("checking: comparing it with the annotation")
    faithful = fidelity(inference.raw or inference.layout, solved)
    inference.fidelity = faithful
    iou = fidelity(inference.layout, solved).iou_per_label()
    checks["solves"] = True
    checks["fidelity"] = faithful.summary()
    checks["iou"] = iou  # against the tidied layout: what the spec writer was given
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


def solved_layout(layout: Layout, spec: Spec, inference: Inference) -> LabelledLayout:
    """The solved spec as a labelled layout: each shape a rectangle with its layer's label
    (a layer is one grid of a label; the wall is the background), layers back to front;
    see-through shapes (transparent symbols) are left out."""
    names = ["wall", *layer_names(inference.grids)]
    label_of = {"wall": BACKGROUND} | {
        n: g.label for n, g in zip(names[1:], inference.grids, strict=True)
    }
    order = {n: k for k, n in enumerate(names)}
    rects = [
        Rect(label_of.get(s.layer, BACKGROUND), s.x0, s.y0, s.x1, s.y1, order.get(s.layer, 0))
        for s in layout.shapes
        if not (spec.qualifiers(s.x).transparent or spec.qualifiers(s.y).transparent)
    ]
    return LabelledLayout(inference.layout.width, inference.layout.height, tuple(rects))
