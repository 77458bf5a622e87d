"""A building's coarser levels of detail, from its CityJSON feature (cityjson.py).

- **LOD1, a block**: each volume's footprint (its GroundSurface, or OuterCeilingSurface
  when lifted) extruded from its base to the volume's top: no roof shape, no façades.
- **LOD2, walls and roofs**: the volume's LOD2.2 solid itself (the roofs of roofs.py, as
  the CityJSON carries them), triangulated, without façades.
- LOD3 is the building's own glb, with its façades.

Both are made from the feature written beside each building's glb, so a resumed run
gets them too (3D Tiles' coarser tiles, and the merged glb at ``--lod 1`` or ``2``), and
the roofs come from one place (roofs.py through cityjson.py). Meshes are in the glTF
frame of every other model of the run (x east, y up, z south, metres from the run's
origin); a building's surfaces keep the order the feature gives them, so the same
feature gives the same bytes.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from facadecli.city.building import MAP_TO_WORLD, ROOF_NAME, WALL_NAME
from facadecli.city.cityjson import SCALE
from facadecli.city.roofs import _triangulate as triangulate_face  # roofs' own, shared
from facadecli.export.gltf import glb_bytes
from facadecli.geometry.facade import pbr
from facadecli.spec.model import Material

COLOURS = {WALL_NAME: "#d9d2c3", ROOF_NAME: "#8f5a48"}  # LOD1 and LOD2 materials

BOTTOMS = ("GroundSurface", "OuterCeilingSurface")
HIDDEN = ("RoofSurface", "ClosureSurface")  # not walls: roofs, and a podium's top under a tower
Polygon3 = list[np.ndarray]  # a planar surface: its exterior ring, then its holes, (n, 3) metres


@dataclass(frozen=True)
class Solid:
    """One volume of a feature: its surfaces (semantic type, rings in metres, map frame:
    x east, y north, z up)."""

    surfaces: tuple[tuple[str, Polygon3], ...]

    @property
    def top(self) -> float:
        return max(float(ring[:, 2].max()) for _, rings in self.surfaces for ring in rings)

    @property
    def roof_depth(self) -> float:
        """How far the roof falls below its top: what a block of the full height gets wrong."""
        lowest = [
            float(ring[:, 2].min())
            for kind, rings in self.surfaces
            if kind == "RoofSurface"
            for ring in rings
        ]
        return self.top - min(lowest) if lowest else 0.0


def solids(feature: dict[str, Any]) -> list[Solid]:
    """The volumes of a CityJSONFeature, in the order of its objects and geometries (a
    MultiSolid's solids, as a roof's posts, each one)."""
    points = np.asarray(feature["vertices"], dtype=float) * SCALE
    found = []
    for item in feature["CityObjects"].values():
        for geometry in item.get("geometry", []):
            boundaries = geometry["boundaries"]
            values = geometry["semantics"]["values"]
            kinds = [entry["type"] for entry in geometry["semantics"]["surfaces"]]
            if geometry["type"] == "MultiSolid":  # solids of shells of surfaces
                pieces = [(s[0], v[0]) for s, v in zip(boundaries, values, strict=True)]
            elif geometry["type"] == "Solid":  # shells of surfaces
                pieces = [(boundaries[0], values[0])]
            else:  # a MultiSurface: surfaces
                pieces = [(boundaries, values)]
            for shell, shell_values in pieces:
                surfaces = tuple(
                    (kinds[value], [points[ring] for ring in surface])
                    for surface, value in zip(shell, shell_values, strict=True)
                )
                found.append(Solid(surfaces))
    return found


def block_surfaces(solid: Solid) -> Iterator[Polygon3]:
    """LOD1: the solid's bottom at its base, the same rings at its top, a wall a side."""
    top = solid.top
    for kind, rings in solid.surfaces:
        if kind not in BOTTOMS:
            continue
        yield rings
        lid = [ring[::-1].copy() for ring in rings]  # the bottom faces down: the lid up
        for ring in lid:
            ring[:, 2] = top
        yield lid
        for ring in rings:  # the bottom's rings turn clockwise seen from above
            for a, b in zip(ring, np.roll(ring, -1, axis=0), strict=True):
                yield [np.array([b, a, (a[0], a[1], top), (b[0], b[1], top)], dtype=float)]


