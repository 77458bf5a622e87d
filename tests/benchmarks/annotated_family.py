"""A family of hand-drawn-looking annotations with known structure, for measuring the
tidy-up against what was drawn (issue 34), seed by seed: nothing in it comes from a CMP
sample.

Each seed draws a façade on CMP's unit square: a grid of bays and floors (pitches
jittered a little, as a hand draws them), a window in every cell with its sill under it
and, on some façades, a blind beside it (CMP's z-order puts the window in front), a
cornice across the façade over some floors, one door in a ground-floor bay (unique), and,
on some façades, mirrored halves (the left half drawn, then mirrored, then each edge
jittered on its own). Every edge is then moved by a drawing jitter of a few thousandths
of the façade. ``known(seed)`` says what is there: windows, bays, floors.

With ``defects``, the façade also has what real façades (CMP's) have and a clean grid
has not: end bays wider than the others (15-35% more wall), and in about a quarter of
the bays (not the door's) one floor whose window is missing (with its sill and blind)
or drawn ``ODD`` wider or narrower (its sill with it). The defects are drawn from a
generator of their own, after the façade's, so a seed without them is the same
annotation as ever.
"""

from __future__ import annotations

import random
import statistics
from dataclasses import dataclass, replace
from pathlib import Path

Box = tuple[str, float, float, float, float]  # label, x0, y0, x1, y1 on the unit square, y up
ODD = (0.1, 0.3)  # the least and most share an odd window is wider or narrower by
DEFECTIVE = 0.25  # the share of bays (not the door's) with a missing or odd window


@dataclass(frozen=True)
class Known:
    bays: int
    floors: int
    windows: int
    doors: int
    mirrored: bool
    blinds: bool
    missing: int = 0  # windows left out (defects)
    odd: int = 0  # windows drawn wider or narrower than their floor's (defects)


