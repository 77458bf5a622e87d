"""``make bench``, part two: split-grammar extraction on the CMP façades (Wu et al. 2014).

Reads the CMP sample annotations beside the project (``../shared/data/cmp-sample/xml``; they
are never copied into it) and prints, per façade, the tiling's size, what regularisation
moved, the greedy baseline's cost and ADP's (2,000 iterations, seed 0), ADP's rules, the
iteration that found the best grammar, the search's time and the whole pipeline's; derived
at 0.7, 1.5 and 2 times the width, the style kept, the windows stretched and the façades
with blank wall instead of bays (fewer windows a metre than the input); the same at 1.5
and 2 times the height and 1.5 times both (windows taller, floors not gained, floors
copied). Then one
derivation at a new size, and six variations at each width and at the input's own size.
Skips, saying so, when the data is not there.
"""

from __future__ import annotations

import itertools
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli.grammar.cmp_xml import read_cmp  # noqa: E402
from facadecli.grammar.extract import extract_grammar  # noqa: E402
from facadecli.grammar.model import (  # noqa: E402
    Extraction,
    Options,
    Piece,
)
from facadecli.grammar.pieces import apart, displacement  # noqa: E402
from facadecli.grammar.read import resize  # noqa: E402
from facadecli.grammar.style import Box, facade_of, tiles_of  # noqa: E402
from facadecli.grammar.tiling import BACKGROUND, Tiling  # noqa: E402
from facadecli.grammar.variations import APART, derive_layout, derive_variations  # noqa: E402
from facadecli.layout import Layout  # noqa: E402

SCALES = (0.7, 1.5, 2.0)  # derived widths, as multiples of the input's (15 x 15 m)
TALLER = ((1.0, 1.5), (1.0, 2.0), (1.5, 1.5))  # derived sizes taller, as multiples of the input's
WIDER = 1.15  # a derived window wider than this times the annotation's widest is stretched
SHRUNK = 0.7  # a derived window narrower or lower than this times its source piece
SPARSE = 0.8  # a derived layout with fewer windows a metre than this times the input's
DATA = ROOT.parent / "shared" / "data" / "cmp-sample" / "xml"


