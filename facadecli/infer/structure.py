"""One structure per façade: the tidied layout's elements put on shared columns and rows
before ``facade infer`` writes them as layers (issue 34).

The tidy-up keeps what was drawn, within a hand's jitter; a spec needs what the façade
means: windows of one size, in columns and floors at one pitch, with their sills under
them. Each axis on its own, for every element that is not a band across the façade
(``layers.BAND``):

1. **Sizes**: a label's sizes each within ``SIZE`` of the next smaller, or within
   ``JITTER`` of the façade (and a quarter of the size), are one, up to twice that from
   the smallest and spanning no more than the regulariser's ``RELATIVE`` of it (or
   ``JITTER``; a wider cluster is cut at its widest step, ``_split``): the cluster's
   median, one symbol in the spec.
2. **Columns** (rows along y): a label's element centres within ``NEAR`` of the façade
   (and half the elements' size, so only elements that already overlap along the axis
   merge) are one line, their mean.
3. **Pitch**: consecutive lines of a label whose spacings are within ``PITCH`` of the
   first of a run are spaced evenly between the run's ends (which stay): the run becomes
   a repeat with one counter.
4. **Mirror**: a label's lines that, reflected about the façade's middle, each fall
   within ``NEAR`` of another are made exactly symmetric, so the spec's words read the
   same backwards and are written mirrored.
5. **Shared structure**: the label with the most elements (windows on a tie) sets the
   structure; another
   label's line within ``NEAR`` of a structure line is put on it (a sill under its
   window, a balcony, a blind over it), so their layers align at any size.

An element whose edge would move further than ``SHARE`` of the narrowest element,
same-label gap or visible part it bounds (``tiling.move_limits``, as the tidy-up's)
stays as drawn along that axis, and so do an element hidden behind others and those
hiding it, and one that would overlap or touch another of its label; nothing is dropped,
and no two elements of a label are put on one line unless they overlapped along the axis
by half their size.
"""

from __future__ import annotations

import statistics
from collections import defaultdict
from collections.abc import Callable

from facadecli.grammar.fidelity import FAITHFUL, Fidelity, fidelity
from facadecli.grammar.inputs import BACKGROUND, CMP_Z_ORDER, LabelledLayout, Rect
from facadecli.grammar.regularize import RELATIVE
from facadecli.grammar.tiling import MOVE_SHARE, move_limits
from facadecli.infer.companions import REACHES, companions_placed
from facadecli.infer.layers import BAND, OPENINGS

SIZE = 0.03  # sizes of a label within this share of one another are one
JITTER = 0.005  # of the façade: or within this (a hand's error, for small elements)
NEAR = 0.01  # of the façade: centres this close are one column (row)
PITCH = 0.03  # spacings within this share of one another are one pitch
SHARE = MOVE_SHARE  # of the narrowest element, gap or visible part an edge bounds
SAMPLES = 4  # points along each side at which an element is looked at for being hidden
DIGITS = 9  # of a metre: lines and sizes equal to that are equal (one gap symbol)
ROW = 0.5  # elements side by side overlapping by this share of the smaller: one row
ROW_MOVE = 0.1  # of its size: the most an edge of an element moves onto its row
STRUCTURE = "window"  # of labels with as many elements, the one that sets the structure
SOLVED = 0.005  # of the mean IoU: what the bays' shapes and the solve may lose past the structure


