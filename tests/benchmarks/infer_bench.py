"""``make bench``, part four: ``facade infer`` on the CMP façades (15 x 15 m).

Reads the CMP sample annotations beside the project (``../shared/data/cmp-sample/xml``; they
are never copied into it) and prints, per façade, the rectangles read, the layers and the
lines of the spec inferred, the least intersection over union of a label when the spec is
solved back at the input's size, whether it solves at 0.7 and 1.5 times the width, and the
time of the whole (inference and check). Skips, saying so, when the data is not there.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from facadecli import parse_spec  # noqa: E402
from facadecli.grammar.model import Options  # noqa: E402
from facadecli.infer.run import check, infer  # noqa: E402

DATA = ROOT.parent / "shared" / "data" / "cmp-sample" / "xml"


def main() -> None:
    files = sorted(DATA.glob("*.xml")) if DATA.is_dir() else []
    if not files:
        print(f"infer benchmark skipped: no CMP annotations in {DATA}")
        return
    print("facade infer, 15 x 15 m, checked by solving")
    print(f"{'facade':10} {'rects':>6} {'layers':>6} {'lines':>6} {'IoU':>6}  widths   time")
    for path in files:
        started = time.perf_counter()
        inferred = infer(path, path.stem, Options(size=(15.0, 15.0)))
        inferred.checks = check(inferred, parse_spec(inferred.text, path.stem))
        elapsed = time.perf_counter() - started
        report = inferred.report()
        iou = f"{report['iou_min']:.3f}" if report.get("solves") else "none"
        widths = "".join(
            "y" if r["solves"] else "n"
            for r in report.get("retargets", [])  # type: ignore[attr-defined]
        )
        print(
            f"{path.stem:10} {report['rectangles']:6d} {report['layers']:6d} "
            f"{report['spec_lines']:6d} {iou:>6}  {widths:6}  {elapsed:5.1f}s"
        )


if __name__ == "__main__":
    main()