def main() -> None:
    files = sorted(DATA.glob("*.xml")) if DATA.is_dir() else []
    if not files:
        print(f"grammar benchmark skipped: no CMP annotations in {DATA}")
        return
    iterations = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    print(f"split grammars, ADP {iterations} iterations, seed 0")
    header = f"{'facade':10} {'cells':>6} {'moved':>6} {'greedy':>7} {'adp':>7} {'rules':>5}"
    print(
        header
        + f" {'repeat':>6} {'best@':>6} {'search':>7} {'time':>7}"
        + "   style kept at 0.7x 1.5x 2x width"
    )
    greedy, adp, times, searches = [], [], [], []
    extractions: list[Extraction] = []
    style_kept: dict[float, int] = {}
    windows: dict[float, int] = {}  # derived windows, and those wider than the source's
    wide: dict[float, int] = {}
    grown: dict[float, int] = {}  # windows wider than their own piece in the source
    sparse: dict[float, int] = {}  # façades with fewer windows a metre than the input's
    style_total = 0
    # at TALLER sizes: style kept, windows taller (or wider), sparse façades, windows,
    # façades whose floors were copied (not the grammar's)
    tall = {scales: [0, 0, 0, 0, 0] for scales in TALLER}
    last = None
    for path in files:
        started = time.perf_counter()
        extraction = extract_grammar(path, Options(iterations=iterations, size=(15.0, 15.0)))
        elapsed = time.perf_counter() - started
        assert not extraction.problems, extraction.problems
        found = extraction.found
        tiling = extraction.tiling
        cells = (len(tiling.xs) - 1) * (len(tiling.ys) - 1)
        moved = len(extraction.regularization.moves)
        greedy.append(found.greedy_cost)
        adp.append(extraction.grammar.cost)
        times.append(elapsed)
        searches.append(extraction.time_ms / 1000)
        repeats = sum(r.op in ("repeat", "repeatABA") for r in extraction.grammar.rules.values())
        style = extraction.style
        kept = []
        widest = _input_widest(path)
        source_density = len(_source_windows(tiling)) / tiling.xs[-1]
        for scale in SCALES:
            drawn, _ = derive_variations(
                extraction.grammar, tiling, 15.0 * scale, 15.0, "bench", 1, 0, style
            )
            kept.append(len(drawn[0].kept.kept))
            widths = _window_widths(drawn[0].layout)
            windows[scale] = windows.get(scale, 0) + len(widths)
            wide[scale] = wide.get(scale, 0) + sum(w > WIDER * widest for w in widths)
            grown[scale] = grown.get(scale, 0) + sum(
                p.x1 - p.x0 > WIDER * p.source_w for p in drawn[0].pieces if p.label == "window"
            )
            density = _windows(drawn[0].pieces, 15.0 * scale) / (15.0 * scale)
            sparse[scale] = sparse.get(scale, 0) + (density < SPARSE * source_density)
        for scales in TALLER:
            width, height = 15.0 * scales[0], 15.0 * scales[1]
            drawn, _ = derive_variations(
                extraction.grammar, tiling, width, height, "bench", 1, 0, style
            )
            pieces = [p for p in drawn[0].pieces if p.label == "window"]
            tall[scales][0] += len(drawn[0].kept.kept)
            tall[scales][1] += sum(
                p.y1 - p.y0 > WIDER * p.source_h or p.x1 - p.x0 > WIDER * p.source_w for p in pieces
            )
            tall[scales][2] += (
                _windows(drawn[0].pieces, width) / (width * height)
                < SPARSE * len(_source_windows(tiling)) / 225.0
            )
            tall[scales][3] += len(pieces)
            tall[scales][4] += "y " in drawn[0].retarget or "by buildings" in drawn[0].retarget
        for scale, count in zip(SCALES, kept, strict=True):
            style_kept[scale] = style_kept.get(scale, 0) + count
        style_total += len(style)
        print(
            f"{path.stem:10} {cells:6d} {moved:6d} {found.greedy_cost:7.1f} "
            f"{extraction.grammar.cost:7.1f} {len(extraction.grammar.rules):5d} {repeats:6d} "
            f"{found.best_iteration:6d} {searches[-1]:6.2f}s {elapsed:6.2f}s   "
            + " ".join(f"{k}/{len(style)}" for k in kept)
        )
        last = extraction
        extractions.append(extraction)
    print(
        f"{'mean':10} {'':6} {'':6} {statistics.mean(greedy):7.1f} {statistics.mean(adp):7.1f}"
        f" {'':5} {'':6} {'':6} {statistics.mean(searches):6.2f}s {statistics.mean(times):6.2f}s"
        f"   search max {max(searches):.2f}s, {sum(s < 1 for s in searches)} of {len(files)}"
        " under 1 s; time: the whole pipeline"
    )
    print(
        "style kept by derived layouts: "
        + ", ".join(f"{style_kept[s]} of {style_total} at {s}x" for s in SCALES)
        + " width (the input's tiling keeps all)"
    )
    print(
        "windows more than 15% wider than the input's widest: "
        + ", ".join(f"{wide[s]} of {windows[s]} at {s}x" for s in SCALES)
        + " width"
    )
    print(
        "windows more than 15% wider than their own piece of the source grammar: "
        + ", ".join(f"{grown[s]} of {windows[s]} at {s}x" for s in SCALES)
        + " width"
    )
    print(
        f"façades with under {SPARSE:.0%} of the input's windows a metre of width (blank wall "
        "instead of bays): " + ", ".join(f"{sparse[s]} of {len(files)} at {s}x" for s in SCALES)
    )
    for (across, up), (kept_tall, taller, sparse_tall, windows_tall, copied) in tall.items():
        print(
            f"at {across}x the width and {up}x the height ({15 * across:g} x {15 * up:g} m): "
            f"style kept {kept_tall} of {style_total}, windows more than 15% taller or wider "
            f"than their own piece {taller} of {windows_tall}, façades with under "
            f"{SPARSE:.0%} of the input's windows a square metre {sparse_tall} of "
            f"{len(files)}, floors copied (not the grammar's) on {copied}"
        )
    wins = sum(a < g for a, g in zip(adp, greedy, strict=True))
    print(f"ADP is cheaper than greedy on {wins} of {len(files)} façades")
    assert last is not None
    started = time.perf_counter()
    derive_layout(last.grammar, last.tiling, 24.0, 15.0, "bench")
    print(f"derive {files[-1].stem} at 24x15 with alignment: {time.perf_counter() - started:.2f}s")
    big = min(4, len(files) - 1)  # cmp_b0005 when all 12 are there
    for size in ((60.0, 60.0), (360.0, 360.0)):  # 4x and 24x both ways: the work budgets
        started = time.perf_counter()
        derive_layout(extractions[big].grammar, extractions[big].tiling, *size, "bench")
        elapsed = time.perf_counter() - started
        print(f"derive {files[big].stem} at {size[0]:g}x{size[1]:g}: {elapsed:.2f}s")
    variations(extractions)
    own_size(extractions)