def structured(layout: LabelledLayout, drawn: LabelledLayout | None = None) -> LabelledLayout:
    """The layout with its elements on shared sizes, lines and pitches (see the module),
    then its companions placed from their openings (``companions``), at the widest
    reach (``companions.REACHES``) that keeps the layout faithful to ``drawn`` (the
    annotation, when given: ``_keeps``); the rectangles in the same order."""
    rects = list(layout.rects)
    x = _axis([(r.label, r.x0, r.x1) for r in rects], layout.width)
    y = _axis([(r.label, r.y0, r.y1) for r in rects], layout.height)
    x = _within_limits(rects, x, "x", layout.width)
    y = _within_limits(rects, y, "y", layout.height)
    placed = [
        Rect(r.label, x0, y0, x1, y1, r.z)
        for r, (x0, x1), (y0, y1) in zip(rects, x, y, strict=True)
    ]
    hiding = _hiding(rects)
    for k in _colliding(rects, placed) | hiding:
        placed[k] = rects[k]
    behind = hiding | _behind(rects)
    lined = _sizes_shared(placed, behind, "y", layout.height)
    lined = _sizes_shared(lined, behind, "x", layout.width)
    lined = _rows_shared(lined, behind, "y", layout.height)
    lined = _settled(placed, _rows_shared(lined, behind, "x", layout.width))
    before = None if drawn is None else fidelity(drawn, _with(layout, lined))
    for share in REACHES:
        out = _with(
            layout, _settled(placed, companions_placed(lined, layout.width, layout.height, share))
        )
        if drawn is None or before is None or _keeps(fidelity(drawn, out), before):
            break
    return out


def _with(layout: LabelledLayout, rects: list[Rect]) -> LabelledLayout:
    return LabelledLayout(layout.width, layout.height, tuple(rects))


def _keeps(placed: Fidelity, before: Fidelity) -> bool:
    """Whether companions placed from their openings keep the layout faithful: its mean
    IoU at ``FAITHFUL`` with ``SOLVED`` to spare, and no element lost or fused that the
    layout before them kept (a companion moved over another element hides it)."""
    return (
        placed.iou_mean >= FAITHFUL + SOLVED
        and placed.lost <= before.lost
        and placed.fused <= before.fused
    )


def _settled(placed: list[Rect], lined: list[Rect]) -> list[Rect]:
    """``lined`` with each element that now overlaps, touches or nearly meets one of its
    label (``_colliding``, ``_closing``) as ``placed`` had it; which may close another
    gap: again, until none does."""
    lined = list(lined)
    moved = {k for k, (a, b) in enumerate(zip(placed, lined, strict=True)) if a != b}
    while back := (_colliding(placed, lined) | _closing(placed, lined)) & moved:
        for k in back:
            lined[k] = placed[k]
        moved -= back
    return lined


def _sizes_shared(rects: list[Rect], keep: set[int], axis: str, extent: float) -> list[Rect]:
    """A label's sizes along ``axis`` that the move limits left apart (a sill under one
    window, a blind beside another), each within ``2 * SIZE`` of the smallest of its
    cluster, given the cluster's median about each element's centre, where no edge moves
    more than ``ROW_MOVE`` of the element (and ``NEAR`` of the façade): the floors of a
    façade one height, so that its spec repeats them with a counter. Elements in ``keep``
    stay as they are."""
    near = NEAR * extent

    def span(r: Rect) -> tuple[float, float]:
        return (r.y0, r.y1) if axis == "y" else (r.x0, r.x1)

    size = {k: span(r)[1] - span(r)[0] for k, r in enumerate(rects)}
    by_label: dict[str, list[int]] = defaultdict(list)
    for k, r in enumerate(rects):
        if r.label != BACKGROUND and k not in keep and 0 < size[k] <= BAND * extent:
            by_label[r.label].append(k)
    out = list(rects)
    for members in by_label.values():
        ordered = sorted(members, key=size.__getitem__)
        for cluster in _chains(ordered, size, lambda first, b: b - first <= 2 * SIZE * first):
            median = statistics.median(size[k] for k in cluster)
            if any(abs(size[k] - median) / 2 > min(near, ROW_MOVE * size[k]) for k in cluster):
                continue
            for k in cluster:
                r = rects[k]
                a, b = span(r)
                low = round((a + b - median) / 2, DIGITS)
                high = round(low + median, DIGITS)
                out[k] = (
                    Rect(r.label, r.x0, low, r.x1, high, r.z)
                    if axis == "y"
                    else Rect(r.label, low, r.y0, high, r.y1, r.z)
                )
    return out


