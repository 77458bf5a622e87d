"""A whole building: every wall edge of its footprint a façade facing outwards, a roof,
and the ground, as meshes in one scene (SPEC 5; DESIGN "Buildings and cities").

The vertical axis of a spec is solved once per building height, so floor lines meet at
the corners; the horizontal axis once per (spec, wall length) for the whole run. Walls
shorter than ``min_facade_width``, or that no layout fits, are plain walls.

World frame: glTF's, metres: x east, y up, z south (map north is -z).
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh
from shapely.geometry import Polygon

from facadecli.city.footprints import Footprint
from facadecli.city.manifest import Roof
from facadecli.city.roofs import roof_meshes
from facadecli.errors import InfeasibleError, SearchLimitError
from facadecli.geometry.facade import facade_scene, pbr
from facadecli.layout import Layout, build_shapes
from facadecli.solver.axis import AxisLayout, solve_axis
from facadecli.spec.model import Material, Spec

WALL = Material(color="#cfc6b8", roughness=0.9)
ROOF = Material(color="#6b4f43", roughness=0.8)
GROUND = Material(color="#808080", roughness=1.0)
SLAB = 0.2  # metres: thickness of flat roofs and plain walls
MIN_EDGE = 0.05  # metres: shorter edges are slivers, merged into the next wall


@dataclass
class AxisCache:
    """Solved axes of a run, shared by all buildings of a worker: (spec key, axis, length)."""

    axes: dict[tuple[str, str, float], AxisLayout | None] = field(default_factory=dict)

    def get(self, key: str, spec: Spec, axis: str, length: float) -> AxisLayout | None:
        slot = (key, axis, round(length, 2))
        if slot not in self.axes:
            try:
                deadline = time.perf_counter() + spec.solver.time_limit / 2
                self.axes[slot] = solve_axis(spec, axis, round(length, 2), deadline)  # type: ignore[arg-type]
            except (InfeasibleError, SearchLimitError):  # a plain wall there
                self.axes[slot] = None
        return self.axes[slot]


@dataclass(frozen=True)
class BuildingResult:
    scene: trimesh.Scene
    facades: int  # walls with a solved façade
    plain_walls: int


def _to_world(origin: tuple[float, float], direction: tuple[float, float]) -> np.ndarray:
    """Façade frame (u along the wall, v up, w outwards) to the world."""
    dx, dy = direction
    matrix = np.eye(4)
    matrix[:3, 0] = (dx, 0.0, -dy)  # u
    matrix[:3, 1] = (0.0, 1.0, 0.0)  # v
    matrix[:3, 2] = (dy, 0.0, dx)  # w: the outward normal (dy, -dx) on the map
    matrix[:3, 3] = (origin[0], 0.0, -origin[1])
    return matrix


MAP_TO_WORLD = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], dtype=float)


def _edges(part: Polygon) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    edges: list[tuple[tuple[float, float], tuple[float, float]]] = []
    for ring in (part.exterior, *part.interiors):  # outer ring CCW, holes CW: outwards is right
        edges.extend(itertools.pairwise(_corners(list(ring.coords))))
    return edges


def _corners(ring: list[tuple[float, ...]]) -> list[tuple[float, float]]:
    """A closed ring's points without those closer than MIN_EDGE to the last one kept: short
    edges merge into the next wall instead of leaving a gap, so walls always close."""
    kept = [(ring[0][0], ring[0][1])]
    for point in ring[1:-1]:
        if math.dist(kept[-1], point[:2]) >= MIN_EDGE:
            kept.append((point[0], point[1]))
    while len(kept) > 1 and math.dist(kept[-1], kept[0]) < MIN_EDGE:
        kept.pop()
    return [*kept, kept[0]] if len(kept) >= 3 else []


def build_building(
    footprint: Footprint,
    spec: Spec,
    spec_key: str,
    height: float,
    roof: Roof,
    min_facade_width: float,
    cache: AxisCache,
    base_dir: Path | None = None,
) -> BuildingResult:
    """The building's scene: façades on every wall, the roof, the ground. ``base_dir`` is
    the spec's folder, where its mesh and texture files are."""
    scene = trimesh.Scene()
    parts: dict[str, list[trimesh.Trimesh]] = {}
    wall_height = height + (roof.parapet if roof.type == "flat" else 0.0)
    vertical = cache.get(spec_key, spec, "y", wall_height)
    facades = plain = 0
    for part in footprint.parts:
        for a, b in _edges(part):
            length = math.dist(a, b)
            direction = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
            placement = _to_world(a, direction)
            horizontal = (
                cache.get(spec_key, spec, "x", length) if length >= min_facade_width else None
            )
            if horizontal is None or vertical is None:
                wall = trimesh.creation.box(extents=(length, wall_height, SLAB))
                wall.apply_translation((length / 2, wall_height / 2, -SLAB / 2))
                wall.apply_transform(placement)
                parts.setdefault("wall", []).append(wall)
                plain += 1
                continue
            facades += 1
            sized = spec.model_copy(
                update={
                    "canvas": spec.canvas.model_copy(
                        update={"width": horizontal.canvas, "height": vertical.canvas}
                    )
                }
            )
            layout = Layout(
                sized,
                horizontal.canvas,
                vertical.canvas,
                horizontal,
                vertical,
                build_shapes(sized, horizontal, vertical),
                0.0,
            )
            for mesh in _placed(facade_scene(layout, base_dir)):
                mesh.apply_transform(placement)
                parts.setdefault(mesh.visual.material.name, []).append(mesh)
        cover, infill = roof_meshes(part, height, roof)
        cover.apply_transform(MAP_TO_WORLD)
        parts.setdefault("roof", []).append(cover)
        for piece in infill:
            piece.apply_transform(MAP_TO_WORLD)
            parts.setdefault("wall", []).append(piece)
        ground = trimesh.creation.extrude_polygon(part, 0.01)
        ground.apply_translation((0, 0, -0.01))
        ground.apply_transform(MAP_TO_WORLD)
        parts.setdefault("ground", []).append(ground)
    materials = {name: pbr(name, m, base_dir) for name, m in spec.materials.items()}
    materials.update(
        {"wall": pbr("wall", WALL), "roof": pbr("roof", ROOF), "ground": pbr("ground", GROUND)}
    )
    for name in sorted(parts):
        merged = trimesh.util.concatenate(parts[name])
        material = materials.get(name) or pbr(name, Material())
        merged.visual = trimesh.visual.TextureVisuals(material=material)
        scene.add_geometry(
            merged, geom_name=f"{footprint.id}/{name}", node_name=f"{footprint.id}/{name}"
        )
    return BuildingResult(scene, facades, plain)


def _placed(scene: trimesh.Scene) -> list[trimesh.Trimesh]:
    """The scene's meshes with their instance transforms applied."""
    meshes = []
    for node in sorted(scene.graph.nodes_geometry):
        matrix, geometry = scene.graph[node]
        mesh = scene.geometry[geometry].copy()
        mesh.apply_transform(matrix)
        meshes.append(mesh)
    return meshes
