"""Rays cast at a built façade, as a viewer sees it: which of them pass through it."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from shapely.geometry import Polygon
from shapely.ops import unary_union

from facadecli.export.glb_merge import read_glb

TILT = math.radians(35)  # from the façade's normal


def directions(count: int = 8, tilt: float = TILT) -> np.ndarray:
    """Unit vectors pointing *into* the façade (−z) from ``count`` directions around it."""
    angles = [2 * math.pi * k / count for k in range(count)]
    return np.array(
        [
            (-math.sin(tilt) * math.cos(a), -math.sin(tilt) * math.sin(a), -math.cos(tilt))
            for a in angles
        ]
    )


def missing(
    triangles: np.ndarray,
    targets: np.ndarray,
    direction: np.ndarray,
    tile: float = 1.0,
    culled: bool = False,
) -> np.ndarray:
    """For rays along ``direction`` through each target point (x, y, 0), whether the ray
    meets no triangle at all (a hole). Rays are taken tile by tile, each against the
    triangles near its tile (Möller-Trumbore, both faces; with ``culled``, only the
    triangles whose front faces the ray, as a viewer draws single-sided materials)."""
    top = float(triangles[:, :, 2].max()) + 0.1
    bottom = float(triangles[:, :, 2].min()) - 0.1
    # a ray enters above the highest point and leaves below the lowest
    origins = targets - direction * ((top - targets[:, 2]) / -direction[2])[:, None]
    reach = (top - bottom) / -direction[2] * np.linalg.norm(direction[:2]) + 1e-6
    low = triangles.min(axis=1)
    high = triangles.max(axis=1)
    result = np.ones(len(targets), dtype=bool)
    keys = np.floor(targets[:, :2] / tile).astype(int)
    for key in np.unique(keys, axis=0):
        rays = np.flatnonzero((keys == key).all(axis=1))
        x0, y0 = key * tile - reach
        x1, y1 = (key + 1) * tile + reach
        near = (high[:, 0] >= x0) & (low[:, 0] <= x1) & (high[:, 1] >= y0) & (low[:, 1] <= y1)
        if near.any():
            result[rays] = ~_hits(triangles[near], origins[rays], direction, culled)
    return result


def _hits(
    triangles: np.ndarray, origins: np.ndarray, direction: np.ndarray, culled: bool = False
) -> np.ndarray:
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)  # (T, 3)
    det = (e1 * p).sum(axis=1)  # (T,): -direction . normal, positive when facing the ray
    usable = det > 1e-12 if culled else np.abs(det) > 1e-12
    inv = np.where(usable, 1.0 / np.where(usable, det, 1.0), 0.0)
    s = origins[:, None, :] - a[None, :, :]  # (R, T, 3)
    u = (s * p[None]).sum(axis=2) * inv[None]
    q = np.cross(s, e1[None])
    v = (q * direction).sum(axis=2) * inv[None]
    t = (q * e2[None]).sum(axis=2) * inv[None]
    inside = usable[None] & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t > 0)
    return inside.any(axis=1)


def nearest(triangles: np.ndarray, origins: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """For each ray, the index of the first triangle it meets (−1 for none)."""
    t = _distances(triangles, origins, direction)
    first = t.argmin(axis=1)
    return np.where(np.isfinite(t.min(axis=1)), first, -1)


def reach(
    triangles: np.ndarray, origins: np.ndarray, direction: np.ndarray, culled: bool = False
) -> np.ndarray:
    """For each ray, how far along ``direction`` (a unit vector) it first meets a triangle
    (infinity for none); with ``culled``, a triangle whose front faces it."""
    return _distances(triangles, origins, direction, culled).min(axis=1)


def _distances(
    triangles: np.ndarray, origins: np.ndarray, direction: np.ndarray, culled: bool = False
) -> np.ndarray:
    """(rays, triangles): where along each ray it meets each triangle, infinity if not."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = (e1 * p).sum(axis=1)
    usable = det > 1e-12 if culled else np.abs(det) > 1e-12
    inv = np.where(usable, 1.0 / np.where(usable, det, 1.0), 0.0)
    s = origins[:, None, :] - a[None, :, :]
    u = (s * p[None]).sum(axis=2) * inv[None]
    q = np.cross(s, e1[None])
    v = (q * direction).sum(axis=2) * inv[None]
    t = (q * e2[None]).sum(axis=2) * inv[None]
    inside = usable[None] & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t > 0)
    return np.where(inside, t, np.inf)


def opaque_parts(
    scene: trimesh.Scene, see_through: set[str] = frozenset()
) -> Iterator[tuple[str, np.ndarray]]:
    """Each node of a loaded model (a glb read back) with its triangles that stop the
    view, placed: those of every material but the blended ones and those named in
    ``see_through`` (transmitting glass)."""
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        mesh = scene.geometry[geometry]
        material = mesh.visual.material
        if material.alphaMode == "BLEND" or material.name in see_through:
            continue
        yield node, mesh.copy().apply_transform(transform).triangles


