"""Why a façade's bays are not shared (issue 34): bay kinds at looser tolerances.

For each façade (the CMP samples beside the project, ``../shared/data/cmp-sample/xml``,
never copied into it; ``--family``: the generated family, ``--defects`` with its
defects, ``--seeds A-B``), inferred at 15 x 15 m as ``facade infer`` does (snapped,
regularised, structured), the bays are cut on the openings (``infer.bays``) and read at
each tolerance of ``TOLERANCES`` (elements alike within that share of the bay's width,
``bays.ALIKE`` is the first), per way of framing them (about their openings, as cut):

- ``kinds``: the bays' kinds on their openings alone, as letters (``ABCBD``), and the
  pairs of bays alike (as drawn or mirrored) of all pairs;
- what ``infer.bays`` makes of them at that tolerance: the bays shared (and the mean
  per-label IoU against the annotation of the layout on the kinds' shapes, 2.5 cm
  raster, CMP z-order, with the elements lost and fused, and the worst label), or
  why not (none repeat, openings moved further than the structure's limit, overlaps,
  the fidelity gate: ``KEEP`` of the structure's IoU, else ``_fair``'s bar).

Counts and IoUs only; the CPU figure is ``time.process_time`` of this process. The
figures go into docs/benchmarks.md with this file's name.
"""

from __future__ import annotations

import sys
import tempfile
import time
from itertools import combinations
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli.grammar.deadline import Deadline  # noqa: E402
from facadecli.grammar.fidelity import Fidelity, fidelity  # noqa: E402
from facadecli.grammar.inputs import LabelledLayout  # noqa: E402
from facadecli.grammar.model import Options  # noqa: E402
from facadecli.grammar.tidy import tidy_layout  # noqa: E402
from facadecli.infer import bays  # noqa: E402
from facadecli.infer.structure import structured  # noqa: E402
from tests.benchmarks.annotated_family import written_family  # noqa: E402

DATA = ROOT.parent / "shared" / "data" / "cmp-sample" / "xml"
TOLERANCES = (bays.ALIKE, 0.10, 0.15)
SIZE = 15.0


def kinds(layout: LabelledLayout, on_openings: bool, alike: float) -> tuple[str, int, int]:
    """The bays' kinds on their openings as letters, the pairs alike and all pairs."""
    strips, spans, _ = bays._strips(layout)
    if len(strips) < 2:
        return "", 0, 0
    frames = bays._frames(layout.rects, strips, spans, on_openings, alike)
    order = bays._right_half_mirrored_first(len(strips))
    openings = [
        bays._slots([layout.rects[k] for k in held if bays._cuts(layout.rects[k])], span)
        for (_, held), span in zip(strips, spans, strict=True)
    ]
    found, _, _ = bays._kinds(openings, frames, order)
    alike_pairs = 0
    for a, b in combinations(range(len(openings)), 2):
        tolerance = frames.tolerance(b, a)
        alike_pairs += tolerance is not None and any(
            bays._match(openings[a], frames.read(openings[b], b, a, flip), tolerance) is not None
            for flip in (False, True)
        )
    pairs = len(openings) * (len(openings) - 1) // 2
    return "".join(chr(ord("A") + k) for k in found), alike_pairs, pairs


def _worst(result: Fidelity) -> str:
    label, iou = min(result.iou_per_label().items(), key=lambda item: item[1])
    return f"{label} {iou:.3f}"


def outcome(
    drawn: LabelledLayout, layout: LabelledLayout, was: Fidelity, on_openings: bool, alike: float
) -> str:
    """What ``infer.bays`` makes of the bays at ``alike`` framed so (companions on the
    shapes within ``FOLLOW``)."""
    for found in bays._found(layout, drawn, on_openings, (bays.FOLLOW,), alike):
        if isinstance(found, str):
            return found
        now = fidelity(drawn, found.layout)
        gate = (
            "kept"
            if bays.kept(was, now)
            else "fair"
            if bays._fair(drawn, layout, found.layout)
            else "refused"
        )
        return (
            f"{found.describe()}: IoU {now.iou_mean:.4f} (structure {was.iou_mean:.4f}), "
            f"lost {now.lost}, fused {now.fused}, worst {_worst(now)}: {gate}"
        )
    return "nothing found"


def run(paths: list[Path]) -> None:
    started = time.process_time()
    for path in paths:
        options = Options(size=(SIZE, SIZE))
        tidied = tidy_layout(path, options, Deadline(options.time_limit, str(path)))
        layout = structured(tidied.layout)
        was = fidelity(tidied.raw, layout)
        print(f"{path.stem}: structure IoU {was.iou_mean:.4f}, worst {_worst(was)}", flush=True)
        for alike in TOLERANCES:
            for on_openings in (True, False):
                letters, alike_pairs, pairs = kinds(layout, on_openings, alike)
                frame = "on openings" if on_openings else "as cut"
                verdict = outcome(tidied.raw, layout, was, on_openings, alike)
                print(
                    f"  {alike:.2f} {frame:11} {letters or '-':12} pairs alike "
                    f"{alike_pairs}/{pairs}: {verdict}",
                    flush=True,
                )
    print(f"CPU {(time.process_time() - started) / max(1, len(paths)):.2f} s a façade")


def main() -> None:
    """``--family`` (``--defects``, ``--seeds A-B``): the generated family, not CMP."""
    if "--family" not in sys.argv:
        files = sorted(DATA.glob("*.xml")) if DATA.is_dir() else []
        if not files:
            print(f"skipped: no CMP annotations in {DATA}")
        run(files)
        return
    first, last = 1, 24
    if "--seeds" in sys.argv:
        a, _, b = sys.argv[sys.argv.index("--seeds") + 1].partition("-")
        first, last = int(a), int(b or a)
    with tempfile.TemporaryDirectory() as folder:
        run(written_family(Path(folder), list(range(first, last + 1)), "--defects" in sys.argv))


if __name__ == "__main__":
    main()
