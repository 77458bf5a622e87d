"""Roofs on any footprint polygon, holes included (SPEC 5): flat, shed, gable, hip.

Meshes are in map coordinates (x east, y north, z up), from the eaves at ``height``:
- flat: a slab (walls carry the parapet);
- shed: one plane rising across the footprint's main direction;
- gable: two planes meeting at a ridge along the main direction (the long axis of the
  footprint's minimum rotated rectangle); walls are filled up to the roof, which gives
  gable ends their triangle;
- hip: every wall edge slopes up at the pitch; the faces come from the straight skeleton
  (py-straight-skeleton), so L, T, U shapes and courtyards get proper valleys and ridges.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
import trimesh
from shapely.geometry import LineString, Polygon
from shapely.ops import split

from facadecli.city.manifest import Roof

SLAB = 0.2

Surface = Callable[[np.ndarray], np.ndarray]  # (n, 2) map points -> roof heights


def roof_meshes(
    part: Polygon, height: float, roof: Roof
) -> tuple[trimesh.Trimesh, list[trimesh.Trimesh]]:
    """(the roof, walls filling the space between the eaves and the roof)."""
    if roof.type == "flat":
        slab = trimesh.creation.extrude_polygon(part, SLAB)
        slab.apply_translation((0, 0, height - SLAB))
        return slab, []
    if roof.type == "hip":
        return _hip(part, height, math.tan(math.radians(roof.pitch))), []
    surface, pieces = _planes(part, height, roof)
    faces = [_surface(piece, surface) for piece in pieces]
    return trimesh.util.concatenate(faces), _infill(part, height, surface, roof)


def _axes(part: Polygon) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Centre, main direction, its normal and the width across it (minimum rectangle)."""
    corners = np.array(part.minimum_rotated_rectangle.exterior.coords)[:4]
    sides = [corners[1] - corners[0], corners[2] - corners[1]]
    long_side, short_side = sorted(sides, key=lambda v: -float(np.hypot(*v)))
    direction = long_side / np.hypot(*long_side)
    normal = np.array([-direction[1], direction[0]])
    return corners.mean(axis=0), direction, normal, float(np.hypot(*short_side))


def _planes(part: Polygon, height: float, roof: Roof) -> tuple[Surface, list[Polygon]]:
    centre, direction, normal, width = _axes(part)
    slope = math.tan(math.radians(roof.pitch))
    if roof.type == "shed":
        low = float(np.min((np.array(part.exterior.coords) - centre) @ normal))

        def shed(points: np.ndarray) -> np.ndarray:
            return np.asarray(height + slope * ((points - centre) @ normal - low), dtype=float)

        return shed, [part]

    def gable(points: np.ndarray) -> np.ndarray:
        across = np.abs((points - centre) @ normal)
        return np.asarray(height + slope * np.maximum(0.0, width / 2 - across), dtype=float)

    reach = 2 * max(part.bounds[2] - part.bounds[0], part.bounds[3] - part.bounds[1]) + 1
    ridge = LineString([centre - reach * direction, centre + reach * direction])
    pieces = [g for g in split(part, ridge).geoms if isinstance(g, Polygon) and g.area > 1e-6]
    return gable, pieces or [part]


def _surface(piece: Polygon, surface: Surface) -> trimesh.Trimesh:
    vertices, faces = trimesh.creation.triangulate_polygon(piece)
    mesh = trimesh.Trimesh(np.column_stack([vertices, surface(vertices)]), faces, process=False)
    _face_up(mesh)
    return mesh


def _face_up(mesh: trimesh.Trimesh) -> None:
    down = mesh.face_normals[:, 2] < 0
    if down.any():
        faces = mesh.faces.copy()
        faces[down] = faces[down][:, ::-1]
        mesh.faces = faces


def _infill(part: Polygon, height: float, surface: Surface, roof: Roof) -> list[trimesh.Trimesh]:
    """Wall pieces from the eaves up to the roof along every edge (gable ends included)."""
    centre, _, normal, _ = _axes(part)
    walls = []
    for ring in (part.exterior, *part.interiors):
        points = np.array(ring.coords)
        for a, b in itertools.pairwise(points):
            profile = [a, b]
            if roof.type == "gable":  # the ridge may cross the edge: a kink in the profile
                da, db = (a - centre) @ normal, (b - centre) @ normal
                if da * db < 0:
                    t = da / (da - db)
                    profile = [a, a + t * (b - a), b]
            tops = surface(np.array(profile))
            if float(np.max(tops)) <= height + 1e-6:
                continue
            vertices = [(*a, height), (*b, height)] + [
                (*p, z) for p, z in reversed(list(zip(profile, tops, strict=True)))
            ]
            fan = [(0, i, i + 1) for i in range(1, len(vertices) - 1)]
            wall = trimesh.Trimesh(np.array(vertices, dtype=float), np.array(fan), process=False)
            outward = np.array([b[1] - a[1], a[0] - b[0], 0.0])
            flip = wall.face_normals @ outward < 0
            if flip.any():
                faces = wall.faces.copy()
                faces[flip] = faces[flip][:, ::-1]
                wall.faces = faces
            walls.append(wall)
    return walls


def _hip(part: Polygon, height: float, slope: float) -> trimesh.Trimesh:
    import py_straight_skeleton as skeletons

    exterior = [tuple(p) for p in np.array(part.exterior.coords)[:-1]]
    holes = [[tuple(p) for p in np.array(r.coords)[:-1]] for r in part.interiors]
    skeleton = skeletons.compute_skeleton(exterior, holes)
    nodes = skeleton.nodes
    meshes = []
    for face in skeleton.get_faces():
        loop = face[:-1] if face[0] == face[-1] else face
        flat = Polygon([(nodes[i].position.x, nodes[i].position.y) for i in loop])
        if not flat.is_valid or flat.area < 1e-9:
            continue
        vertices, faces = trimesh.creation.triangulate_polygon(flat)
        heights = np.array([height + slope * _time_at(nodes, loop, v) for v in vertices])
        mesh = trimesh.Trimesh(np.column_stack([vertices, heights]), faces, process=False)
        _face_up(mesh)
        meshes.append(mesh)
    return trimesh.util.concatenate(meshes)


def _time_at(nodes: list[object], loop: list[int], point: np.ndarray) -> float:
    """The skeleton time (offset) of a face vertex: that of the node at the same place."""
    best, time = math.inf, 0.0
    for i in loop:
        node = nodes[i]
        distance = math.hypot(node.position.x - point[0], node.position.y - point[1])  # type: ignore[attr-defined]
        if distance < best:
            best, time = distance, float(node.time)  # type: ignore[attr-defined]
    return time
