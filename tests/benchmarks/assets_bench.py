"""What a game engine would load for a city (make bench): the generated demo district's
first 50 buildings built with ``facade city -j 1``, its merged glb counted per building.

Prints draw calls (primitives drawn, one per mesh instance's primitive), materials, images,
triangles and megabytes, per building and for the whole city, and the CPU seconds the run
took (user + system of the ``facade city`` process). Counts depend only on the code;
the CPU time on the machine and its load. Run it with PYTHONPATH=SOURCE to count another
checkout's code (the figures "before" in docs/reference/materials.md were taken so)."""

from __future__ import annotations

import json
import resource
import struct
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
BUILDINGS = 50


def read_glb(path: Path) -> tuple[dict[str, Any], int]:
    """A glb's JSON document and its binary chunk's length."""
    data = path.read_bytes()
    size, _ = struct.unpack_from("<II", data, 12)
    document = json.loads(data[20 : 20 + size])
    binary = struct.unpack_from("<I", data, 20 + size)[0] if len(data) > 20 + size else 0
    return document, binary


def counts(document: dict[str, Any]) -> dict[str, int]:
    """Draw calls and triangles as drawn (every node that shows a mesh draws each of its
    primitives; a mesh with ``EXT_mesh_gpu_instancing`` draws once per primitive for all
    its instances), and the stored materials, textures and images."""
    draws = triangles = 0
    nodes = document.get("nodes", [])

    def visit(index: int) -> None:
        nonlocal draws, triangles
        node = nodes[index]
        if "mesh" in node:
            instances = 1
            instancing = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
            if instancing:
                first = next(iter(instancing["attributes"].values()))
                instances = document["accessors"][first]["count"]
            for primitive in document["meshes"][node["mesh"]]["primitives"]:
                draws += 1
                accessor = primitive.get("indices", primitive["attributes"]["POSITION"])
                triangles += document["accessors"][accessor]["count"] // 3 * instances
        for child in node.get("children", []):
            visit(child)

    scene = document.get("scenes", [{}])[document.get("scene", 0)]
    for root in scene.get("nodes", []):
        visit(root)
    return {
        "buildings": len(scene.get("nodes", [])),
        "draws": draws,
        "triangles": triangles,
        "materials": len(document.get("materials", [])),
        "textures": len(document.get("textures", [])),
        "images": len(document.get("images", [])),
    }


def main() -> None:
    from facadecli.city.demo import write_demo

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        manifest = write_demo(folder / "demo", ROOT / "specs", 4)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        command = [sys.executable, "-m", "facadecli", "city", str(manifest), "-o", str(folder)]
        subprocess.run(
            [*command, "-j", "1", "--limit", str(BUILDINGS)], check=True, capture_output=True
        )
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        glb = folder / "demo-district.glb"
        document, binary = read_glb(glb)
        found = counts(document)
        size = glb.stat().st_size
    n = found["buildings"]
    print(
        f"city assets, demo district ({n} buildings): per building "
        f"{found['draws'] / n:.1f} draw calls, {found['materials'] / n:.2f} materials, "
        f"{found['images'] / n:.2f} images, {found['triangles'] / n:,.0f} triangles, "
        f"{size / n / 1e6:.2f} MB; whole city {found['draws']} draw calls, "
        f"{found['materials']} materials, {found['textures']} textures, {found['images']} "
        f"images, {size / 1e6:.1f} MB ({binary / 1e6:.1f} MB binary); {cpu:.1f} s CPU (-j 1)"
    )


if __name__ == "__main__":
    main()