def _rows_shared(rects: list[Rect], keep: set[int], axis: str, extent: float) -> list[Rect]:
    """The elements of a label that stand in one row (one floor; along x, one column):
    side by side, each overlapping the row's first along ``axis`` by ``ROW`` of the
    smaller, given the row's median span where no edge moves more than ``NEAR`` of the
    façade (a hand's error, the tidy-up's tolerance). A move limit (``tiling.move_limits``)
    can leave a floor's windows a few centimetres apart where a sill or a blind meets
    them; a spec writes each such row as a layer of its own, and solved wider, layers
    apart gain bays apart, over one another. Elements in ``keep`` (hidden, or hiding
    others) stay as they are."""
    near = NEAR * extent

    def span(r: Rect) -> tuple[float, float]:
        return (r.y0, r.y1) if axis == "y" else (r.x0, r.x1)

    def across(r: Rect) -> tuple[float, float]:
        return (r.x0, r.x1) if axis == "y" else (r.y0, r.y1)

    by_label: dict[str, list[int]] = defaultdict(list)
    for k, r in enumerate(rects):
        a, b = span(r)
        if r.label != BACKGROUND and k not in keep and 0 < b - a <= BAND * extent:
            by_label[r.label].append(k)
    out = list(rects)
    for members in by_label.values():
        rows: list[list[int]] = []
        for k in sorted(members, key=lambda k: span(rects[k])):
            a, b = span(rects[k])
            for row in rows:
                c, d = span(rects[row[0]])
                apart = all(
                    min(across(rects[k])[1], across(rects[j])[1])
                    <= max(across(rects[k])[0], across(rects[j])[0])
                    for j in row
                )
                if apart and min(b, d) - max(a, c) >= ROW * min(b - a, d - c):
                    row.append(k)
                    break
            else:
                rows.append([k])
        for row in rows:
            if len(row) < 2:
                continue
            low = statistics.median(span(rects[k])[0] for k in row)
            high = statistics.median(span(rects[k])[1] for k in row)
            if any(
                max(abs(span(rects[k])[0] - low), abs(span(rects[k])[1] - high))
                > min(near, ROW_MOVE * (span(rects[k])[1] - span(rects[k])[0]))
                for k in row
            ):
                continue
            for k in row:
                r = rects[k]
                out[k] = (
                    Rect(r.label, r.x0, low, r.x1, high, r.z)
                    if axis == "y"
                    else Rect(r.label, low, r.y0, high, r.y1, r.z)
                )
        # the rows at one pitch (``_even``), where no element moves too far
        rows.sort(key=lambda row: sum(span(out[row[0]])))
        centres = [sum(span(out[row[0]])) / 2 for row in rows]
        for row, was, now in zip(rows, centres, _even(centres), strict=True):
            if any(
                abs(now - was) > min(near, ROW_MOVE * (span(out[k])[1] - span(out[k])[0]))
                for k in row
            ):
                continue
            for k in row:
                r = out[k]
                a, b = span(r)
                low, high = round(a + now - was, DIGITS), round(b + now - was, DIGITS)
                out[k] = (
                    Rect(r.label, r.x0, low, r.x1, high, r.z)
                    if axis == "y"
                    else Rect(r.label, low, r.y0, high, r.y1, r.z)
                )
    return out


def _within_limits(
    rects: list[Rect], moved: list[tuple[float, float]], axis: str, extent: float
) -> list[tuple[float, float]]:
    """The moved spans, each kept as it was where an edge of it moved further than the
    structure lets an edge move (``tiling.move_limits`` with ``NEAR`` and ``SHARE``: an
    eighth of the narrowest element, same-label gap or visible part it bounds, as in the
    tidy-up): what was drawn shows."""
    spans = [(r.x0, r.x1) if axis == "x" else (r.y0, r.y1) for r in rects]
    return [
        span if far else to
        for span, to, far in zip(
            spans, moved, beyond_limits(rects, moved, axis, extent), strict=True
        )
    ]