def family(seed: int, defects: bool = False) -> tuple[list[Box], Known]:
    """The annotation of seed ``seed`` (background first, then by label) and its structure;
    ``defects``: with wider end bays and missing or odd windows (see the module)."""
    rng = random.Random(seed)
    bays, floors = rng.randint(3, 9), rng.randint(2, 7)
    mirrored, blinds = rng.random() < 0.5, rng.random() < 0.5
    jitter = rng.uniform(0.001, 0.004)  # a hand's error, of the façade
    margin = rng.uniform(0.02, 0.06)
    pitch_x = (1 - 2 * margin) / bays
    pitch_y = 0.9 / (floors + 0.5)
    width = rng.uniform(0.35, 0.6) * pitch_x
    height = rng.uniform(0.4, 0.6) * pitch_y
    door_bay = bays // 2 if mirrored else rng.randrange(bays)

    def bay_x(k: int) -> float:  # the centre of bay k, its pitch jittered
        return margin + (k + 0.5) * pitch_x + rng.uniform(-0.1, 0.1) * pitch_x * 0.1

    centres = [bay_x(k) for k in range(bays)]
    flaws = random.Random(f"defects-{seed}")  # its own generator: the façade's draws stay
    odd: dict[tuple[int, int], float] = {}  # (bay, floor): the window's width, as a share
    if defects:
        more = flaws.uniform(0.15, 0.35)
        centres, inner = _wider_ends(centres, margin, pitch_x, more)
        beside = 0.3 * width if blinds else 0.0  # a blind's reach beyond its window
        widest = 2 * (0.9 * inner - width / 2 - beside) / width  # clear of the next bay's
        for k in range(bays):
            if k != door_bay and flaws.random() < DEFECTIVE:
                scale = 1 + flaws.choice((-1, 1)) * flaws.uniform(*ODD)
                if scale > widest:
                    scale = 2 - scale  # as much narrower: wider would reach the next bay
                odd[k, flaws.randrange(floors)] = 0.0 if flaws.random() < 0.5 else scale
    if mirrored:  # the left half drawn, mirrored
        half = [centres[k] for k in range(bays // 2)]
        middle = [0.5] if bays % 2 else []
        centres = [*half, *middle, *(1 - c for c in reversed(half))]
    boxes: list[Box] = [("facade", 0.0, 0.0, 1.0, 1.0)]
    windows, sills, side, cornices, doors = [], [], [], [], []
    for f in range(floors):
        base = 0.05 + (f + 0.25) * pitch_y
        for k, c in enumerate(centres):
            if f == 0 and k == door_bay:
                w = width * 1.2
                doors.append(("door", c - w / 2, 0.0, c + w / 2, base + height))
                continue
            scale = odd.get((k, f), 1.0)
            if not scale:
                continue  # a window missing (defects)
            w = width * scale
            windows.append(("window", c - w / 2, base, c + w / 2, base + height))
            sills.append(("sill", c - w * 0.55, base - 0.012, c + w * 0.55, base))
            if blinds:
                reach = c + width * 0.8 if scale == 1.0 else c + w / 2 + width * 0.3
                side.append(("blind", c + w / 2 - 0.01, base, reach, base + height))
        if f and rng.random() < 0.4:
            top = base + height + 0.15 * pitch_y
            cornices.append(("cornice", margin / 2, top, 1 - margin / 2, top + 0.012))

    def drawn(box: Box) -> Box:
        label, *edges = box
        x0, y0, x1, y1 = (min(max(v + rng.gauss(0.0, jitter / 2), 0.0), 1.0) for v in edges)
        return (label, x0, y0, x1, y1)

    boxes += [drawn(b) for b in (*windows, *cornices, *doors, *sills, *side)]
    missing = sum(1 for scale in odd.values() if not scale)
    known = Known(
        bays, floors, len(windows), len(doors), mirrored, blinds, missing, len(odd) - missing
    )
    return boxes, known


def _wider_ends(
    centres: list[float], margin: float, pitch: float, more: float
) -> tuple[list[float], float]:
    """The bays' centres (each with its jitter) with the two end bays ``more`` wider than
    the inner ones, the bays as wide in all, each end window in the middle of its bay;
    and the inner bays' pitch."""
    count = len(centres)
    inner = pitch * count / (count + 2 * more)
    pitches = [inner * (1 + more), *[inner] * (count - 2), inner * (1 + more)]
    out, edge = [], margin
    for k, step in enumerate(pitches):
        out.append(edge + step / 2 + (centres[k] - margin - (k + 0.5) * pitch))
        edge += step
    return out, inner


def cmp_xml(boxes: list[Box]) -> str:
    """CMP XML of the boxes (CMP's rows count down from the top)."""
    return "\n".join(
        f"<object><points><x>{1 - y1:.6f}</x><x>{1 - y0:.6f}</x><y>{x0:.6f}</y>"
        f"<y>{x1:.6f}</y></points><label>3</label><labelname>{label}</labelname>"
        "<flag>1</flag></object>"
        for label, x0, y0, x1, y1 in boxes
    )


def paired_family(seed: int) -> tuple[list[Box], Known]:
    """``family(seed)`` with narrow bays between its columns (issue 34's coarse units): a
    small window (with its sill) on the top floor in the middle of the wall between two
    columns of windows, in every wall (``ABAB..``) or every other one (``AAB AAB..``, the
    seed's draw), as on façades whose attic windows sit between the columns below. Each
    column's windows are drawn narrower by a share of their own (0.6-0.85, a mirrored
    façade's partners alike), so that no two bays read alike: every bay drawn once, as on
    CMP. A column holds a window a floor (the door's one fewer) and a narrow bay one, so a
    façade of another width keeps its density only by gaining or dropping a column with
    the narrow bay beside it. ``Known.windows`` counts the small windows too."""
    boxes, known = family(seed)
    rng = random.Random(f"paired-{seed}")
    columns = _columns(boxes)
    count = len(columns)

    def column(box: Box) -> int:
        return _column(columns, box)

    scales = [rng.uniform(0.6, 0.85) for _ in range(count)]
    if known.mirrored:
        scales = [scales[min(k, count - 1 - k)] for k in range(count)]
    every = rng.choice((1, 2))  # a narrow bay in every wall, or in every other one
    out = _narrowed(boxes, columns, scales)
    top = max(b[2] for b in out if b[0] == "window")
    row = [b for b in out if b[0] == "window" and top - b[2] < 0.02]
    y0, y1 = statistics.median(b[2] for b in row), statistics.median(b[4] for b in row)
    walls = [k for k in range(count - 1) if k % every == 0]
    if known.mirrored:  # mirrored: the walls chosen mirror too
        walls = sorted({*walls, *(count - 2 - k for k in walls)})
    held = [b for b in out if b[0] in ("window", "door", "sill", "blind")]
    added: list[Box] = []
    for k in walls:
        left = max(b[3] for b in held if column(b) == k)
        right = min(b[1] for b in held if column(b) == k + 1)
        middle, size = (left + right) / 2, 0.4 * (right - left)
        added.append(("window", middle - size / 2, y0, middle + size / 2, y1))
        added.append(("sill", middle - 0.55 * size, y0 - 0.012, middle + 0.55 * size, y0))
    out += added
    order = ("facade", "window", "cornice", "door", "sill", "blind")
    out.sort(key=lambda b: order.index(b[0]))
    return out, replace(known, windows=known.windows + len(added) // 2)


def _columns(boxes: list[Box]) -> list[float]:
    """The centres of the columns of openings (the drawn ones within 2 cm are one)."""
    columns: list[float] = []
    for c in sorted((b[1] + b[3]) / 2 for b in boxes if b[0] in ("window", "door")):
        if not columns or c - columns[-1] > 0.02:
            columns.append(c)
    return columns


def _column(columns: list[float], box: Box) -> int:
    return min(range(len(columns)), key=lambda j: abs(columns[j] - (box[1] + box[3]) / 2))


def _narrowed(boxes: list[Box], columns: list[float], scales: list[float]) -> list[Box]:
    """The boxes with each column's windows and sills drawn narrower by its ``scales``
    share about their middles, its blinds moved with their windows' edges."""
    out: list[Box] = []
    for box in boxes:
        label, x0, y0, x1, y1 = box
        if label in ("window", "sill", "blind"):
            k = _column(columns, box)
            if label == "blind":  # beside its window: it moves with the window's edge
                x0, x1 = (
                    columns[k] + (x0 - columns[k]) * scales[k],
                    x1 + (x0 - columns[k]) * (scales[k] - 1),
                )
            else:
                half = (x1 - x0) * scales[k] / 2
                x0, x1 = (x0 + x1) / 2 - half, (x0 + x1) / 2 + half
        out.append((label, x0, y0, x1, y1))
    return out


def doorway_family(seed: int) -> tuple[list[Box], Known]:
    """``family(seed)`` whose door stands in a bay of its own: no window (sill, blind) over
    it in its column, as over an entrance hall or a passage (issue 34's dense copies:
    CMP's b0012). Every other bay holds a column of windows, so the façade holds fewer
    windows a metre than each of its columns does; a wider façade that gains columns at
    their drawn pitch grows denser than drawn. Each column's windows are drawn narrower
    by a share of their own (0.6-0.85, a mirrored façade's partners alike), so that no
    two bays read alike: every bay drawn once, as on CMP. ``Known.windows`` counts the
    windows left."""
    boxes, known = family(seed)
    rng = random.Random(f"doorway-{seed}")
    columns = _columns(boxes)
    count = len(columns)
    scales = [rng.uniform(0.6, 0.85) for _ in range(count)]
    if known.mirrored:
        scales = [scales[min(k, count - 1 - k)] for k in range(count)]
    boxes = _narrowed(boxes, columns, scales)
    door = next(b for b in boxes if b[0] == "door")
    middle = (door[1] + door[3]) / 2

    def over_door(box: Box) -> bool:
        return box[0] in ("window", "sill", "blind") and box[1] < middle < box[3]

    kept = [b for b in boxes if not over_door(b)]
    gone = sum(b[0] == "window" for b in boxes) - sum(b[0] == "window" for b in kept)
    return kept, replace(known, windows=known.windows - gone)


def written_family(
    folder: Path,
    seeds: list[int],
    defects: bool = False,
    paired: bool = False,
    doorway: bool = False,
) -> list[Path]:
    """The annotations of ``seeds`` as CMP XML files in ``folder`` (``family-<seed>.xml``;
    ``defects``: ``family``'s; ``paired``: ``paired_family``'s; ``doorway``:
    ``doorway_family``'s)."""
    paths = []
    for seed in seeds:
        path = folder / f"family-{seed}.xml"
        if doorway:
            boxes = doorway_family(seed)[0]
        else:
            boxes = paired_family(seed)[0] if paired else family(seed, defects)[0]
        path.write_text(cmp_xml(boxes))
        paths.append(path)
    return paths
