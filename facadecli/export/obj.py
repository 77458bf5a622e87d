"""Wavefront OBJ + MTL of a layout: one object per layer and material."""

from __future__ import annotations

from pathlib import Path

import trimesh
from trimesh.exchange.obj import export_obj

from facadecli.export.atomic import write_atomic


def obj_files(scene: trimesh.Scene, name: str) -> tuple[str, dict[str, bytes]]:
    """(OBJ text, {file name: bytes} of the MTL and its texture images): the scene's
    instances placed and merged by layer and material."""
    groups: dict[tuple[str, str], list[trimesh.Trimesh]] = {}
    for node in ordered_nodes(scene):
        matrix, geometry = scene.graph[node]
        mesh = scene.geometry[geometry].copy()
        mesh.apply_transform(matrix)
        layer = node.split("/", 1)[0]
        groups.setdefault((layer, mesh.visual.material.name), []).append(mesh)
    flat = trimesh.Scene()
    for (layer, material), meshes in groups.items():
        merged = trimesh.util.concatenate(meshes)
        if meshes[0].visual.uv is None:
            merged.visual = trimesh.visual.TextureVisuals(material=meshes[0].visual.material)
        flat.add_geometry(merged, geom_name=f"{layer}.{material}")
    text, textures = export_obj(
        flat,
        include_normals=False,
        include_color=False,
        include_texture=True,
        return_texture=True,
        mtl_name=f"{name}.mtl",
    )
    return text, dict(sorted(textures.items()))


def ordered_nodes(scene: trimesh.Scene) -> list[str]:
    """Geometry nodes in a stable order: layer by layer, shapes in layout order."""

    def key(node: str) -> tuple[str, int]:
        head, _, count = node.rpartition("/")
        return head.split("/", 1)[0], int(count) if count.isdigit() else 0

    layers = [n for n in scene.graph.nodes if str(n).startswith("layer:")]
    order = {str(n)[len("layer:") :]: i for i, n in enumerate(layers)}
    nodes = [str(n) for n in scene.graph.nodes_geometry]
    return sorted(nodes, key=lambda n: (order.get(key(n)[0], 0), key(n)[1], n))


def write_obj(scene: trimesh.Scene, path: Path) -> list[Path]:
    text, files = obj_files(scene, path.stem)
    written = []
    for name, data in files.items():  # the MTL and textures first, the OBJ that names them last
        write_atomic(path.parent / name, data)
        written.append(path.parent / name)
    write_atomic(path, text)
    return [path, *written]