def beyond_limits(
    rects: list[Rect],
    moved: list[tuple[float, float]],
    axis: str,
    extent: float,
    share: float = SHARE,
) -> list[bool]:
    """For each of ``rects`` (as drawn), whether an edge of its span along ``axis``
    ``moved`` further than the structure lets an edge move (see ``_within_limits``;
    ``share`` of the narrowest span it bounds)."""
    spans = [(r.x0, r.x1) if axis == "x" else (r.y0, r.y1) for r in rects]
    across = [(r.y0, r.y1) if axis == "x" else (r.x0, r.x1) for r in rects]
    tolerance = NEAR * extent * share / SHARE
    limits = move_limits(rects, spans, across, tolerance, share)
    return [
        abs(c - a) > limits.get(a, tolerance) or abs(d - b) > limits.get(b, tolerance)
        for (a, b), (c, d) in zip(spans, moved, strict=True)
    ]


def _colliding(before: list[Rect], after: list[Rect]) -> set[int]:
    """The elements that overlap or touch one of their label (an opening: any opening)
    after structuring but did not before (grown a few per cent into a neighbour): they
    stay as drawn, never fused."""
    by_label: dict[str, list[int]] = defaultdict(list)
    for k, rect in enumerate(after):
        if rect.label != BACKGROUND:  # openings together: a window never moves onto a door
            by_label["" if rect.label in OPENINGS else rect.label].append(k)
    found: set[int] = set()
    for members in by_label.values():
        for n, a in enumerate(members):
            for b in members[n + 1 :]:
                if _meet(after[a], after[b]) and not _meet(before[a], before[b]):
                    found |= {a, b}
    return found


def _closing(before: list[Rect], after: list[Rect]) -> set[int]:
    """The elements whose gap to one of their label (an opening: to any opening) facing
    them, overlapping along the other axis, is closed by more than ``SHARE`` of it: the
    wall between two windows never narrows to a sliver (they would read as one)."""
    by_label: dict[str, list[int]] = defaultdict(list)
    for k, rect in enumerate(before):
        if rect.label != BACKGROUND:
            by_label["" if rect.label in OPENINGS else rect.label].append(k)
    found: set[int] = set()
    for members in by_label.values():
        for n, i in enumerate(members):
            for j in members[n + 1 :]:
                for axis in ("x", "y"):
                    was, now = _gap(before[i], before[j], axis), _gap(after[i], after[j], axis)
                    if was > 0 and now < (1 - SHARE) * was:
                        found |= {i, j}
    return found


def _gap(a: Rect, b: Rect, axis: str) -> float:
    """The gap between two elements along ``axis`` where they overlap along the other
    (0 where they do not face each other, or touch or overlap)."""
    if axis == "x":
        facing = min(a.y1, b.y1) - max(a.y0, b.y0) > 1e-9
        gap = max(a.x0, b.x0) - min(a.x1, b.x1)
    else:
        facing = min(a.x1, b.x1) - max(a.x0, b.x0) > 1e-9
        gap = max(a.y0, b.y0) - min(a.y1, b.y1)
    return gap if facing and gap > 0 else 0.0


def _behind(rects: list[Rect]) -> set[int]:
    """The elements partly behind one in front of them (CMP's order, then ``z``): what
    shows of them is what the annotation shows, so the steps that go further than the
    move limits (``_sizes_shared``, ``_rows_shared``) leave them be."""
    order = {k: (CMP_Z_ORDER.get(r.label, 99), r.z, k) for k, r in enumerate(rects)}
    found: set[int] = set()
    shown = [k for k, r in enumerate(rects) if r.label != BACKGROUND]
    for n, i in enumerate(shown):
        for j in shown[n + 1 :]:
            a, b = rects[i], rects[j]
            if a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1:
                found.add(min(i, j, key=order.__getitem__))
    return found


