"""How many footprint walls merge as one (make bench): the Delft and Kotka footprints
beside the project (../shared/data/footprints), read as ``facade city`` reads them, their
walls (ring edges) counted before and after near-collinear nodes are merged at 1°, 3°
(the default) and 5°, and the CPU seconds the merging and the planning (party walls, the
parts standing on others) take. Figures are for the docs and notes, never asserted."""

from __future__ import annotations

import itertools
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT.parent / "shared" / "data" / "footprints"


def walls(footprints: tuple, shortest: float = 0.0) -> int:
    count = 0
    for footprint in footprints:
        for part in footprint.parts:
            for ring in (part.exterior, *part.interiors):
                pairs = itertools.pairwise(ring.coords)
                count += sum(1 for a, b in pairs if math.dist(a, b) >= shortest)
    return count


def main() -> None:
    from facadecli.city.default import default_city
    from facadecli.city.footprints import read_footprints
    from facadecli.city.run import plan, standing
    from facadecli.city.s3db import inherited, replaced_outlines
    from facadecli.city.straight import straighten

    for name in ("delft", "kotka"):
        path = DATA / f"{name}.geojson"
        if not path.is_file():
            print(f"({path} not found: skipped)")
            continue
        found = read_footprints(path)
        city = default_city(path)
        replaced = replaced_outlines(found.footprints)
        built, _ = standing(city, inherited(found.footprints, replaced), replaced)
        before = walls(tuple(built))
        for angle in (1.0, 3.0, 5.0):
            started = time.process_time()
            straight = straighten(built, angle, city.manifest.defaults.party_wall_tolerance)
            merging = time.process_time() - started
            print(
                f"walls {name} ({len(built):,} footprints), {angle:g}°: {before:,} -> "
                f"{walls(straight.footprints):,} walls ({straight.nodes:,} nodes merged, "
                f"{straight.footprints_changed:,} footprints); walls of 3 m or more "
                f"{walls(tuple(built), 3.0):,} -> {walls(straight.footprints, 3.0):,}; "
                f"{merging:.2f} CPU-s"
            )
        started = time.process_time()
        tasks, _ = plan(city, list(straighten(built, 3.0, 0.3).footprints), Path("unused"))
        planning = time.process_time() - started
        party = sum(1 for task in tasks if task.shared is not None)
        print(f"walls {name}: planning {planning:.2f} CPU-s, {party:,} footprints with party walls")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
