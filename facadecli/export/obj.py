"""Wavefront OBJ + MTL of a layout: one object per layer and material."""

from __future__ import annotations

from pathlib import Path

import trimesh
from trimesh.exchange.obj import export_obj

from facadecli.export.atomic import write_atomic
from facadecli.export.textures import TextureFiles, texture_files


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
    materials = {}
    for (layer, material), meshes in groups.items():
        merged = trimesh.util.concatenate(meshes)
        if meshes[0].visual.uv is None:
            merged.visual = trimesh.visual.TextureVisuals(material=meshes[0].visual.material)
        materials[material] = merged.visual.material
        merged.visual.material = _Simple.of(merged.visual.material)
        flat.add_geometry(merged, geom_name=f"{layer}.{material}")
    text, textures = export_obj(
        flat,
        include_normals=False,
        include_color=False,
        include_texture=True,
        return_texture=True,
        mtl_name=f"{name}.mtl",
    )
    pictures = texture_files(sorted(materials.items()), name)
    if pictures.files:
        textures = _pbr_library(textures, f"{name}.mtl", materials, pictures)
    return text, dict(sorted(textures.items()))


class _Simple(trimesh.visual.material.SimpleMaterial):  # type: ignore[misc]
    """An MTL entry as trimesh writes a PBR material's (its base colour and picture), told
    apart by its name too: trimesh folds materials of equal colours and pictures into one
    entry, and the upper floors' rooms were drawn in the lit ground floor's."""

    @classmethod
    def of(cls, material: object) -> object:
        simple = getattr(material, "to_simple", None)
        if simple is None:
            return material
        plain = simple()
        return cls(image=plain.image, diffuse=plain.diffuse, name=plain.name)

    def __hash__(self) -> int:
        return hash((super().__hash__(), self.name))


def _pbr_library(
    textures: dict[str, bytes],
    mtl_name: str,
    materials: dict[str, object],
    pictures: TextureFiles,
) -> dict[str, bytes]:
    """trimesh's MTL and pictures with each drawn material's entry written again with
    every map (trimesh keeps only the base colour): ``map_Kd``, ``norm`` and
    ``map_Bump`` (normal map), ``map_Pr``/``map_Pm`` (roughness and metallic, from the
    green and blue of glTF's packed picture), ``map_ao`` (its red: occlusion)."""
    blocks = textures[mtl_name].decode("utf-8").split("\nnewmtl ")
    kept: dict[str, bytes] = {}
    out = [blocks[0]]
    for block in blocks[1:]:
        name = block.split("\n", 1)[0].strip()
        material = materials.get(name)
        if material is None or (name, "normal") not in pictures.names:
            out.append(block)
            kept.update({f: textures[f] for f in _maps(block) if f in textures})
            continue
        out.append(_entry(name, material, pictures))
    kept.update(pictures.files)
    kept[mtl_name] = "\nnewmtl ".join(out).encode("utf-8")
    return kept


def _maps(block: str) -> list[str]:
    """The picture files an MTL entry names."""
    return [line.split()[-1] for line in block.splitlines() if line.startswith("map_")]


def _entry(name: str, material: object, pictures: TextureFiles) -> str:
    colour = getattr(material, "baseColorFactor", None)
    opacity = 1.0 if colour is None else float(colour[3]) / 255.0
    base, normal, orm = (pictures.names[(name, slot)] for slot in ("base_colour", "normal", "orm"))
    glow = getattr(material, "emissiveFactor", None)  # a lit room: its base colour, dimmed
    lit = [] if glow is None else ["Ke " + " ".join(f"{c:.8f}" for c in glow), f"map_Ke {base}"]
    return "\n".join(
        [
            name,
            "Kd 1.00000000 1.00000000 1.00000000",
            f"d {opacity:.8f}",
            f"map_Kd {base}",
            f"norm {normal}",
            f"map_Bump -bm 1.0 {normal}",
            f"map_Pr -imfchan g {orm}",
            f"map_Pm -imfchan b {orm}",
            f"map_ao -imfchan r {orm}",
            *lit,
            "",
        ]
    )


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
