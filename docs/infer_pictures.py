"""Before/after pictures of ``facade infer``'s worst cases (issue 34), for the docs.

Each picture is one case (an annotation and a size) drawn by one version of the code: the
annotation as read on the left, at its size, and the inferred spec solved at the case's
size on the right, each rectangle in its label's colour (``grammar.palette``), painted in
the annotation's z-order (the spec's layers back to front on the right); a red outline
marks an opening (window or door) that overlaps another by more than 1 cm x 1 cm. The SVG
is taken as a PNG by headless Chromium (``pictures.screenshot``).

A case is ``family-<seed>`` (``tests/benchmarks/annotated_family``) or the path of a CMP
XML annotation (or of a JSON list of rectangles), at ``1x``, ``0.7w``, ``1.5w``, ``2w``,
``1.5h`` or ``0.7h``; the façade is inferred at 15 x 15 m, as the benchmarks do. The
code that draws the right side is the checkout whose root is given (``--code``, default
this one); it is run in a child process of this interpreter with that checkout first on
``sys.path``, so an older commit's checkout (a ``git worktree`` of it) gives its
"before"::

    python docs/infer_pictures.py docs/pictures/infer-worst-family-12-1x-after.png \\
        family-12 1x "family seed 12 at 1x, after"
    python docs/infer_pictures.py --code /tmp/before docs/pictures/...-before.png ...
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from html import escape
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
SIZES = {"1x": (1.0, 1.0), "0.7w": (0.7, 1.0), "1.5w": (1.5, 1.0), "2w": (2.0, 1.0)}
SIZES["1.5h"] = (1.0, 1.5)
SIZES["0.7h"] = (1.0, 0.7)
SCALE = 24.0  # pixels a metre
GAP = 24.0  # pixels between the two elevations and round them
OVERLAP = 0.01  # m: openings overlapping by more than this both ways are marked

# Run in the child process, with the checkout to draw first on sys.path: infer the case,
# solve its spec at the size and print the annotation and the solved rectangles (JSON).
DUMP = """
import importlib.util, json, sys, tempfile
from pathlib import Path
sys.path.insert(0, sys.argv[1])
import facadecli
assert Path(facadecli.__file__).parent.parent == Path(sys.argv[1]), facadecli.__file__
from facadecli import parse_spec
try:
    from facadecli.grammar.model import Options
    from facadecli.grammar.read import read_layout, resize
except ImportError:  # before the grammar was re-cut along its pipeline
    from facadecli.grammar.run import Options, read_layout, resize
from facadecli.infer.run import infer
from facadecli.infer.spec_text import layer_names
from facadecli.solve import retarget, solve
generated = importlib.util.spec_from_file_location(
    "annotated_family", Path(sys.argv[5]) / "tests" / "benchmarks" / "annotated_family.py"
)
annotated = sys.modules["annotated_family"] = importlib.util.module_from_spec(generated)
generated.loader.exec_module(annotated)

case, wide, high = sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
size = 15.0
if case.startswith("family-"):
    path = Path(tempfile.mkdtemp()) / f"{case}.xml"
    path.write_text(annotated.cmp_xml(annotated.family(int(case.split("-")[1]))[0]))
else:
    path = Path(case)
