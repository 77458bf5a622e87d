"""Rays cast at a built façade, as a viewer sees it: which of them pass through it."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import trimesh

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