def _hiding(before: list[Rect]) -> set[int]:
    """The elements hidden behind those in front of them (CMP's order, then ``z``, as
    ``layers`` stacks them; looked at in ``SAMPLES`` x ``SAMPLES`` points), and those
    hiding them: moved, they would show slivers of what the annotation hides."""
    order = sorted(
        range(len(before)), key=lambda k: (CMP_Z_ORDER.get(before[k].label, 99), before[k].z)
    )
    found: set[int] = set()
    for n, k in enumerate(order):
        if before[k].label == BACKGROUND:
            continue
        fronts = [j for j in order[n + 1 :] if before[j].label != BACKGROUND]
        if _hidden(before[k], [before[j] for j in fronts]):  # it, and what hides it
            found.add(k)
            found.update(j for j in fronts if _meet(before[j], before[k]))
    return found


def _hidden(rect: Rect, fronts: list[Rect]) -> bool:
    near = [
        f for f in fronts if f.x0 < rect.x1 and rect.x0 < f.x1 and f.y0 < rect.y1 and rect.y0 < f.y1
    ]
    if not near:
        return False
    for i in range(SAMPLES):
        x = rect.x0 + (i + 0.5) / SAMPLES * (rect.x1 - rect.x0)
        for j in range(SAMPLES):
            y = rect.y0 + (j + 0.5) / SAMPLES * (rect.y1 - rect.y0)
            if not any(f.x0 <= x <= f.x1 and f.y0 <= y <= f.y1 for f in near):
                return False
    return True


def _meet(a: Rect, b: Rect) -> bool:
    """Overlapping, or touching along one axis while overlapping along the other."""
    x = min(a.x1, b.x1) - max(a.x0, b.x0)
    y = min(a.y1, b.y1) - max(a.y0, b.y0)
    return x > -1e-9 and y > -1e-9 and max(x, y) > 1e-9


def _axis(spans: list[tuple[str, float, float]], extent: float) -> list[tuple[float, float]]:
    """Each span, structured along one axis (see the module)."""
    size = {k: b - a for k, (_, a, b) in enumerate(spans)}
    centre = {k: (a + b) / 2 for k, (_, a, b) in enumerate(spans)}
    by_label: dict[str, list[int]] = defaultdict(list)
    for k, (label, a, b) in enumerate(spans):
        if label != BACKGROUND and 0 < b - a <= BAND * extent:
            by_label[label].append(k)
    for members in by_label.values():

        def similar(first: float, b: float) -> bool:  # within twice the step of the first
            return b - first <= 2 * max(SIZE * first, min(JITTER * extent, 0.25 * first))

        def step(a: int, b: int) -> bool:
            return size[b] - size[a] <= max(SIZE * size[a], min(JITTER * extent, 0.25 * size[a]))

        chains = _chains(sorted(members, key=size.__getitem__), size, similar, step)
        for cluster in (c for chain in chains for c in _split(chain, size, JITTER * extent)):
            median = statistics.median(size[k] for k in cluster)
            for k in cluster:
                size[k] = median
    leading = sorted(by_label, key=lambda name: (-len(by_label[name]), name != STRUCTURE, name))
    _twins_sized(spans, size, leading)
    reference: list[float] = []
    near = NEAR * extent
    for label in leading:
        members = sorted(by_label[label], key=centre.__getitem__)

        def close(a: int, b: int) -> bool:
            return centre[b] - centre[a] <= min(near, 0.5 * size[a], 0.5 * size[b])

        lines = _chains(members, centre, lambda _v, _w: True, close)
        lines_at = _even([statistics.fmean(centre[k] for k in line) for line in lines])
        means = _mirrored(lines_at, extent, near)
        if reference:
            means = _onto(means, reference, near)
        else:
            reference = means
        for line, mean in zip(lines, means, strict=True):
            for k in line:
                centre[k] = mean
    out = []
    for k, (label, a, b) in enumerate(spans):
        if k not in size or label == BACKGROUND or not 0 < b - a <= BAND * extent:
            out.append((a, b))
            continue
        low = round(max(0.0, centre[k] - size[k] / 2), DIGITS)
        out.append((low, round(min(extent, low + size[k]), DIGITS)))
    return out