def triangles(polygon: Polygon3) -> np.ndarray:
    """A planar polygon with holes as triangles, (n, 3, 3), facing the way its exterior
    ring turns (counter-clockwise seen from the front)."""
    exterior = polygon[0]
    normal = np.cross(exterior - exterior.mean(axis=0), np.roll(exterior, -1, axis=0) - exterior)
    normal = normal.sum(axis=0)  # Newell's normal, twice the area
    if not np.any(normal):
        return np.zeros((0, 3, 3))
    drop = int(np.argmax(np.abs(normal)))  # seen along its dominant axis, in plan
    stacked = np.vstack(polygon)
    flat = stacked[:, [axis for axis in range(3) if axis != drop]]
    ends = np.cumsum([0, *(len(ring) for ring in polygon)])
    face = tuple(tuple(range(a, b)) for a, b in itertools.pairwise(ends))
    corners = np.asarray(triangulate_face(face, flat), dtype=np.int64).reshape(-1, 3)
    found = stacked[corners]
    facing = np.cross(found[:, 1] - found[:, 0], found[:, 2] - found[:, 0]) @ normal
    found[facing < 0] = found[facing < 0][:, ::-1]  # counter-clockwise in plan: maybe not here
    return np.asarray(found[facing != 0])


def mesh(polygons: Sequence[Polygon3]) -> trimesh.Trimesh:
    """Planar polygons in the map frame as one mesh in the glTF frame."""
    pieces = [triangles(polygon) for polygon in polygons]
    corners = np.concatenate([np.zeros((0, 3, 3)), *pieces]).reshape(-1, 3)
    faces = np.arange(len(corners), dtype=np.int64).reshape(-1, 3)
    found = trimesh.Trimesh(corners, faces, process=False)
    found.merge_vertices()
    found.apply_transform(MAP_TO_WORLD)
    return found


def lod_meshes(feature: dict[str, Any], lod: int) -> dict[str, trimesh.Trimesh]:
    """A building's meshes at ``lod`` (1 or 2), by material: ``wall`` (a block's every
    side, or the walls and ground), ``roof`` (LOD2's roofs)."""
    volumes = solids(feature)
    if lod == 1:
        return {WALL_NAME: mesh([p for solid in volumes for p in block_surfaces(solid)])}
    if lod != 2:
        raise ValueError(f"LOD{lod} is not made from the CityJSON")
    walls = [p for solid in volumes for kind, p in solid.surfaces if kind not in HIDDEN]
    roofs = [p for solid in volumes for kind, p in solid.surfaces if kind == "RoofSurface"]
    return {WALL_NAME: mesh(walls), ROOF_NAME: mesh(roofs)}


def roof_depth(feature: dict[str, Any]) -> float:
    """The deepest roof of a building's volumes (metres below their top)."""
    return max((solid.roof_depth for solid in solids(feature)), default=0.0)


def feature_of(glb: Path) -> dict[str, Any]:
    """A building's CityJSON feature, written beside its glb."""
    feature: dict[str, Any] = json.loads(glb.with_suffix(".city.jsonl").read_text("utf-8"))
    return feature


def dressed(meshes: dict[str, trimesh.Trimesh]) -> dict[str, trimesh.Trimesh]:
    """LOD meshes (by material) in their materials: flat colours, one of each kind, so
    that every building's are the same material (one draw call a kind, merged)."""
    found = {}
    for name, part in sorted(meshes.items()):
        if not len(part.faces):
            continue
        part = part.copy()
        part.visual = trimesh.visual.TextureVisuals()
        part.visual.material = pbr(name, Material(color=COLOURS[name], roughness=0.9), None)
        found[name] = part
    return found


def lod_glb(glb: Path, lod: int) -> bytes:
    """A building at ``lod`` (1 or 2) as a glb, from the feature beside its own ``glb``."""
    return glb_bytes(feature_scene(feature_of(glb), glb.stem, lod))


def feature_scene(feature: dict[str, Any], stem: str, lod: int) -> trimesh.Scene:
    """A building's ``feature`` at ``lod`` (1 or 2): a node a material, named as the full
    building's are (``<stem>/wall``, ``<stem>/roof``)."""
    scene = trimesh.Scene()
    for name, part in dressed(lod_meshes(feature, lod)).items():
        scene.add_geometry(part, geom_name=f"{stem}/{name}", node_name=f"{stem}/{name}")
    return scene
