"""A page as headless Chromium shows it: a screenshot and the DOM once its scripts ran,
both from one load of the page (one browser started, not one for each)."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Callable, Iterable
from pathlib import Path

BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")


def browse(
    folder: Path,
    url: str,
    budgets: Iterable[int] = (10_000, 40_000, 120_000, 120_000, 120_000),
    loaded: Callable[[str], bool] = lambda dom: "<title>loading: " not in dom,
) -> tuple[Path, str]:
    """A screenshot (1000 x 600, ``folder``/shot.png) of the page at ``url`` and its DOM
    once its scripts ran. Work outside Chromium's virtual time (decoding a textured
    model's pictures, fetching tiles) may not be done when a budget ends, so a page not
    ``loaded`` yet is browsed again with the next, larger budget, and the largest again:
    on a loaded machine (the suite's other worker busy) the decoding can outlast three
    loads (a page that never loads still fails the caller's check of its DOM)."""
    assert BROWSER is not None, "no Chromium installed"
    shot = folder / "shot.png"
    dom = ""
    for budget in budgets:
        flags = [
            "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
            f"--user-data-dir={folder / 'profile'}", "--window-size=1000,600",
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
