"""The memory of writing ``3dtiles/tileset.json`` for a town of N buildings, alone.

``python tests/benchmarks/tileset_close_bench.py N``: a :class:`TilesetWriter` planned for
N buildings at seeded random places (LOD 1, 2, 3, the default capacities), each square's
tiles' record filled as writing its glb files would fill it (seeded boxes and errors, no glb
written: no building is built), then :meth:`TilesetWriter.close` measured: the peak of
Python's allocations while it writes (tracemalloc) and the process's resident peak
(``ru_maxrss``). Figures for docs/benchmarks.md, never asserted by the tests.
"""

from __future__ import annotations

import random
import resource
import sys
import tempfile
import tracemalloc
from pathlib import Path

from facadecli.city.georef import Georef
from facadecli.city.tileset import Square, TilesetWriter


def filled(writer: TilesetWriter, square: Square, rng: random.Random) -> None:
    """The square's tiles and box as writing its content would leave them (its record,
    :class:`.SquareRecords`), its children's too."""
    lods = writer.lods_of(square)
    if lods:
        errors = [round(rng.uniform(3, 9), 3) * (k < 3) for k in lods]
        x, y = rng.uniform(0, 1000), rng.uniform(0, 1000)
        box = (x, y, 0.0, x + rng.uniform(5, 50), y + rng.uniform(5, 50), rng.uniform(6, 20))
        writer.records.put_tiles(square.index, box, errors)
    for child in writer.tree.children(square):
        filled(writer, child, rng)


def main(count: int) -> None:
    rng = random.Random(1)
    side = 8 * count**0.5  # metres: about a building every 64 m²
    places = [(rng.uniform(0, side), rng.uniform(0, side)) for k in range(count)]
    with tempfile.TemporaryDirectory(prefix="tileset-") as folder:
        writer = TilesetWriter(
            Path(folder), Georef("EPSG:3067", (385000.0, 6672000.0)), (1, 2, 3), places
        )
        filled(writer, writer.tree.root, rng)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        tracemalloc.start()
        writer.close("bench")
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        size = (Path(folder) / "3dtiles" / "tileset.json").stat().st_size
    print(
        f"{count} buildings: tileset.json {size / 2**20:.1f} MiB; writing it: traced peak "
        f"{peak / 2**20:.2f} MiB, resident peak {before:.0f} MiB before, {after:.0f} MiB after"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]))
