"""The 3D Tiles step of `facade city --3dtiles` (make bench): CPU seconds a building spent
writing tiles (the LOD1 and LOD2 meshes made, every tile written, tileset.json), apart
from building the buildings, and the tiles' triangles and bytes by level of detail. On
the generated demo district, and on the Delft footprints (first 30, and all 160) when
../shared/data/footprints/delft.geojson is beside the project.

CPU time is ``time.process_time`` in the main process around the tile writer's work
(the buildings are built in two worker processes). Figures depend on the machine; they
are for the docs, never asserted by the tests."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import facadecli.city.tileset as tileset
from facadecli.city.default import default_city
from facadecli.city.demo import write_demo
from facadecli.city.manifest import City, load_city
from facadecli.city.run import run_city

ROOT = Path(__file__).resolve().parents[2]
DELFT = ROOT.parent / "shared" / "data" / "footprints" / "delft.geojson"
SPENT = {"cpu": 0.0}


def _timed(method: Callable[..., Any]) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        started = time.process_time()
        try:
            return method(*args, **kwargs)
        finally:
            SPENT["cpu"] += time.process_time() - started

    return timed


def measure(name: str, city: City, out: Path, limit: int | None) -> None:
    SPENT["cpu"] = 0.0
    report = run_city(city, out, jobs=2, limit=limit, lods=(1, 2, 3))
    built = report["summary"]["ok"]
    tiles = report["models"]["3dtiles"]
    largest = max(p.stat().st_size for p in (out / "3dtiles").rglob("*.glb"))
    print(
        f"3D Tiles, {name}: {built} buildings, {tiles['tiles']} tiles, "
        f"{SPENT['cpu'] / built:.4f} CPU-s a building for the tiles; "
        + ", ".join(
            f"LOD{k} {tiles['triangles'][f'lod{k}']:,} triangles "
            f"{tiles['bytes'][f'lod{k}'] / 1e3:,.0f} kB"
            for k in tiles["lods"]
        )
        + f"; largest tile {largest / 1e3:,.0f} kB"
    )


def main() -> None:
    tileset.TilesetWriter._write_square = _timed(tileset.TilesetWriter._write_square)  # type: ignore[method-assign]
    tileset.TilesetWriter.close = _timed(tileset.TilesetWriter.close)  # type: ignore[method-assign]
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        demo = load_city(write_demo(folder / "demo", ROOT / "specs", 2))
        measure("demo district (2 x 2 blocks)", demo, folder / "demo-out", None)
        if DELFT.is_file():
            measure("Delft, first 30", default_city(DELFT), folder / "delft-30", 30)
            measure("Delft, all", default_city(DELFT), folder / "delft", None)
        else:
            print(f"({DELFT} not found: Delft skipped)")


if __name__ == "__main__":
    main()
