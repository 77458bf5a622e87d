"""Render the README's pictures with facadecli itself (``make pictures``).

Each picture is a spec solved with ``facade solve -f html,svg`` and a screenshot of the
page (the model alone, ``?bare``, from the camera ``?view=`` gives) or of the SVG
elevation, taken by a headless Chromium (software WebGL). Needs ``chromium`` on the PATH
(or CHROME=/path/to/browser); run from the project's root.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

from facadecli.geometry.primitives import RECESS_DEPTH

ROOT = Path(__file__).resolve().parent.parent
TARGET = ROOT / "docs" / "pictures"
WINDOW = "900,560"

# picture name -> (spec, what: "model" or "elevation", camera: around, up, zoom, x, y)
PICTURES: dict[str, tuple[str, str, str]] = {
    "centred-bay": ("centred-bay", "model", "35,10"),
    "qualifiers": ("qualifiers", "model", "35,10"),
    "residential-house": ("residential-house", "model", "35,10"),
    "shop-front": ("shop-front", "model", "35,10"),
    "terraced-house": ("terraced-house", "model", "35,10"),
    "townhouse": ("townhouse", "model", "35,10"),
    "townhouse-street": ("townhouse", "model", "street,25"),
    # the rooms behind the windows close up: 30° round and 5° up, five times closer than
    # the whole façade; and from below, as from the street, 40° round and 12° down
    "townhouse-rooms-depth": ("townhouse", "model", "30,5,5,0.6,0.45,0.9"),
    "townhouse-rooms-street": ("townhouse", "model", "40,-12,2.4,0.5,0.35,0.9"),
    # the rooms as wide as a room, floor at the storey's floor: 35° round, level, six
    # times closer than the whole façade; and from below as townhouse-rooms-street
    "townhouse-rooms-wide": ("townhouse", "model", "35,0,6,0.45,0.5,0.9"),
    "townhouse-rooms-below": ("townhouse", "model", "40,-12,2.4,0.5,0.35,0.9"),
    "parts": ("parts", "model", "35,10,1.1,0.5,0.5"),
    "parts-elevation": ("parts", "elevation", ""),
}

Shape = dict[str, Any]  # a shape of a solved layout's report (``layout.json``)

# a part's close-up: the spec, the shapes it shows (a test of each visible shape of the
# solved layout), the share of their height it shows from their foot up (a sill: the
# foot of its window) and the camera's angle round and up; aimed and zoomed by
# :func:`part_view` from where the shapes stand, so the part fills the picture
PARTS: dict[str, tuple[str, Callable[[Shape], bool], tuple[float, float], float, float]] = {
    "part-door": ("parts", lambda s: s["mesh"] == "door", (0.0, 1.0), 25, 5),
    "part-arch-shutters": ("parts", lambda s: s["mesh"] in ("arch", "shutter"), (0, 1), -30, 5),
    "part-balcony": ("parts", lambda s: s["mesh"] == "balcony", (0.0, 1.0), 45, 20),
    "part-sill": (
        "parts",
        lambda s: s["mesh"] == "frame" and (s["x"], s["y"]) == ("D", "F"),
        (0.0, 0.6),
        50,
        25,
    ),
    # the cornice's free end, where its profile shows
    "part-ledge": ("parts", lambda s: s["y"] == "C" and s["x1"] <= 2.0, (0.0, 1.0), -60, -15),
    # the townhouse's middle pilaster on the ground floor: its coursed sandstone (the
    # library's ashlar) close up
    "stone-close": (
        "townhouse",
        lambda s: s["layer"] == "pilasters" and s["y"] == "G" and 3 < s["x0"] < 6,
        (0.25, 0.75),
        20,
        5,
    ),
}
# of the picture's width or height (the tighter) the part would span seen square on; the
# viewer's 8% margin and the perspective of an oblique view leave about three quarters
PART_FILL = 0.9
ASPECT = 900 / 560  # the screenshot's (WINDOW), the widest a part's picture is
PART_NARROWEST = 0.6  # the narrowest a part's picture is, as a share of its height


def looks(wide: float, high: float, deep: float, around: float, up: float) -> tuple[float, float]:
    """How wide and how high a box looks from ``around`` degrees round and ``up`` degrees
    up (seen from afar: no perspective)."""
    a, u = math.radians(around), math.radians(up)
    across = wide * abs(math.cos(a)) + deep * abs(math.sin(a))
    return across, high * math.cos(u) + (deep * abs(math.cos(a))) * abs(math.sin(u))


def part_view(
    layout: dict[str, Any],
    shows: Callable[[Shape], bool],
    share: tuple[float, float],
    around: float,
    up: float,
) -> tuple[str, str]:
    """The viewer's ``?view=`` aimed at the part and the window to take it in: the middle
    of the shapes ``shows`` picks (the ``share`` of their height from the foot), as
    shares of the model's box (the canvas across and up; in depth, from the deepest
    shape's back, less a window recess, to the most proud one's front), and zoomed from
    the whole model's fit until the part spans :data:`PART_FILL` of the picture (the fit
    shows the canvas, its tighter side filling the picture). The window is as tall as
    :data:`WINDOW` and as wide as the part looks beside its height, from
    :data:`PART_NARROWEST` to :data:`ASPECT` times it: a tall part (a door) gets an
    upright picture of itself, not its neighbours either side."""
    visible = [s for s in layout["shapes"] if s["visible"]]
    chosen = [s for s in visible if shows(s)]
    assert chosen, "no shape of the layout is the part"
    x0, x1 = min(s["x0"] for s in chosen), max(s["x1"] for s in chosen)
    y0, y1 = min(s["y0"] for s in chosen), max(s["y1"] for s in chosen)
    y0, y1 = y0 + share[0] * (y1 - y0), y0 + share[1] * (y1 - y0)
    front = max(s["z1"] for s in chosen)
    back = min(s["z0"] for s in visible) - RECESS_DEPTH
    deep = max(s["z1"] for s in visible) - back
    width, height = layout["canvas"]["width"], layout["canvas"]["height"]
    depth = front - min(s["z0"] for s in chosen)
    model_wide, model_high = looks(width, height, deep, around, up)
    part_wide, part_high = looks(x1 - x0, y1 - y0, depth, around, up)
    aspect = min(max(part_wide / part_high, PART_NARROWEST), ASPECT)
    seen_wide = max(model_wide, model_high * aspect)  # the model's fit: what the picture spans
    zoom = PART_FILL * min(seen_wide / part_wide, seen_wide / aspect / part_high)
    at = ((x0 + x1) / 2 / width, (y0 + y1) / 2 / height, (front - depth / 2 - back) / deep)
    high = int(WINDOW.split(",")[1])
    view = f"{around:g},{up:g},{zoom:.2f}," + ",".join(f"{share:.3f}" for share in at)
    return view, f"{round(high * aspect)},{high}"


def browser() -> str:
    found = os.environ.get("CHROME") or shutil.which("chromium")
    found = found or shutil.which("chromium-browser")
    if not found:
        sys.exit("make pictures needs Chromium: apt install chromium (or CHROME=/path/to/it)")
    return found


def screenshot(chrome: str, url: str, target: Path, window: str, profile: Path) -> None:
    """Chromium's screenshot of the page. Decoding a textured model's pictures runs
    outside Chromium's virtual time, so a blank picture (the page still loading when the
    budget ended) is taken again with a larger budget."""
    for budget in (15_000, 60_000, 180_000):
        subprocess.run(
            [
                chrome,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--use-gl=swiftshader",
                "--enable-unsafe-swiftshader",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--no-first-run",
                "--hide-scrollbars",
                f"--user-data-dir={profile}",
                f"--window-size={window}",
                f"--virtual-time-budget={budget}",
                f"--screenshot={target}",
                url,
            ],
            check=True,
            capture_output=True,
            timeout=600,
        )
        if not _blank(target):
            return
    sys.exit(f"{target}: the page drew nothing in {budget // 1000} s of virtual time")


def _blank(picture: Path) -> bool:
    """Whether a screenshot shows nothing drawn yet: its lower third one flat colour (the
    haze below the sky's horizon; the ground, under every view, comes with the model).
    The whole picture's spread no longer tells: the sky has clouds before a model comes."""
    from PIL import Image, ImageStat

    with Image.open(picture) as image:
        lower = image.convert("L").crop((0, image.height * 2 // 3, image.width, image.height))
        return bool(ImageStat.Stat(lower).stddev[0] < 2.0)


def svg_size(svg: Path) -> str:
    text = svg.read_text(encoding="utf-8")
    width = text.split('width="', 1)[1].split('"', 1)[0]
    height = text.split('height="', 1)[1].split('"', 1)[0]
    return f"{round(float(width))},{round(float(height))}"


# the 50-building city block: camera (around, up, zoom, x, y) of each picture
CITY_BLOCK = 50
CITY_VIEWS: dict[str, str] = {
    "front": "0",  # the viewer picks the elevation at which the buildings fill the picture
    "oblique": "35,35",
    "street": "street",  # in one of the district's streets (the viewer finds it)
}


def city_pictures(chrome: str, out: Path, suffix: str = "") -> None:
    """The generated demo district's first :data:`CITY_BLOCK` buildings built with
    ``facade city`` and shown in ``facade view``'s page from the front, 35° up and at
    street level: ``city-block-VIEW{suffix}.png``."""
    from facadecli.city.demo import write_demo

    facade = [sys.executable, "-m", "facadecli"]  # PYTHONPATH=SOURCE: another checkout's
    manifest = write_demo(out / "district", ROOT / "specs", 4)
    city = out / "city"
    limit = ["--limit", str(CITY_BLOCK)]
    run = partial(subprocess.run, check=True, capture_output=True)
    run([*facade, "city", str(manifest), "-o", str(city), *limit])
    page = out / "city.html"
    run([*facade, "view", str(city), "-o", str(page)])
    for name, view in CITY_VIEWS.items():
        target = TARGET / f"city-block-{name}{suffix}.png"
        screenshot(chrome, f"{page.as_uri()}?bare&view={view}", target, WINDOW, out / "profile")
        print(f"{target.relative_to(ROOT)}: {target.stat().st_size // 1024} KB")


# the look of every example and of the city block from three cameras, one strip each in
# docs/pictures/look (issue 35): front, 35° oblique, street level (around, up, zoom, x, y)
LOOK = TARGET / "look"
LOOK_VIEWS = ("0,6", "35,10", "street,25")
LOOK_TILE = (600, 373)  # each view's size in a strip (its screenshot is WINDOW, downscaled)


def strip(shots: list[Path], target: Path) -> None:
    """The views side by side in one picture, each downscaled to :data:`LOOK_TILE`."""
    from PIL import Image

    width, height = LOOK_TILE
    joined = Image.new("RGB", (width * len(shots), height), "white")
    for index, shot in enumerate(shots):
        with Image.open(shot) as image:
            tile = image.convert("RGB").resize(LOOK_TILE, Image.Resampling.LANCZOS)
        joined.paste(tile, (index * width, 0))
    joined.save(target, optimize=True)
    print(f"{target}: {target.stat().st_size // 1024} KB")


def look_pictures(chrome: str, out: Path, suffix: str = "") -> None:
    """Every example spec (specs/*.yaml) and the 50-building city block from the front, 35°
    oblique and at street level (:data:`LOOK_VIEWS`), a strip each:
    ``look/NAME{suffix}.png``; LOOK=name,name... takes those alone."""
    from facadecli.city.demo import write_demo

    LOOK.mkdir(parents=True, exist_ok=True)
    facade = [sys.executable, "-m", "facadecli"]
    run = partial(subprocess.run, check=True, capture_output=True)
    only = [name for name in os.environ.get("LOOK", "").split(",") if name]
    pages = {}
    for spec in sorted((ROOT / "specs").glob("*.yaml")):
        if not only or spec.stem in only:
            run([*facade, "solve", str(spec), "-o", str(out), "-f", "html"])
            pages[spec.stem] = out / f"{spec.stem}.html"
    if not only or "city-block" in only:
        manifest = write_demo(out / "district", ROOT / "specs", 4)
        city = out / "city"
        run([*facade, "city", str(manifest), "-o", str(city), "--limit", str(CITY_BLOCK)])
        run([*facade, "view", str(city), "-o", str(out / "city-block.html")])
        pages["city-block"] = out / "city-block.html"
    for name, page in pages.items():
        views = LOOK_VIEWS if name != "city-block" else tuple(CITY_VIEWS.values())
        shots = []
        for index, view in enumerate(views):
            shot = out / f"{name}-{index}.png"
            screenshot(chrome, f"{page.as_uri()}?bare&view={view}", shot, WINDOW, out / "profile")
            shots.append(shot)
        strip(shots, LOOK / f"{name}{suffix}.png")


def cesium_picture(out: Path) -> None:
    """The tests' OSM district (``tests/osm_district.py``: 36 buildings near Helsinki, one
    of each case S3DB names) built with ``facade city --3dtiles`` and its tiles opened in
    CesiumJS in headless Chromium with no network (``tests/cesium.py``, the page the
    CesiumJS test opens): ``city-3dtiles-cesium.png``. Needs npm ``cesium`` in
    .venv/node (``make test`` installs it) or FACADE_CESIUM."""
    sys.path.insert(0, str(ROOT))  # the tests' district and page
    from PIL import Image

    from tests import cesium
    from tests.osm_district import write_district

    if not cesium.installed():
        sys.exit(f"no CesiumJS in {cesium.CESIUM}: make test installs it (or set FACADE_CESIUM)")
    district = write_district(out / "district.osm")
    run = out / "district"
    facade = [sys.executable, "-m", "facadecli"]
    subprocess.run(
        [*facade, "city", str(district), "--3dtiles", "-j", "2", "-o", str(run)],
        check=True,
        capture_output=True,
    )
    missing: list[str] = []
    shot, dom = cesium.open_tiles(run, out, [], missing)
    title = cesium.title(dom)
    if not title.startswith("loaded"):
        sys.exit(f"CesiumJS did not load the district's tiles: {title}")
    if unanswered := [path for path in missing if not path.endswith("favicon.ico")]:
        sys.exit(f"CesiumJS asked for what the run did not write: {unanswered}")
    target = TARGET / "city-3dtiles-cesium.png"
    with Image.open(shot) as image:
        image.convert("RGB").save(target, optimize=True)
    print(f"{target.relative_to(ROOT)}: {title}, {target.stat().st_size // 1024} KB")


SWATCH = 192  # pixels a side of one material on the library's contact sheet


def material_sheet(target: Path) -> None:
    """The material library's contact sheet: each material's pictures at 256 px, two by
    two copies (so a seam would show), lit from the upper left through its normal map
    and occlusion: colour x (0.3 + 0.7 n.l) x occlusion. No browser needed."""
    import numpy as np
    from PIL import Image, ImageDraw

    from facadecli.materials import LIBRARY, TILES, images

    light = np.array([-0.5, 0.5, 0.7]) / np.linalg.norm([-0.5, 0.5, 0.7])
    columns, label = 4, 18
    rows = -(-len(LIBRARY) // columns)
    sheet = Image.new("RGB", (columns * SWATCH, rows * (SWATCH + label)), "white")
    draw = ImageDraw.Draw(sheet)
    for index, (name, material) in enumerate(LIBRARY.items()):
        drawn = images(material.model_copy(update={"resolution": 256}))
        colour = np.asarray(drawn.base_colour, dtype=float) / 255.0
        normal = np.asarray(drawn.normal, dtype=float) / 127.5 - 1.0
        occlusion = np.asarray(drawn.orm, dtype=float)[..., 0] / 255.0
        lit = colour * ((0.3 + 0.7 * np.clip(normal @ light, 0, 1)) * occlusion)[..., None]
        four = np.tile(lit, (2, 2, 1))
        swatch = Image.fromarray(np.round(np.clip(four, 0, 1) * 255).astype(np.uint8))
        swatch = swatch.resize((SWATCH, SWATCH), Image.Resampling.LANCZOS)
        x, y = (index % columns) * SWATCH, (index // columns) * (SWATCH + label)
        sheet.paste(swatch, (x, y + label))
        draw.text((x + 4, y + 3), f"{name}: 2 x 2 tiles of {TILES[name]} m", fill="black")
    sheet.save(target, optimize=True)


def main(names: list[str]) -> None:
    """The pictures named (all without names): a spec's from :data:`PICTURES` or
    :data:`PARTS`, ``materials`` (the library's sheet), ``city`` (the city block's three views;
    SUFFIX=-before names them for the record of older code), ``look`` (every example
    and the city block from three cameras, SUFFIX likewise) or ``cesium`` (the tests' OSM
    district's 3D Tiles in CesiumJS)."""
    everything = not names
    if everything or "materials" in names:
        target = TARGET / "materials.png"
        material_sheet(target)
        print(f"{target.relative_to(ROOT)}: {target.stat().st_size // 1024} KB")
    chosen = [name for name in names if name not in ("materials", "city", "look", "cesium")]
    if not (everything or chosen or {"city", "look", "cesium"} & set(names)):
        return
    chrome = browser()
    TARGET.mkdir(parents=True, exist_ok=True)
    if everything or "look" in names:
        with tempfile.TemporaryDirectory() as scratch:
            look_pictures(chrome, Path(scratch), os.environ.get("SUFFIX", ""))
    if everything or "city" in names:
        with tempfile.TemporaryDirectory() as scratch:
            city_pictures(chrome, Path(scratch), os.environ.get("SUFFIX", ""))
    if everything or "cesium" in names:
        with tempfile.TemporaryDirectory() as scratch:
            cesium_picture(Path(scratch))
    if not (everything or chosen):
        return
    facade = Path(sys.executable).parent / "facade"
    chosen = chosen or [*PICTURES, *PARTS]
    with tempfile.TemporaryDirectory() as scratch:
        out = Path(scratch)
        specs = {(PICTURES.get(name) or PARTS[name])[0] for name in chosen}
        for spec in sorted(specs):
            path = ROOT / "specs" / f"{spec}.yaml"
            subprocess.run(
                [str(facade), "solve", str(path), "-o", str(out), "-f", "html,svg,json"],
                check=True,
                capture_output=True,
            )
        for name in chosen:
            if name in PARTS:
                spec, shows, share, around, up = PARTS[name]
                layout = json.loads((out / f"{spec}.layout.json").read_text(encoding="utf-8"))
                what, (view, window) = "model", part_view(layout, shows, share, around, up)
            else:
                (spec, what, view), window = PICTURES[name], WINDOW
            target = TARGET / f"{name}.png"
            if what == "elevation":
                svg = out / f"{spec}.svg"
                screenshot(chrome, svg.as_uri(), target, svg_size(svg), out / "profile")
            else:
                url = f"{(out / f'{spec}.html').as_uri()}?bare&view={view}"
                screenshot(chrome, url, target, window, out / "profile")
            print(f"{target.relative_to(ROOT)}: {target.stat().st_size // 1024} KB")


if __name__ == "__main__":
    main(sys.argv[1:])
