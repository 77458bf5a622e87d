"""A page as headless Chromium shows it: a screenshot and the DOM once its scripts ran,
both from one load of the page (one browser started, not one for each)."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Callable, Iterable
from pathlib import Path

BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")

WINDOW = ("--window-size=1000,600",)
# A page that draws on demand (the viewer's) fills a screen of the screenshot's size from
# its first layout: in a window of that size alone, headless Chromium lays the page out
# 1000 x 457 (the window less its toolbars), then resizes it to 1000 x 600 to take the
# screenshot, and the viewer frames and draws its model a second time for the new size
# (its 'resize' event). A district's page took 36-39 s that way and 24-29 s filling the
# screen (the same picture: a mean difference of 0.003-0.012 grey levels, as between
# two runs of either). A page drawing every frame (CesiumJS) keeps the window: filling
# the screen, its test took 61-95 s where it took 16-36 s.
SCREEN = ("--kiosk", "--screen-info={1000x600}", *WINDOW)


def browse(
    folder: Path,
    url: str,
    budgets: Iterable[int] = (120_000, 120_000, 120_000),
    loaded: Callable[[str], bool] = lambda dom: "<title>loading: " not in dom,
    screen: tuple[str, ...] = SCREEN,
) -> tuple[Path, str]:
    """A screenshot (1000 x 600, ``folder``/shot.png) of the page at ``url`` and its DOM
    once its scripts ran. Work outside Chromium's virtual time (decoding a textured
    model's pictures, fetching tiles) may not be done when a budget ends, so a page not
    ``loaded`` yet is browsed again, up to three times (a page that never loads still
    fails the caller's check of its DOM). The viewer draws only when something changes,
    so virtual time left once its page is drawn passes at no cost: the largest budget
    comes first (a budget of 10,000 ms left a page still loading on a loaded machine,
    and its next load cost a whole run more; 120,000 loads it the first time). ``screen``:
    the flags that size the page (:data:`SCREEN`, or :data:`WINDOW` for a page that draws
    every frame)."""
    assert BROWSER is not None, "no Chromium installed"
    shot = folder / "shot.png"
    dom = ""
    for budget in budgets:
        flags = [
            "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
            f"--user-data-dir={folder / 'profile'}", *screen,
            f"--virtual-time-budget={budget}",
        ]  # fmt: skip
        shot.unlink(missing_ok=True)
        done = subprocess.run(
            [BROWSER, *flags, f"--screenshot={shot}", "--dump-dom", url],
            timeout=300,
            capture_output=True,
            text=True,
        )
        dom = done.stdout
        if not shot.exists():  # a Chromium that does one command a run: the shot alone
            subprocess.run([BROWSER, *flags, f"--screenshot={shot}", url], timeout=300)
        if loaded(dom):
            break
    return shot, dom