def _split(cluster: list[int], size: dict[int, float], jitter: float) -> list[list[int]]:
    """A cluster of sizes (sorted) cut at its widest step until each spans no more than
    the regulariser's share of its least (``RELATIVE``) or a hand's ``jitter``: a chain
    of steps each within a hand's error can bridge two sizes drawn apart (bays of
    windows a fifth wider than their neighbours' and the jittered ones between them)."""
    low, high = size[cluster[0]], size[cluster[-1]]
    if high - low <= max(RELATIVE * low, jitter):
        return [cluster]
    cut = max(range(1, len(cluster)), key=lambda n: size[cluster[n]] - size[cluster[n - 1]])
    return _split(cluster[:cut], size, jitter) + _split(cluster[cut:], size, jitter)


def _twins_sized(
    spans: list[tuple[str, float, float]], size: dict[int, float], leading: list[str]
) -> None:
    """Elements of different labels on one span (a sill snapped to its window's edges)
    keep one size: that of the label first in ``leading`` (the structure's), so their
    edges stay one after each label's sizes are clustered on its own. An opening keeps
    its own label's (a door snapped to the windows' edges over it, drawn wider than
    they are, took their width: family-with-defects seed 2's door lost 0.05 of IoU)."""
    rank = {label: n for n, label in enumerate(leading)}
    first: dict[tuple[float, float], int] = {}
    for k in sorted((k for k in size if spans[k][0] in rank), key=lambda k: (rank[spans[k][0]], k)):
        label, a, b = spans[k]
        if (a, b) in first and spans[first[(a, b)]][0] != label and label not in OPENINGS:
            size[k] = size[first[(a, b)]]
        else:
            first.setdefault((a, b), k)


def _mirrored(lines: list[float], extent: float, near: float) -> list[float]:
    """The lines made exactly symmetric about the façade's middle where, reflected, each
    is within ``near`` of another (mirrored halves, drawn by hand)."""
    reflected = [extent - m for m in reversed(lines)]
    if all(abs(a - b) <= near for a, b in zip(lines, reflected, strict=True)):
        return [(a + b) / 2 for a, b in zip(lines, reflected, strict=True)]
    return lines


def _onto(lines: list[float], reference: list[float], near: float) -> list[float]:
    """Each line on the nearest reference line within ``near``, unless another line of
    the same label would go there too (then both stay)."""
    nearest = [min(reference, key=lambda r: abs(r - m)) for m in lines]
    taken: dict[float, int] = defaultdict(int)
    for line, target in zip(lines, nearest, strict=True):
        taken[target] += abs(target - line) <= near
    return [
        target if abs(target - line) <= near and taken[target] == 1 else line
        for line, target in zip(lines, nearest, strict=True)
    ]


def _chains(
    members: list[int],
    value: dict[int, float],
    with_first: Callable[[float, float], bool],
    with_last: Callable[[int, int], bool] | None = None,
) -> list[list[int]]:
    """Sorted members cut into runs: each joins the run when ``with_first`` holds for the
    run's first value and its own, and ``with_last`` (when given) for the run's last
    member and itself."""
    runs: list[list[int]] = []
    for k in members:
        if (
            runs
            and with_first(value[runs[-1][0]], value[k])
            and (with_last is None or with_last(runs[-1][-1], k))
        ):
            runs[-1].append(k)
        else:
            runs.append([k])
    return runs


def _even(lines: list[float]) -> list[float]:
    """The lines with each run of near-equal spacings (within ``PITCH`` of the run's
    first, two spacings or more) spaced evenly between the run's ends."""
    out = list(lines)
    start = 0
    while start < len(out) - 1:
        first = out[start + 1] - out[start]
        end = start + 1
        while end < len(out) - 1 and abs((out[end + 1] - out[end]) - first) <= PITCH * first:
            end += 1
        if end - start >= 2:
            pitch = (out[end] - out[start]) / (end - start)
            for j in range(start + 1, end):
                out[j] = out[start] + (j - start) * pitch
        start = end
    return out
