"""``--format html``: one self-contained page a run, the model with orbit controls beside
the elevation, read in a real browser where one is installed."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from facadecli import load_spec, solve
from facadecli.export import OutputOptions, write_outputs

ROOT = Path(__file__).resolve().parent.parent
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")


def _page(tmp_path: Path) -> Path:
    layout = solve(load_spec(ROOT / "specs" / "townhouse.yaml"))
    (path,) = write_outputs(layout, tmp_path, ["html"], OutputOptions())
    return path


def test_the_page_holds_everything_it_shows(tmp_path: Path) -> None:
    text = _page(tmp_path).read_text()
    assert '<script type="importmap">' in text and "data:text/javascript;base64," in text
    assert '<script id="glb" type="application/octet-stream">Z2xURg' in text  # "glTF"
    assert "<svg" in text and "MIT licence" in text
    assert not re.search(r"(src|href)=[\"']https?://", text)  # nothing fetched at view time


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_browser_shows_the_model(tmp_path: Path) -> None:
    from PIL import Image, ImageStat

    page = _page(tmp_path)
    flags = [
        "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader",
        "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
        f"--user-data-dir={tmp_path / 'profile'}", "--window-size=1000,600",
        "--virtual-time-budget=10000",
    ]  # fmt: skip
    shot = tmp_path / "shot.png"
    run = [str(BROWSER), *flags]
    subprocess.run([*run, f"--screenshot={shot}", page.as_uri()], timeout=120, check=False)
    dom = subprocess.run(
        [*run, "--dump-dom", page.as_uri()], timeout=120, capture_output=True, text=True
    )
    assert "<title>townhouse</title>" in dom.stdout  # the model loaded ("loading: " is gone)
    with Image.open(shot) as image:
        model = image.convert("L").crop((0, 0, image.width * 3 // 5, image.height))
        assert ImageStat.Stat(model).stddev[0] > 10  # not a blank canvas
