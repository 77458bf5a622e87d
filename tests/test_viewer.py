"""``--format html``: one self-contained page a run, the model with orbit controls beside
the elevation; ``facade view``: one page of every model in a folder. Both read in a real
browser where one is installed."""

from __future__ import annotations

import base64
import json
import re
import shutil
import sys
from html import unescape
from pathlib import Path
from typing import Any
from urllib.parse import quote

import pytest

from facadecli import load_spec, solve
from facadecli.city.demo import write_demo
from facadecli.city.folders import building_file
from facadecli.cli import main
from facadecli.export import OutputOptions, write_outputs
from facadecli.viewer import VIEWER, gallery
from tests.browser import BROWSER, browse
from tests.running import facade, facade_output, files

ROOT = Path(__file__).resolve().parent.parent


def _page(tmp_path: Path) -> Path:
    layout = solve(load_spec(ROOT / "specs" / "townhouse.yaml"))
    (path,) = write_outputs(layout, tmp_path, ["html"], OutputOptions())
    return path


def _shown(tmp_path: Path, text: str, query: str) -> tuple[Path, str]:
    """The page of a spec (its YAML ``text``) solved, in the browser with ``query`` (its
    view): the screenshot and the page's DOM."""
    spec = tmp_path / "spec.yaml"
    spec.write_text(text)
    layout = solve(load_spec(spec))
    (path,) = write_outputs(layout, tmp_path, ["html"], OutputOptions())
    return browse(tmp_path, path.as_uri() + query)


def _district_page(folder: Path, manifest: Path) -> Path:
    """The page of the city ``facade city`` builds from ``manifest`` into ``folder``/city
    (``facade view``, ``folder``/city.html)."""
    code, _, err = facade_output("city", manifest, "-o", folder / "city")
    assert code == 0, err
    page = folder / "city.html"
    code, _, err = facade_output("view", folder / "city", "-o", page)
    assert code == 0, err
    return page


def _district_shown(tmp_path: Path, page: Path, query: str, shows: str) -> tuple[Path, Any]:
    """A district's ``page`` in the browser with ``query`` (its view): the screenshot (in
    ``tmp_path``) and what the page reports in its ``data-<shows>`` attribute."""
    shot, dom = browse(tmp_path, page.as_uri() + query)
    found = re.search(rf'data-{shows}="([^"]+)"', dom)
    assert found, f"the page reports no {shows}"
    return shot, json.loads(unescape(found.group(1)))


def test_the_page_holds_everything_it_shows(tmp_path: Path) -> None:
    text = _page(tmp_path).read_text()
    assert '<script type="importmap">' in text and "data:text/javascript;base64," in text
    assert '<script id="glb" type="application/octet-stream">Z2xURg' in text  # "glTF"
    assert "<svg" in text and "MIT licence" in text
    assert "three/addons/postprocessing/GTAOPass.js" in text  # ambient occlusion, bundled
    assert not re.search(r"(src|href)=[\"']https?://", text)  # nothing fetched at view time


def _drawn(shot: Path, left: float, right: float) -> bool:
    """Whether the screenshot's columns from ``left`` to ``right`` (fractions of its width)
    hold a picture, not a blank canvas."""
    from PIL import Image, ImageStat

    with Image.open(shot) as image:
        box = (int(image.width * left), 0, int(image.width * right), image.height)
        return bool(ImageStat.Stat(image.convert("L").crop(box)).stddev[0] > 10)


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_browser_shows_the_model(tmp_path: Path) -> None:
    shot, dom = browse(tmp_path, _page(tmp_path).as_uri())
    assert "<title>townhouse</title>" in dom  # the model loaded ("loading: " is gone)
    assert _drawn(shot, 0, 3 / 5)