raw = resize(read_layout(path)[0], size, size)
inference = infer(path, path.stem, Options(size=(size, size)))
spec = parse_spec(inference.text, path.stem)
layout = solve(retarget(spec, round(size * wide, 4), round(size * high, 4)))
names = ["wall", *layer_names(inference.grids)]
label = {n: g.label for n, g in zip(names[1:], inference.grids)}
order = {n: k for k, n in enumerate(names)}
shown = [
    (label[s.layer], s.x0, s.y0, s.x1, s.y1, order[s.layer])
    for s in layout.shapes
    if s.layer in label
    and not (spec.qualifiers(s.x).transparent or spec.qualifiers(s.y).transparent)
]
drawn = [(r.label, r.x0, r.y0, r.x1, r.y1, r.z) for r in raw.rects]
print(json.dumps({
    "annotation": {"width": raw.width, "height": raw.height, "rects": drawn},
    "output": {"width": size * wide, "height": size * high, "rects": shown},
}))
"""


def dumped(code: Path, case: str, size: str) -> dict[str, dict[str, Any]]:
    """The annotation and the solved spec of ``case`` at ``size``, by the code at ``code``."""
    wide, high = SIZES[size]
    found = subprocess.run(
        [sys.executable, "-c", DUMP, str(code), case, str(wide), str(high), str(ROOT)],
        capture_output=True,
        text=True,
    )
    if found.returncode:
        sys.exit(f"{case} at {size} by {code}:\n{found.stderr}")
    result: dict[str, dict[str, Any]] = json.loads(found.stdout)
    return result


def elevation(part: dict[str, Any], left: float, top: float, height: float) -> list[str]:
    """SVG rectangles of one elevation (``part``: its width, height and rects, y up),
    painted by z (stable), at ``left``, ``top``; openings overlapping others outlined red."""
    from facadecli.grammar.palette import label_colour

    width, tall = float(part["width"]), float(part["height"])
    rects = sorted(part["rects"], key=lambda r: r[5])
    out = [
        f'<rect x="{left:.1f}" y="{top + (height - tall) * SCALE:.1f}" '
        f'width="{width * SCALE:.1f}" height="{tall * SCALE:.1f}" '
        f'fill="{label_colour("facade")}"/>'
    ]
    openings = [r[1:5] for r in rects if r[0] in ("window", "door")]
    for label, x0, y0, x1, y1, _ in rects:
        if label == "facade":
            continue
        over = label in ("window", "door") and any(
            min(x1, c1) - max(x0, c0) > OVERLAP and min(y1, d1) - max(y0, d0) > OVERLAP
            for c0, d0, c1, d1 in openings
            if (c0, d0, c1, d1) != (x0, y0, x1, y1)
        )
        stroke = 'stroke="#e02020" stroke-width="2"' if over else 'stroke="#222" stroke-width="0.5"'
        out.append(
            f'<rect x="{left + x0 * SCALE:.1f}" y="{top + (height - y1) * SCALE:.1f}" '
            f'width="{(x1 - x0) * SCALE:.1f}" height="{(y1 - y0) * SCALE:.1f}" '
            f'fill="{label_colour(label)}" {stroke}/>'
        )
    return out


def mismatch(found: dict[str, dict[str, Any]]) -> tuple[str, str]:
    """Where the solved spec shows another label than the annotation, as a PNG data URI
    (red; the annotation faint elsewhere), on ``grammar.fidelity``'s raster (2.5 cm, the
    annotation's z-order; the output's layers back to front): what its IoU counts; and
    that fidelity in words (mean IoU, the two lowest labels, elements lost)."""
    import base64
    import io

    import numpy as np
    from PIL import Image

    from facadecli.grammar.fidelity import fidelity, grid, paint
    from facadecli.grammar.inputs import BACKGROUND, LabelledLayout, Rect

    given, made = found["annotation"], found["output"]
    cells = grid(float(given["width"]), float(given["height"]))
    parts = [[Rect(*r) for r in part["rects"]] for part in (given, made)]
    names = sorted({BACKGROUND, *(r.label for rects in parts for r in rects)})
    code = {name: k for k, name in enumerate(names)}
    drawn, shown = (paint(rects, cells, code)[0] for rects in parts)
    picture = np.full((*drawn.shape, 3), 255, dtype=np.uint8)
    picture[drawn != code[BACKGROUND]] = (215, 215, 225)
    picture[drawn != shown] = (224, 32, 32)
    buffer = io.BytesIO()
    Image.fromarray(picture[::-1]).save(buffer, format="PNG", optimize=True)
    width, height = cells.width, cells.height
    given_layout, made_layout = (LabelledLayout(width, height, tuple(rects)) for rects in parts)
    measured = fidelity(given_layout, made_layout)
    lowest = sorted(measured.iou_per_label().items(), key=lambda item: item[1])[:2]
    said = (
        f"mean IoU {measured.iou_mean:.3f} ("
        + ", ".join(f"{label} {iou:.3f}" for label, iou in lowest)
        + f"), {measured.lost} lost, {measured.fused} fused"
    )
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode(), said


def picture_svg(found: dict[str, dict[str, Any]], title: str) -> tuple[str, int, int]:
    """The SVG of the annotation and the solved spec side by side, titled, and at the
    input's size a third panel: the cells whose label differs (``mismatch``); its size."""
    given, made = found["annotation"], found["output"]
    panels = [float(given["width"]), float(made["width"])]
    same = (given["width"], given["height"]) == (made["width"], made["height"])
    if same:
        panels.append(float(given["width"]))
    tallest = max(float(given["height"]), float(made["height"]))
    width = GAP * (len(panels) + 1) + sum(panels) * SCALE
    height = GAP * 2.5 + tallest * SCALE
    right = GAP * 2 + panels[0] * SCALE
    body = [
        f'<text x="{GAP}" y="{GAP * 0.8:.1f}" font-family="sans-serif" font-size="13">'
        f"{escape(title)}</text>",
        *elevation(given, GAP, GAP * 1.5, tallest),
        *elevation(made, right, GAP * 1.5, tallest),
    ]
    if same:
        picture, said = mismatch(found)
        body[0] = body[0].replace("</text>", f": {escape(said)}</text>")
        body.append(
            f'<image x="{right + GAP + panels[1] * SCALE:.1f}" y="{GAP * 1.5:.1f}" '
            f'width="{panels[2] * SCALE:.1f}" height="{tallest * SCALE:.1f}" '
            f'preserveAspectRatio="none" style="image-rendering:pixelated" '
            f'href="{picture}"/>'
        )
    svg = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}">'
        f'<rect width="100%" height="100%" fill="#fff"/>{"".join(body)}</svg>'
    )
    return svg, round(width), round(height)


def main(arguments: list[str]) -> None:
    code = ROOT
    if arguments[:1] == ["--code"]:
        code, arguments = Path(arguments[1]).resolve(), arguments[2:]
    target, case, size, title = Path(arguments[0]), arguments[1], arguments[2], arguments[3]
    sys.path.insert(0, str(ROOT / "docs"))
    from pictures import browser, screenshot

    svg, width, height = picture_svg(dumped(code, case, size), title)
    with tempfile.TemporaryDirectory() as scratch:
        page = Path(scratch) / "picture.svg"
        page.write_text(svg, encoding="utf-8")
        screenshot(browser(), page.as_uri(), target, f"{width},{height}", Path(scratch) / "p")
    print(f"{target}: {target.stat().st_size // 1024} KB")


if __name__ == "__main__":
    main(sys.argv[1:])