def opaque_triangles(scene: trimesh.Scene, see_through: set[str] = frozenset()) -> np.ndarray:
    """The triangles of a loaded model that stop the view (:func:`opaque_parts`)."""
    return np.concatenate([triangles for _, triangles in opaque_parts(scene, see_through)])


def grid(low: np.ndarray, high: np.ndarray, step: float, margin: float) -> np.ndarray:
    """Target points (x, y, 0) every ``step`` metres over the rectangle from ``low`` to
    ``high`` (x, y), ``margin`` metres in from its edges: a ray that close to a free end
    at 35° may leave through the wall's end, which is no window."""
    xs = np.arange(low[0] + margin, high[0] - margin + 1e-9, step)
    ys = np.arange(low[1] + margin, high[1] - margin + 1e-9, step)
    return np.array([(x, y, 0.0) for x in xs for y in ys])


def _buildings(scene: trimesh.Scene, see_through: set[str]) -> dict[str, list[np.ndarray]]:
    """The opaque triangles of each building of a merged city (its root node's name):
    glass that blends or transmits (``see_through``) is left out, as a viewer sees
    through it."""
    parents = scene.graph.transforms.parents
    found: dict[str, list[np.ndarray]] = defaultdict(list)
    for node, triangles in opaque_parts(scene, see_through):
        root = node
        while parents.get(root) not in (None, scene.graph.base_frame):
            root = parents[root]
        found[root].append(triangles)
    return found


def _beyond_the_rooms(plan: Any) -> Any:
    """The part of a building's plan deeper in than the rooms behind its windows reach:
    :data:`.ROOM_DEPTH` and 10 cm; in a narrow building, whose rooms reach half way in
    at most (:func:`.room_reach`), the middle: 98% of the way to its deepest point."""
    from facadecli.geometry.primitives import ROOM_DEPTH

    inner = plan.buffer(-(ROOM_DEPTH + 0.1))
    if not inner.is_empty:
        return inner
    low, high = 0.0, ROOM_DEPTH + 0.1  # the deepest point: bisected
    for _ in range(20):
        middle = (low + high) / 2
        low, high = (middle, high) if not plan.buffer(-middle).is_empty else (low, middle)
    return plan.buffer(-0.98 * low)


def city_leaks(glb: Path) -> tuple[int, list[tuple[str, list[float], list[list[float]]]]]:
    """From eight directions 35° above the horizon, rays aimed at points inside each
    building of a merged city (a metre in from its footprint, 1 m up and at 40% of its
    height) must meet the front of the building's own opaque surface before they get
    there (a viewer draws no back face). The number of buildings, and the rays that got
    through: (building, direction, the first targets reached)."""
    document, _ = read_glb(glb.read_bytes())
    transmitting = "KHR_materials_transmission"
    see_through = {
        m["name"] for m in document["materials"] if transmitting in m.get("extensions", {})
    }
    assert see_through  # the glass of the windows: the rays pass it
    buildings = _buildings(trimesh.load(glb, force="scene"), see_through)
    down = math.radians(35)
    directions = np.array(
        [
            (math.cos(down) * math.cos(a), -math.sin(down), math.cos(down) * math.sin(a))
            for a in np.radians(np.arange(0, 360, 45))
        ]
    )
    leaks = []
    for name, parts in sorted(buildings.items()):
        triangles = np.concatenate(parts)
        low, high = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
        ground = [t for t in triangles if np.ptp(t[:, 1]) < 1e-6 and t[0, 1] <= low[1] + 0.02]
        plan = unary_union([Polygon(t[:, [0, 2]]) for t in ground if Polygon(t[:, [0, 2]]).area])
        inner = _beyond_the_rooms(plan)
        assert not inner.is_empty, name
        x0, z0, x1, z1 = inner.bounds
        points = [
            (x, z)
            for x in np.linspace(x0, x1, 5)
            for z in np.linspace(z0, z1, 5)
            if inner.contains(Polygon([(x, z), (x + 1e-3, z), (x, z + 1e-3)]))
        ] or [inner.representative_point().coords[0]]
        heights = (low[1] + 1.0, low[1] + 0.4 * (high[1] - low[1]))
        targets = np.array([(x, y, z) for x, z in points for y in heights])
        far = 2 * float(np.linalg.norm(high - low)) + 10.0
        for direction in directions:
            origins = targets - direction * far
            met = reach(triangles, origins, direction, culled=True)
            through = targets[met >= far - 1e-6]
            if len(through):
                leaks.append((name, direction.round(2).tolist(), through[:3].round(2).tolist()))
    return len(buildings), leaks