def _lit(shot: Path) -> tuple[float, int]:
    """In a screenshot of a model alone (``?bare``) standing on the ground: the spread of
    brightness across the model's columns, and how many pixels of the ground right of the
    model are darker than the haze behind it by more than a tenth (its shadow, the sun
    being on the left)."""
    from PIL import Image, ImageStat

    with Image.open(shot) as image:
        grey = image.convert("L")
    haze = grey.getpixel((2, 2))
    assert isinstance(haze, int)
    band = grey.crop((0, 0, grey.width, grey.height // 4))  # above the ground: model or haze
    darkest = [min(band.crop((x, 0, x + 1, band.height)).tobytes()) for x in range(band.width)]
    columns = [x for x, value in enumerate(darkest) if value < haze - 12]
    assert columns, "no model drawn"
    model = grey.crop((min(columns), 0, max(columns) + 1, grey.height))
    beside = grey.crop((max(columns) + 8, grey.height // 2, grey.width, grey.height))
    shaded = sum(1 for value in beside.tobytes() if value < haze - 25)
    return ImageStat.Stat(model).stddev[0], shaded


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
@pytest.mark.parametrize("example", ["townhouse", "shop-front"])
def test_the_model_is_lit_and_shades_the_ground(tmp_path: Path, example: str) -> None:
    """A sun from the front left: the walls, reveals and glass read in light and shade, and
    the building's shadow darkens the ground beside it (the old viewer's flat light on a
    plain backdrop had neither)."""
    layout = solve(load_spec(ROOT / "specs" / f"{example}.yaml"))
    (path,) = write_outputs(layout, tmp_path, ["html"], OutputOptions())
    shot, dom = browse(tmp_path, path.as_uri() + "?bare&view=0,10,1,0.5,0.5")
    assert f"<title>{example}</title>" in dom
    spread, shaded = _lit(shot)
    assert spread > 10
    assert shaded > 2000  # of 1000 x 600; the old viewer's backdrop: none


# ``facade view``: a gallery of a folder's models


@pytest.fixture(scope="module")
def varied(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder written by ``facade vary``: 4 variants (glb + svg; at 8 m, the second is
    drawn proportions) and a contact sheet."""
    folder = tmp_path_factory.mktemp("vary") / "out"
    argv = sys.argv
    sys.argv = ["facade", "vary", str(ROOT / "specs" / "residential-house.yaml")]
    sys.argv += ["--widths", "8,12", "--count", "2", "--seed", "7", "-f", "glb,svg"]
    sys.argv += ["-o", str(folder)]
    try:
        with pytest.raises(SystemExit) as stop:
            main()
    finally:
        sys.argv = argv
    assert stop.value.code in (0, None)
    assert len(list(folder.glob("*.glb"))) == 4 and (folder / "contact-sheet.svg").exists()
    return folder


def test_view_lists_every_model_of_a_vary_folder(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path
) -> None:
    page = tmp_path / "page.html"
    code, out, err = facade(capsys, "view", varied, "-o", page)
    assert code == 0, err
    assert out.strip() == f"4 models -> {page}"
    text = page.read_text()
    names = re.findall(r'data-name="([^"]+)"', text)
    assert names == [  # every model once, numbers in order (8 before 12)
        "residential-house-8x3-0",
        "residential-house-8x3-1",
        "residential-house-12x3-0",
        "residential-house-12x3-1",
    ]
    for index, name in enumerate(names):  # each glb and its elevation, byte for byte
        glb = re.search(rf'<script id="glb-{index}" type="application/octet-stream">([^<]*)<', text)
        assert glb and base64.b64decode(glb[1]) == (varied / f"{name}.glb").read_bytes()
        svg = base64.b64encode((varied / f"{name}.svg").read_bytes()).decode()
        assert f'<img src="data:image/svg+xml;base64,{svg}"' in text
    assert "contact-sheet" not in text
    assert '<script type="importmap">' in text and "MIT licence" in text
    assert not re.search(r"(src|href)=[\"']https?://", text)  # nothing fetched at view time


def test_view_writes_index_html_and_the_same_bytes_each_time(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path
) -> None:
    folder = tmp_path / "copy"
    shutil.copytree(varied, folder)
    code, out, _ = facade(capsys, "view", folder)
    assert code == 0 and out.strip() == f"4 models -> {folder / 'index.html'}"
    first = (folder / "index.html").read_bytes()
    assert facade(capsys, "view", folder)[0] == 0
    assert (folder / "index.html").read_bytes() == first
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]  # no temporary left


@pytest.mark.parametrize("sharded", [True, False])  # buildings/<shard>/, or as before them
def test_view_shows_a_citys_buildings_when_the_folder_has_no_other_model(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path, sharded: bool
) -> None:
    model = varied / "residential-house-8x3-0.glb"
    for name in ("b10", "b9", "b11"):
        path = tmp_path / (str(building_file(name)) if sharded else f"buildings/{name}.glb")
        path.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(model, path)
    code, out, err = facade(capsys, "view", tmp_path)
    assert code == 0 and out.strip() == f"3 models -> {tmp_path / 'index.html'}", err
    text = (tmp_path / "index.html").read_text()
    assert re.findall(r'data-name="([^"]+)"', text) == ["b9", "b10", "b11"]
    assert "3 models in buildings/" in text and "<img" not in text  # no elevations
    shutil.copy(varied / "residential-house-12x3-0.glb", tmp_path / "district.glb")
    assert facade(capsys, "view", tmp_path)[0] == 0  # the merged model, not the buildings
    text = (tmp_path / "index.html").read_text()
    assert re.findall(r'data-name="([^"]+)"', text) == ["district"]


def test_view_refuses_a_folder_without_models(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path
) -> None:
    code, out, err = facade(capsys, "view", tmp_path / "missing")
    assert code == 2 and out == ""
    assert f"{tmp_path / 'missing'}: error: no such folder" in err and "facade solve" in err
    empty = tmp_path / "empty"
    empty.mkdir()
    shutil.copy(varied / "contact-sheet.svg", empty)  # an elevation is not a model
    code, _, err = facade(capsys, "view", empty)
    assert code == 2 and f"{empty}: error: no models (.glb files)" in err
    assert "facade solve" in err and files(empty) == ["contact-sheet.svg"]
    code, _, err = facade(capsys, "view", empty / "contact-sheet.svg")
    assert code == 2 and "not a folder" in err


def test_view_refuses_more_than_the_page_limit(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    varied: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    total = sum(p.stat().st_size for p in varied.iterdir() if p.suffix in (".glb", ".svg"))
    total -= (varied / "contact-sheet.svg").stat().st_size  # no model of its stem
    monkeypatch.setattr(gallery, "GALLERY_BYTES_MAX", total - 1)
    code, out, err = facade(capsys, "view", varied, "-o", tmp_path / "page.html")
    assert code == 2 and out == ""
    assert f"more than {total - 1:,} bytes" in err and "GALLERY_BYTES_MAX" in err
    assert "fewer models" in err and files(tmp_path) == []
    monkeypatch.setattr(gallery, "GALLERY_BYTES_MAX", total)  # exactly the limit is fine
    assert facade(capsys, "view", varied, "-o", tmp_path / "page.html")[0] == 0


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_browser_shows_the_gallery(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path
) -> None:
    page = tmp_path / "gallery.html"
    assert facade(capsys, "view", varied, "-o", page)[0] == 0
    shot, dom = browse(tmp_path, page.as_uri() + "#" + quote("residential-house-12x3-1"))
    assert f"<title>{varied.name}</title>" in dom  # a model loaded ("loading: " is gone)
    assert '<h3 id="name">residential-house-12x3-1</h3>' in dom  # the one the address names
    assert re.findall(r'aria-pressed="true" title="([^"]+)"', dom) == ["residential-house-12x3-1"]
    assert '<img src="data:image/svg+xml;base64,' in dom.split('id="elevation"')[1]
    assert '<p id="status">drag to orbit, scroll to zoom</p>' in dom  # not "cannot show"
    assert _drawn(shot, 0.25, 0.65)  # the viewer, between the list and the elevation


# what a page inlines: regular files inside the folder, each what its name says


def test_view_leaves_out_links_out_of_the_folder_and_mislabelled_files(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, varied: Path
) -> None:
    name = "residential-house-8x3-0"
    glb, svg = (varied / f"{name}.glb").read_bytes(), (varied / f"{name}.svg").read_bytes()
    (tmp_path / "house.glb").write_bytes(glb)
    (tmp_path / "house.svg").write_bytes(svg)
    outside = tmp_path.parent / f"{tmp_path.name}-secret.txt"
    outside.write_text("root:x:0:0:leaked-7c1e\n")
    (tmp_path / "shadow.glb").write_bytes(glb)  # a real model whose elevation links out
    (tmp_path / "shadow.svg").symlink_to(outside)
    (tmp_path / "passwd.glb").symlink_to(outside)
    (tmp_path / "copy.glb").symlink_to(tmp_path / "house.glb")  # a link inside: fine
    (tmp_path / "text.glb").write_text("root:x:0:0:leaked-7c1e\n")  # not glTF
    (tmp_path / "text.svg").write_text("root:x:0:0:leaked-7c1e\n")  # not read: no model to show
    (tmp_path / "dtd.glb").write_bytes(glb)
    (tmp_path / "dtd.svg").write_text(
        f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file://{outside}">]>'
        '<svg xmlns="http://www.w3.org/2000/svg"><text>&x;</text></svg>'
    )
    (tmp_path / "folder.glb").mkdir()
    page = tmp_path / "page.html"
    code, out, err = facade(capsys, "view", tmp_path, "-o", page)
    assert code == 0 and out.strip() == f"4 models -> {page} (5 files left out)", err
    text = page.read_text()
    assert re.findall(r'data-name="([^"]+)"', text) == ["copy", "dtd", "house", "shadow"]
    leaked = outside.read_bytes()
    assert "leaked-7c1e" not in text and base64.b64encode(leaked).decode() not in text
    assert text.count("<img") == 1  # house's: the others have none or it is left out
    for file, why in [
        ("shadow.svg", f"a link to {outside.resolve()}, outside the folder"),
        ("passwd.glb", "outside the folder"),
        ("text.glb", "not a glTF binary"),
        ("dtd.svg", "declares a document type (DTD)"),
        ("folder.glb", "not a regular file"),
    ]:
        line = rf"{re.escape(str(tmp_path / file))}: warning: left out: .*{re.escape(why)}"
        assert re.search(line, err), (file, err)


def test_view_refuses_a_folder_whose_every_model_is_left_out(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "shadow.glb").symlink_to("/etc/passwd")
    (tmp_path / "empty.glb").write_bytes(b"")
    code, out, err = facade(capsys, "view", tmp_path)
    assert code == 2 and out == "" and files(tmp_path) == ["empty.glb", "shadow.glb"]
    assert f"{tmp_path}: error: no model to show" in err
    assert f"{tmp_path / 'shadow.glb'}: error: left out: a link to /etc/passwd" in err


# one wall 10 x 6 m (the screenshot's proportions) with one window 3 x 3 m in its middle
PANE_SPEC = """
version: 1
name: pane
canvas: {width: 10.0, height: 6.0}
symbol_defaults: {opaque: true}
symbols:
  A: {size: 3.5, label: wall}
  B: {size: 3.0, label: window}
  P: {size: 1.5, label: plinth}
  Q: {size: 3.0, label: storey}
patterns: {across: "A B A", up: "P Q P"}
layers: [{name: base, x: across, y: up}]
shapes:
  - {match: {x: B, y: Q}, material: glass, depth: -0.08, thickness: 0.02}
materials:
  plaster: {library: render, color: "#c9a27e", resolution: 64}
  glass: {library: float-glass, resolution: 64}
defaults: {mesh: box, material: plaster, thickness: 0.2}
"""


def _mean_grey(shot: Path, box: tuple[float, float, float, float]) -> float:
    """The mean grey (0..255) of the screenshot's part ``box`` (left, top, right, bottom
    as fractions of its width and height)."""
    from PIL import Image, ImageStat

    with Image.open(shot) as image:
        grey = image.convert("L")
        left, top, right, bottom = box
        part = (left * grey.width, top * grey.height, right * grey.width, bottom * grey.height)
        return float(ImageStat.Stat(grey.crop(tuple(round(edge) for edge in part))).mean[0])


@pytest.fixture(scope="module")
def pane_square_on(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """:data:`PANE_SPEC` seen square on (``?bare&view=0,0``): the screenshot and the DOM,
    one load of the page for the two tests that read that picture (each loaded it)."""
    return _shown(tmp_path_factory.mktemp("pane"), PANE_SPEC, "?bare&view=0,0")


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_glass_reads_neither_black_nor_white_nor_as_the_wall(
    pane_square_on: tuple[Path, str],
) -> None:
    """A window seen square on, framed by the model's box (which fills the 1000 x 600
    screenshot, centred): its pane mirrors the sky and the street, so its mean grey lies
    in a band well inside 0..255 and apart from the wall's. Glass blended by its fallback
    alpha over a dark ground read about 37 (black); a pane as pale as the wall, or blown
    out, fails too."""
    shot, dom = pane_square_on
    assert "<title>pane</title>" in dom
    # the window spans 0.35..0.65 of the wall across and 0.25..0.75 up; the wall fills
    # 1/1.08 of the picture, so 0.42..0.58 of it is pane and 0.12..0.2 wall
    pane = _mean_grey(shot, (0.42, 0.42, 0.58, 0.58))
    wall = _mean_grey(shot, (0.12, 0.4, 0.2, 0.6))
    assert 60 < pane < 170
    assert abs(wall - pane) > 25


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_glass_seen_at_35_degrees_mirrors_the_street_not_a_slate(tmp_path: Path) -> None:
    """The window of :data:`PANE_SPEC` seen from 35° round and 10° up: the pane mirrors
    what lies 10° below the horizon, the houses across the street (their fronts and their
    windows), at the reflectance of a double-glazed unit, so it is lighter than a dark
    slate and shows something. Measured on the pane's middle (0.33..0.45 across,
    0.32..0.6 up): mean grey 66.3, spread (standard deviation) 4.3 when the environment
    held plain paving there and the glass reflected one face's 4%; 83.5 and 7.4 with
    the reflection (square on, 0.42..0.58: 65.7 and 7.1 before, 88.2 and 12.0); 66.9
    since glass transmits all it does not reflect (transmission 1: no white veil of
    diffuse light over the room), its spread telling the reflection from a slate."""
    from PIL import Image, ImageStat

    shot, dom = _shown(tmp_path, PANE_SPEC, "?bare&view=35,10")
    assert "<title>pane</title>" in dom
    with Image.open(shot) as image:
        grey = image.convert("L")
        width, height = grey.size
        box = (round(0.33 * width), round(0.32 * height), round(0.45 * width), round(0.6 * height))
        pane = ImageStat.Stat(grey.crop(box))
    assert 55 < pane.mean[0] < 170, pane.mean[0]
    assert pane.stddev[0] > 5.8, pane.stddev[0]


def _pane_spread(shot: Path) -> float:
    """The spread (standard deviation of grey, 0..255) over the 3 x 3 m window of
    :data:`PANE_SPEC` seen square on: 0.38..0.62 across, 0.3..0.7 up (the window spans
    0.36..0.64 and 0.27..0.73 of the picture)."""
    from PIL import Image, ImageStat

    with Image.open(shot) as image:
        grey = image.convert("L")
        width, height = grey.size
        box = (round(0.38 * width), round(0.3 * height), round(0.62 * width), round(0.7 * height))
        return float(ImageStat.Stat(grey.crop(box)).stddev[0])


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_pane_shows_the_room_behind_it(tmp_path: Path, pane_square_on: tuple[Path, str]) -> None:
    """The window of :data:`PANE_SPEC` square on, behind it the dark recess (the built-in
    interior) and then a room of the library's ``rooms``: through the glass, the room's
    back wall (1.2 m back) lifts the pane's grey over the dark recess's. Mean grey over
    the pane, headless Chromium with SwiftShader, one shot each: 80.0 with the dark
    recess, 110.9 with the room (140.4 since the rooms are brighter by day). (Its
    spread told them apart while the room was a perspective picture on the plate, 12.6
    and 20.3; a room box seen square on shows its back wall, and the spread is the
    reflection's: 17.7 and 17.4.)"""
    with_room = PANE_SPEC.replace("materials:\n", "materials:\n  interior: {library: rooms}\n")
    assert "<title>pane</title>" in pane_square_on[1]
    dark = _mean_grey(pane_square_on[0], (0.38, 0.3, 0.62, 0.7))
    room = _mean_grey(_shown(tmp_path, with_room, "?bare&view=0,0")[0], (0.38, 0.3, 0.62, 0.7))
    assert room > dark + 15, (dark, room)


WALLS_SPEC = """
version: 1
name: walls
canvas: {width: 12.0, height: 6.0}
symbol_defaults: {opaque: true}
symbols:
  A: {size: 6.0, label: wall}
  B: {size: 6.0, label: wall}
  Q: {size: 6.0, label: storey}
patterns: {across: "A B", up: "Q"}
layers: [{name: base, x: across, y: up}]
shapes:
  - {match: {x: B, y: Q}, material: brick}
materials:
  plaster: {color: "#e4d6bd", roughness: 0.9}
  brick: {color: "#a0522d", roughness: 0.9}
defaults: {mesh: box, material: plaster, thickness: 0.2}
"""


def _hue_and_saturation(shot: Path, box: tuple[float, float, float, float]) -> tuple[float, float]:
    """The median hue (degrees) and saturation (HSV, 0..1) of the pixels of the
    screenshot's part ``box`` (left, top, right, bottom as fractions of its size)."""
    import colorsys
    import statistics

    from PIL import Image

    with Image.open(shot) as image:
        rgb = image.convert("RGB")
        left, top, right, bottom = box
        part = rgb.crop(
            (
                round(left * rgb.width),
                round(top * rgb.height),
                round(right * rgb.width),
                round(bottom * rgb.height),
            )
        )
        data = part.tobytes()
    pixels = [
        colorsys.rgb_to_hsv(data[at] / 255, data[at + 1] / 255, data[at + 2] / 255)
        for at in range(0, len(data), 3)
    ]
    return (
        statistics.median(hue for hue, _, _ in pixels) * 360,
        statistics.median(saturation for _, saturation, _ in pixels),
    )


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_lit_wall_keeps_its_colours_hue_and_saturation(tmp_path: Path) -> None:
    """Two sunlit walls seen square on, a pale plaster (#e4d6bd: hue 38.5 degrees,
    saturation 0.171) and a brick red (#a0522d: 19.3, 0.719), render in their own hue and
    saturation (each pixel's, the median over the middle of the wall): the light is white
    (the sun, and the sky's light on a wall balanced to grey) and the tone mapping
    (Khronos PBR Neutral) keeps a colour's hue and saturation. ACES filmic tone mapping
    under a slightly blue light drained the plaster to 0.070 (near white)."""
    shot, dom = _shown(tmp_path, WALLS_SPEC, "?bare&view=0,0")
    assert "<title>walls</title>" in dom
    # the walls fill 1/1.08 of the picture's width, plaster left, brick right
    for box, hue, saturation in [
        ((0.15, 0.3, 0.4, 0.7), 38.5, 0.171),
        ((0.6, 0.3, 0.85, 0.7), 19.3, 0.719),
    ]:
        seen_hue, seen_saturation = _hue_and_saturation(shot, box)
        assert abs(seen_hue - hue) < 4, (seen_hue, hue)
        assert abs(seen_saturation / saturation - 1) < 0.15, (seen_saturation, saturation)


def test_the_page_lights_the_model_by_the_sky_it_shows() -> None:
    """One sky is the backdrop and, prefiltered, the light and what glass mirrors; the sun
    that casts the shadows shines from the direction of the sky's sun (its disc and glow)."""
    assert "uniforms: {sky: {value: daylight.backdrop}" in VIEWER  # the backdrop's dome
    assert "scene.environment = daylight.environment;" in VIEWER
    assert VIEWER.count("sunDirection") >= 4  # the disc, the glow, the clouds' light, the sun


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_the_sky_behind_a_model_is_blue_and_has_clouds(tmp_path: Path) -> None:
    """A wall seen level from twice its fit's distance: the top fifth of the picture is
    sky, not one flat colour (its clouds and its gradient: a spread of 8.6 greys,
    measured) and bluer at the top than lower down (blue less red: 9.8 in the top 5% of
    the picture, 6.7 at 15-20%). The flat grey backdrop before: a spread of 0, 9.0 and
    9.0."""
    from PIL import Image, ImageStat

    shot, dom = _shown(tmp_path, WALLS_SPEC, "?bare&view=0,0,0.5")
    assert "<title>walls</title>" in dom

    def blueness(image: Image.Image, top: float, bottom: float) -> float:
        band = image.crop((0, round(top * image.height), image.width, round(bottom * image.height)))
        red, _, blue = ImageStat.Stat(band).mean
        return float(blue - red)

    with Image.open(shot) as image:
        rgb = image.convert("RGB")
        spread = ImageStat.Stat(rgb.crop((0, 0, rgb.width, rgb.height // 5)).convert("L")).stddev[0]
        assert spread > 3, spread
        assert blueness(rgb, 0, 0.05) > blueness(rgb, 0.15, 0.2) + 1.5


@pytest.fixture(scope="module")
def demo_district(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo district of two blocks (``demo/``), built (``city/``) and its page
    (``city.html``): one build for the views of it below, each a load of the page."""
    folder = tmp_path_factory.mktemp("district")
    _district_page(folder, write_demo(folder / "demo", ROOT / "specs", 2))
    return folder


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_districts_street_view_stands_in_a_street_among_its_buildings(
    tmp_path: Path, demo_district: Path
) -> None:
    """``?view=street`` of a district: the eye 1.6 m above the ground in the open between
    the buildings (outside every footprint, a few metres from the nearest), facing several
    of them, which fill the picture: its upper half is mostly buildings, not the backdrop
    (the old street view stood back until the whole district was in view: a row of houses
    on the horizon under a sky filling half the picture)."""
    import json

    from PIL import Image
    from shapely.geometry import Point, shape

    page = demo_district / "city.html"
    shot, street = _district_shown(tmp_path, page, "?bare&view=street", "street")
    georef = json.loads((demo_district / "city" / "demo-district.georef.json").read_text())
    features = json.loads((demo_district / "demo" / "footprints.geojson").read_text())["features"]
    footprints = {f["properties"]["osm_id"]: shape(f["geometry"]) for f in features}
    x, height, z = street["eye"]
    eye = Point(georef["origin"][0] + x, georef["origin"][1] - z)  # glTF x east, z south
    assert abs(height - 1.6) < 0.02  # above the model's foot (its floors' 1 cm slabs)
    assert min(footprint.distance(eye) for footprint in footprints.values()) > 3.0
    assert len(street["seen"]) >= 4 and set(street["seen"]) <= set(footprints)
    with Image.open(shot) as image:
        grey = image.convert("L")
    backdrop = grey.getpixel((grey.width - 1, 0))  # above the houses' roofs: the backdrop
    assert isinstance(backdrop, int)
    upper = grey.crop((0, 0, grey.width, grey.height // 2)).tobytes()
    sky = sum(1 for value in upper if abs(value - backdrop) <= 2) / len(upper)
    assert sky < 0.5


BLANK_SPEC = """
version: 1
name: blank
canvas: {width: 10.0, height: 9.0}
symbols: {A: 1.0, F: 3.0}
patterns: {across: "A^+", up: "F^+"}
layers: [{name: base, x: across, y: up}]
materials: {wall: {color: "#9c4a32", roughness: 0.9}}
defaults: {mesh: box, material: wall, thickness: 0.2}
solver: {tolerance: 0.5}
"""


def _windows_and_blank_walls(folder: Path) -> tuple[Path, set[str]]:
    """A district of generated footprints (metres, a projected CRS): a street of tall
    buildings with blank walls, 12 of them facing each other 12 m apart, the kind of view
    the street camera likes best by the share of the picture it fills; and past an open
    square behind them, a row of four lower houses with windows (the townhouse's façade),
    each 10 m wide with 6 m between them. Returns the manifest and the windowed ids."""
    import json

    features = []
    windowed = set()

    def building(key: str, x: float, y: float, width: float, depth: float, tags: dict) -> None:
        ring = [[x, y], [x + width, y], [x + width, y + depth], [x, y + depth], [x, y]]
        features.append(
            {
                "type": "Feature",
                "properties": {"osm_id": key, **tags},
                "geometry": {"type": "Polygon", "coordinates": [ring]},
            }
        )

    for k in range(6):
        for side, y in enumerate((0.0, 24.0)):
            building(f"blank/{side}{k}", 10.0 * k, y, 10.0, 12.0, {"building": "shed"})
    for k in range(4):
        building(f"house/{k}", 16.0 * k, 70.0, 10.0, 10.0, {"building": "house"})
        windowed.add(f"house/{k}")
    folder.mkdir()
    (folder / "footprints.geojson").write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
                "features": [
                    {**f, "geometry": {**f["geometry"], "coordinates": [
                        [[100000 + x, 400000 + y] for x, y in f["geometry"]["coordinates"][0]]
                    ]}}
                    for f in features
                ],
            }
        )
    )  # fmt: skip
    (folder / "blank.yaml").write_text(BLANK_SPEC)
    manifest = folder / "district.yaml"
    manifest.write_text(
        "version: 1\nname: streets\nfootprints: footprints.geojson\n"
        f"defaults: {{facade: {ROOT / 'specs' / 'townhouse.yaml'}, height: 9.0,"
        " floor_height: 3.0, roof: {type: flat}}\n"
        "rules:\n  - when: {building: shed}\n    facade: blank.yaml\n    height: 15.0\n"
    )
    return manifest, windowed


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_districts_street_view_looks_at_windows_from_a_distance(tmp_path: Path) -> None:
    """``?view=street`` prefers façades with openings to blank walls, and stands back from
    a house rather than fill the picture with it: of a street of tall blank buildings and
    a row of lower windowed houses, the view looks at the houses (they fill most of the
    buildings' share of the picture, their walls seen are windowed), at least two of them,
    none filling more than half of the picture. The old view, scored by the share of the
    picture alone, stood in the blank street."""

    manifest, windowed = _windows_and_blank_walls(tmp_path / "district")
    page = _district_page(tmp_path, manifest)
    _shot, street = _district_shown(tmp_path, page, "?bare&view=street", "street")
    seen = set(street["seen"])
    assert len(seen & windowed) >= 2 and len(seen - windowed) <= len(seen & windowed), seen
    shares = dict(zip(street["seen"], street["shares"], strict=True))
    houses = sum(share for name, share in shares.items() if name in windowed)
    assert houses > 0.6 * sum(shares.values()), shares
    assert max(shares.values()) < 0.5, shares
    assert sum(street["open"]) > 0.5 * houses, street


def _sky_at_the_top(shot: Path) -> tuple[float, float]:
    """The mean blue less red at the top of a screenshot (a thirtieth of its height), and
    the share of the picture's lower half that is asphalt (darker than 70 of 255)."""
    from PIL import Image, ImageStat

    with Image.open(shot) as image:
        rgb = image.convert("RGB")
        top = rgb.crop((0, 0, rgb.width, rgb.height // 30))
        lower = rgb.convert("L").crop((0, rgb.height // 2, rgb.width, rgb.height))
    red, _green, blue = ImageStat.Stat(top).mean
    dark = sum(1 for value in lower.tobytes() if value < 70) / (lower.width * lower.height)
    return blue - red, dark


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_districts_ground_has_streets_trees_and_a_sky_over_the_haze_from_35_degrees(
    tmp_path: Path, demo_district: Path
) -> None:
    """The demo district's ground: paving along the walls, a kerb, asphalt between the
    blocks, no grass (every lot reaches a street; it was a lawn past the outer streets),
    street trees and centre-line dashes; seen from 35° up, the top of the picture is the
    sky's blue over the haze, where it was the haze's cream (blue less red about -13)."""
    page = demo_district / "city.html"
    shot, ground = _district_shown(tmp_path, page, "?bare&view=35,35", "ground")
    assert ground["paving"] > 0.1 and ground["asphalt"] > 0.3  # of the district's box
    assert 0 < ground["kerb"] < 0.1 and ground["grass"] < 0.01
    assert len(ground["trees"]) >= 10 and ground["dashes"] >= 10
    assert len(ground["lamps"]) >= 5  # street lamps along the roads
    blue, asphalt = _sky_at_the_top(shot)
    assert blue > 4  # the sky over the horizon
    assert asphalt > 0.2  # the streets round the district


def _courtyard_block(folder: Path) -> tuple[Path, list[Any], Any]:
    """Generated footprints (metres, a projected CRS) of blank-walled buildings: a closed
    perimeter block 44 m square round a 20 m courtyard, a bar 16 m south of it across a
    street, and a lone building 40 m east across an open square. Returns the manifest,
    the footprints (shapely) and the courtyard."""
    from shapely.geometry import box

    bars = {
        "north": (0, 32, 44, 44), "south": (0, 0, 44, 12), "west": (0, 12, 12, 32),
        "east": (32, 12, 44, 32), "across": (0, -28, 44, -16), "lone": (84, 0, 96, 12),
    }  # fmt: skip
    features = [
        {
            "type": "Feature",
            "properties": {"osm_id": f"way/{key}", "building": "shed"},
            "geometry": {
                "type": "Polygon",
                "coordinates": [
                    [
                        [100000 + x, 400000 + y]
                        for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0))
                    ]
                ],
            },
        }
        for key, (x0, y0, x1, y1) in bars.items()
    ]
    folder.mkdir()
    (folder / "footprints.geojson").write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
                "features": features,
            }
        )
    )
    (folder / "blank.yaml").write_text(BLANK_SPEC)
    manifest = folder / "district.yaml"
    manifest.write_text(
        "version: 1\nname: courtyard\nfootprints: footprints.geojson\n"
        "defaults: {facade: blank.yaml, height: 9.0, floor_height: 3.0, roof: {type: flat}}\n"
    )
    footprints = [box(100000 + x0, 400000 + y0, 100000 + x1, 400000 + y1)
                  for x0, y0, x1, y1 in bars.values()]  # fmt: skip
    return manifest, footprints, box(100012, 400012, 100032, 400032)


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_districts_grass_is_its_courtyard_and_its_trees_stand_on_pavements(
    tmp_path: Path,
) -> None:
    """The ground by what each place is: the closed block's courtyard, which no street
    reaches, is grass inside a 1 m path (18 m square, 324 m²); the street between the
    block and the bar is asphalt; the 40 m gap to the lone building, open to the north and
    south, no walls closing it in, is lawn, not a paved square (about 2,500 m² more
    grass); street trees stand on the pavements, at least 3 m from every wall and none in
    the courtyard; dashes run down the 16 m street."""
    from shapely.geometry import Point

    manifest, footprints, courtyard = _courtyard_block(tmp_path / "district")
    page = _district_page(tmp_path, manifest)
    _shot, ground = _district_shown(tmp_path, page, "?bare&view=35,35", "ground")
    assert 2000 < ground["grass"] * ground["area"] < 3500, ground
    assert ground["asphalt"] > 0.12 and ground["paving"] > 0.05  # streets round the block
    georef = json.loads((tmp_path / "city" / "courtyard.georef.json").read_text())
    trees = [Point(georef["origin"][0] + x, georef["origin"][1] - z) for x, _, z in ground["trees"]]
    assert len(trees) >= 8
    assert all(min(f.distance(tree) for f in footprints) > 3.0 for tree in trees)
    assert not any(courtyard.contains(tree) for tree in trees)
    assert ground["dashes"] >= 3
