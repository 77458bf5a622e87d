"""A run's 3D Tiles opened in CesiumJS in headless Chromium, with no network: npm
``cesium``'s ``Build/Cesium`` and the run's output folder served from one local site, a
plain globe (no Cesium ion, no imagery), the camera flown to the tileset's bounding
sphere, the sun fixed. One page for the test that checks where CesiumJS puts the tiles
(``tests/test_tileset.py``) and for the README's picture of it (``make pictures``,
``docs/pictures.py``)."""

from __future__ import annotations

import functools
import http.server
import os
import re
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from tests.browser import WINDOW, browse

# a folder with Cesium.js: npm cesium's Build/Cesium, which make test installs in the venv
CESIUM = os.environ.get(
    "FACADE_CESIUM", str(Path(sys.prefix) / "node" / "node_modules" / "cesium" / "Build" / "Cesium")
)
GLOBE = (0x7D, 0x9A, 0x6A)  # the globe's plain colour
SUN = "2026-06-21T09:00:00Z"  # the scene's time: where the sun lights the houses from

# The title starts "loaded LON LAT HEIGHT" (the bounding sphere's centre, as CesiumJS
# computed it from the root transform) once every tile the view needs is loaded, and the
# label says it with the georeference the run wrote into tileset.json's extras.
PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><title>loading: tileset</title>
<script>window.CESIUM_BASE_URL = "cesium/";</script>
<script src="cesium/Cesium.js"></script>
<link href="cesium/Widgets/widgets.css" rel="stylesheet">
<style>html, body, #globe { margin: 0; width: 100%; height: 100%; overflow: hidden }
#label { position: absolute; top: 8px; left: 10px; padding: 4px 9px; border-radius: 3px;
  font: 14px/18px sans-serif; color: #fff; background: rgba(40, 40, 40, 0.85) }
#label:empty { display: none }</style>
</head><body><div id="globe"></div><div id="label"></div><script>
// No network: no Cesium ion, no imagery, a plain globe on the WGS 84 ellipsoid.
async function main() {
  Cesium.Ion.defaultAccessToken = "";
  const viewer = new Cesium.Viewer("globe", {
    baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false,
    animation: false, homeButton: false, sceneModePicker: false, fullscreenButton: false,
    navigationHelpButton: false, infoBox: false, selectionIndicator: false,
    terrainProvider: new Cesium.EllipsoidTerrainProvider(), skyBox: false,
    skyAtmosphere: false, shouldAnimate: false,
    contextOptions: { webgl: { preserveDrawingBuffer: true } },
  });
  viewer.clock.currentTime = Cesium.JulianDate.fromIso8601("@SUN@");
  viewer.scene.globe.baseColor = Cesium.Color.fromBytes(@GLOBE@);
  const tileset = await Cesium.Cesium3DTileset.fromUrl("run/3dtiles/tileset.json",
                                                       { maximumScreenSpaceError: 2 });
  viewer.scene.primitives.add(tileset);
  const sphere = tileset.boundingSphere;
  viewer.camera.flyToBoundingSphere(sphere, { duration: 0, offset: new Cesium.HeadingPitchRange(
    Cesium.Math.toRadians(30), Cesium.Math.toRadians(-35), sphere.radius * 2.2) });
  const at = Cesium.Cartographic.fromCartesian(sphere.center);
  tileset.allTilesLoaded.addEventListener(() => {
    const degrees = (v) => Cesium.Math.toDegrees(v).toFixed(8);
    const place = (lon, lat, digits) =>
      `${Math.abs(lon).toFixed(digits)}° ${lon < 0 ? "W" : "E"}, ` +
      `${Math.abs(lat).toFixed(digits)}° ${lat < 0 ? "S" : "N"}`;
    const extras = tileset.extras || {};
    const geo = extras.georeference || {};
    const origin = geo.origin_lonlat || [NaN, NaN];
    document.getElementById("label").innerText =
      `CesiumJS ${Cesium.VERSION}: the tileset's centre at ` +
      `${place(Cesium.Math.toDegrees(at.longitude), Cesium.Math.toDegrees(at.latitude), 6)} ` +
      `(WGS 84), from its root transform\\n${extras.name}: its origin at ` +
      `${place(origin[0], origin[1], 6)} in ${geo.crs} (the run's georeference)`;
    document.title = `loaded ${degrees(at.longitude)} ${degrees(at.latitude)} ${at.height}`;
  });
}
main().catch((error) => { document.title = "error: " + error; });
</script></body></html>
""".replace("@SUN@", SUN).replace("@GLOBE@", ", ".join(map(str, GLOBE)))


def installed() -> bool:
    """Whether CesiumJS is where :data:`CESIUM` says."""
    return bool(CESIUM) and (Path(CESIUM) / "Cesium.js").is_file()


class _Counted(http.server.SimpleHTTPRequestHandler):
    """Serves a folder quietly, keeping the paths asked for and those it could not find."""

    asked: list[str]
    missing: list[str]

    def do_GET(self) -> None:
        self.asked.append(self.path)
        super().do_GET()

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        self.missing.append(self.path)
        super().send_error(code, message, explain)

    def log_message(self, format: str, *args: Any) -> None:
        pass


@contextmanager
def _served(folder: Path, asked: list[str], missing: list[str]) -> Iterator[str]:
    kept = {"asked": asked, "missing": missing}
    handler = functools.partial(type("Handler", (_Counted,), kept), directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/index.html"
    finally:
        server.shutdown()
        server.server_close()


def open_tiles(run: Path, folder: Path, asked: list[str], missing: list[str]) -> tuple[Path, str]:
    """The run's 3D Tiles in CesiumJS: a site in ``folder`` (CesiumJS, the whole output
    folder ``run`` as ``run/``, as a user serves it, since the tiles name its
    ``textures/``, and :data:`PAGE`) served locally and browsed until the title says
    loaded; the screenshot (1000 x 600) and the DOM. ``asked`` and ``missing`` receive
    the paths requested and those not found."""
    site = folder / "site"
    site.mkdir()
    (site / "cesium").symlink_to(Path(CESIUM).resolve())
    (site / "run").symlink_to(run.resolve())
    (site / "index.html").write_text(PAGE, encoding="utf-8")
    with _served(site, asked, missing) as url:
        # CesiumJS draws every frame: in a window (browser.WINDOW), not the whole screen
        return browse(
            folder, url, (20_000, 60_000), lambda dom: "<title>loaded" in dom, screen=WINDOW
        )


def title(dom: str) -> str:
    """The page's title: ``loaded LON LAT HEIGHT`` once the tiles are in."""
    found = re.search(r"<title>([^<]*)</title>", dom)
    return found.group(1) if found else ""
