"""What a game engine would load for a city (make bench): the generated demo district's
first 50 buildings built with ``facade city -j 1``, its merged glb counted per building:
as built by default, with ``--instance`` (repeated parts as GPU instances), and built at
``--lod 2`` and ``--lod 1`` (no façade solved).

Prints draw calls (primitives drawn: one per node's primitive, one per primitive of an
instanced mesh for all its instances), materials, images, triangles drawn and stored
(an instanced mesh's once) and megabytes (the glb and the pictures it names in the run's
``textures/``), per building and for the whole city, and the
CPU seconds each run took (user + system of the ``facade city`` process). Counts depend
only on the code; the CPU time on the machine and its load. Run it with PYTHONPATH=SOURCE
to count another checkout's code (the figures "before" in docs/reference/materials.md
were taken so)."""

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
    drawn: set[int] = set()  # meshes

    def visit(index: int) -> None:
        nonlocal draws, triangles
        node = nodes[index]
        if "mesh" in node:
            instances = 1
            instancing = node.get("extensions", {}).get("EXT_mesh_gpu_instancing")
            if instancing:
                first = next(iter(instancing["attributes"].values()))
                instances = document["accessors"][first]["count"]
            drawn.add(node["mesh"])
            for primitive in document["meshes"][node["mesh"]]["primitives"]:
                draws += 1
                accessor = primitive.get("indices", primitive["attributes"]["POSITION"])
                triangles += document["accessors"][accessor]["count"] // 3 * instances
        for child in node.get("children", []):
            visit(child)

    scene = document.get("scenes", [{}])[document.get("scene", 0)]
    for root in scene.get("nodes", []):
        visit(root)
    stored = sum(
        document["accessors"][p.get("indices", p["attributes"]["POSITION"])]["count"] // 3
        for mesh in drawn
        for p in document["meshes"][mesh]["primitives"]
    )
    roots = [nodes[root].get("name") for root in scene.get("nodes", [])]
    return {
        "buildings": sum(1 for name in roots if name != "instanced"),
        "draws": draws,
        "triangles": triangles,
        "stored": stored,
        "materials": len(document.get("materials", [])),
        "textures": len(document.get("textures", [])),
        "images": len(document.get("images", [])),
    }


def line(label: str, glb: Path, cpu: float | None) -> str:
    """The figures of a merged glb, per building and for the whole city."""
    document, binary = read_glb(glb)
    found = counts(document)
    uris = {image["uri"] for image in document.get("images", []) if "uri" in image}
    pictures = sum((glb.parent / uri).stat().st_size for uri in uris)  # the run's textures/
    size = glb.stat().st_size + pictures
    n = found["buildings"]
    took = f"; {cpu:.1f} s CPU (-j 1)" if cpu is not None else ""
    return (
        f"city assets, demo district ({n} buildings), {label}: per building "
        f"{found['draws'] / n:.1f} draw calls, {found['materials'] / n:.2f} materials, "
        f"{found['images'] / n:.2f} images, {found['triangles'] / n:,.0f} triangles drawn, "
        f"{found['stored'] / n:,.0f} stored, {size / n / 1e6:.2f} MB; whole city "
        f"{found['draws']} draw calls, {found['materials']} materials, {found['textures']} "
        f"textures, {found['images']} images, {size / 1e6:.1f} MB ({binary / 1e6:.1f} MB "
        f"binary, {pictures / 1e6:.1f} MB of pictures in textures/){took}"
    )


def unit_shapes(glb: Path) -> str:
    """How many of the instanced meshes are one shape at other sizes (the same material,
    the same triangles once scaled into the unit cube): those a unit mesh a material
    (scaled by its placements) could draw as one, were their textures free to stretch."""
    import numpy as np

    from facadecli.export.glb_merge import read_glb as read_chunk
    from facadecli.export.instancing import EXTENSION

    document, chunk = read_chunk(glb.read_bytes())

    def values(index: int) -> np.ndarray:
        accessor = document["accessors"][index]
        view = document["bufferViews"][accessor["bufferView"]]
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        kind = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}[accessor["componentType"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[accessor["type"]]
        return np.frombuffer(chunk, kind, accessor["count"] * width, start).reshape(-1, width)

    meshes, shapes = 0, set()
    for node in document["nodes"]:
        if EXTENSION not in node.get("extensions", {}):
            continue
        meshes += 1
        key = []
        for primitive in document["meshes"][node["mesh"]]["primitives"]:
            points = values(primitive["attributes"]["POSITION"]).astype(float)
            low, extent = points.min(axis=0), np.ptp(points, axis=0)
            unit = np.round((points - low) / np.where(extent > 1e-9, extent, 1.0), 4)
            corners = values(primitive["indices"]).tobytes()
            key += [primitive.get("material"), corners, unit.tobytes()]
        shapes.add(tuple(key))
    return (
        f"  --instance: {meshes} instanced meshes; as unit meshes, one a material and "
        f"shape at any size, they would be {len(shapes)}"
    )


def build(manifest: Path, out: Path, *options: str) -> float:
    """``facade city`` on the manifest's first buildings; its CPU seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    command = [sys.executable, "-m", "facadecli", "city", str(manifest), "-o", str(out)]
    subprocess.run(
        [*command, "-j", "1", "--limit", str(BUILDINGS), *options], check=True, capture_output=True
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    from facadecli.city.demo import write_demo

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        manifest = write_demo(folder / "demo", ROOT / "specs", 4)
        cpu = build(manifest, folder / "plain")
        print(line("default", folder / "plain" / "demo-district.glb", cpu), flush=True)
        cpu = build(manifest, folder / "instanced", "--instance")
        print(line("--instance", folder / "instanced" / "demo-district.glb", cpu), flush=True)
        print(unit_shapes(folder / "instanced" / "demo-district.glb"), flush=True)
        for lod in (2, 1):  # façades not solved: the CPU is the volumes and roofs alone
            cpu = build(manifest, folder / f"lod{lod}", "--lod", str(lod))
            glb = folder / f"lod{lod}" / "demo-district.glb"
            print(line(f"--lod {lod}", glb, cpu), flush=True)


if __name__ == "__main__":
    main()