def _input_widest(path: Path) -> float:
    """The widest window of the annotation itself, at 15 x 15 m (the layout derived at the
    input's size is no reference: tidying may have changed it)."""
    annotation = resize(read_cmp(path), 15.0, 15.0)
    return max((r.x1 - r.x0 for r in annotation.rects if r.label == "window"), default=0.0)


def _source_windows(tiling: Tiling) -> list[Box]:
    facade = facade_of(tiles_of(tiling), tiling.xs[-1], tiling.ys[-1], BACKGROUND)
    return [b for b in facade.boxes if b.label == "window"]


def _windows(pieces: tuple[Piece, ...], width: float) -> int:
    """The windows of a derived layout, each counted once however many pieces make it."""
    boxes = [Box(p.label, p.x0, p.y0, p.x1, p.y1) for p in pieces]
    height = max((p.y1 for p in pieces), default=1.0)
    return sum(b.label == "window" for b in facade_of(boxes, width, height, BACKGROUND).boxes)


def _window_widths(layout: Layout) -> list[float]:
    labels = {name: symbol.label for name, symbol in layout.spec.symbols.items()}
    return [s.x1 - s.x0 for s in layout.shapes if labels.get(s.x) == "window"]


def variations(extractions: list[Extraction]) -> None:
    """``--variations 6`` at each width: how many distinct layouts, and how many of them
    keep as many constraints of the style as the size's first layout."""
    asked, made, full, seconds = 6, dict.fromkeys(SCALES, 0), dict.fromkeys(SCALES, 0), 0.0
    least: dict[float, list[float]] = {s: [] for s in SCALES}  # of the façade's smaller side
    near = dict.fromkeys(SCALES, 0)  # pairs of variations less than APART apart
    for extraction in extractions:
        for scale in SCALES:
            started = time.perf_counter()
            drawn, _ = derive_variations(
                extraction.grammar,
                extraction.tiling,
                15.0 * scale,
                15.0,
                "bench",
                asked,
                0,
                extraction.style,
            )
            seconds += time.perf_counter() - started
            made[scale] += len(drawn)
            full[scale] += sum(len(v.kept.kept) >= len(drawn[0].kept.kept) for v in drawn)
            moved = [
                displacement(a.pieces, b.pieces) / 15.0 for a, b in itertools.combinations(drawn, 2)
            ]
            least[scale] += [min(moved)] if moved else []
            near[scale] += sum(
                not apart(a.pieces, b.pieces, APART * 15.0)
                for a, b in itertools.combinations(drawn, 2)
            )
    total = asked * len(extractions)
    print(
        f"--variations {asked}: "
        + ", ".join(f"{made[s]} of {total} at {s}x" for s in SCALES)
        + " width; keeping as much of the style as the first: "
        + ", ".join(f"{full[s]}" for s in SCALES)
        + f" ({seconds / (len(extractions) * len(SCALES)):.1f} s a size)"
    )
    print(
        "  variations apart (pieces.displacement: mean edge distance of an element to the "
        "nearest of its label in the other, of the façade's 15 m): least pair, mean over "
        "façades, "
        + ", ".join(f"{statistics.fmean(least[s]) if least[s] else 0:.1%} at {s}x" for s in SCALES)
        + f"; pairs not visibly apart (as many elements, under {APART:.0%}): "
        + ", ".join(f"{near[s]}" for s in SCALES)
    )


def own_size(extractions: list[Extraction]) -> None:
    """``--variations 6`` at the input's own size (15 x 15 m): distinct layouts, those
    keeping as much of the style as the first, and windows shrunk below ``SHRUNK`` of their
    source size either way."""
    asked, made, full, shrunk, windows = 6, 0, 0, 0, 0
    for extraction in extractions:
        drawn, _ = derive_variations(
            extraction.grammar, extraction.tiling, 15.0, 15.0, "bench", asked, 0, extraction.style
        )
        made += len(drawn)
        full += sum(len(v.kept.kept) >= len(drawn[0].kept.kept) for v in drawn)
        for variation in drawn:
            pieces = [p for p in variation.pieces if p.label == "window"]
            windows += len(pieces)
            shrunk += sum(
                p.x1 - p.x0 < SHRUNK * p.source_w or p.y1 - p.y0 < SHRUNK * p.source_h
                for p in pieces
            )
    print(
        f"--variations {asked} at the input's own size: {made} of {asked * len(extractions)}, "
        f"keeping as much of the style as the first: {full}; windows shrunk below "
        f"{SHRUNK:.0%} of their source size: {shrunk} of {windows}"
    )


if __name__ == "__main__":
    main()
