"""The weighted straight skeleton of a footprint, the roofs' skeleton (see roofs.py).

Every edge of the outline moves inwards at its own speed (its weight; 0 keeps it still,
as a gable end), and the skeleton is where the moving edges meet: under every edge, the
face its wavefront swept, and for every node the time it was reached (the roof's height
there, over the slope). Events that happen at nearly one time are handled together,
which rectilinear outlines need. Raises :class:`Degenerate` when an outline cannot be
done; the roofs then fall back to simpler shapes.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from facadecli.city.roofs import _Outline

MAX_EVENTS = 20  # skeleton steps per vertex before giving up
MAX_SKELETON = 200  # vertices: larger outlines get the roofs that need no skeleton, or flat


class Degenerate(Exception):
    """A skeleton or shape that cannot be built here: the caller falls back."""


@dataclass
class _Vertex:
    """A vertex of the wavefront: where it is now, its edges, the node its arc left."""

    x: float
    y: float
    a: int  # the edge coming in
    b: int  # the edge going out
    node: int


class Skeleton:
    """The weighted straight skeleton of an outline, by simulating its wavefront from
    event to event; ``faces[e]``: the loops of nodes under edge ``e`` (counter-clockwise,
    the edge's start first), ``t`` the time each node was reached.

    Each step moves every vertex to the earliest event (an edge shrinking to nothing, a
    reflex vertex reaching another edge, an edge changing weight), then tidies the
    wavefront: vertices closer than ``eps`` merge, spikes fold, rings without area die,
    vertices lying on another edge split it. Whatever happens at one time is handled
    together, which copes with the many simultaneous events of rectilinear outlines."""

    def __init__(
        self,
        outline: _Outline,
        weights: Sequence[float],
        switches: dict[int, float],
        stops: dict[int, float] | None = None,
    ) -> None:
        if outline.count > MAX_SKELETON:
            raise Degenerate("too many vertices for a skeleton here")
        self.outline = outline
        self.eps = outline.eps
        self.normal = np.column_stack([-outline.direction[:, 1], outline.direction[:, 0]])
        self.dirs = outline.direction
        self.unit = [(float(x), float(y)) for x, y in outline.direction]
        self.weights = list(weights)
        self.weight = np.array(weights, dtype=float)
        # (time, edge, its weight from then): switches start still edges, stops stop them
        self.pending = sorted(
            [(time, e, 1.0) for e, time in switches.items()]
            + [(time, e, 0.0) for e, time in (stops or {}).items()]
        )
        self.x: list[float] = []
        self.y: list[float] = []
        self.times: list[float] = []
        self.segments: dict[int, list[tuple[int, int]]] = defaultdict(list)
        self.time = 0.0
        self.rings: list[list[_Vertex]] = []
        for head, ring in zip(outline.heads, outline.local, strict=True):
            vertices = []
            for k, (x, y) in enumerate(ring):
                e = head + k
                node = self._node(float(x), float(y))
                vertices.append(_Vertex(float(x), float(y), int(outline.prev[e]), e, node))
                self.segments[e].append((e, int(outline.next[e])))
            self.rings.append(vertices)
        self._run()
        self.xy = np.column_stack([self.x, self.y]) if self.x else np.zeros((0, 2))
        self.t = np.array(self.times)
        self.faces = self._faces()

    def _node(self, x: float, y: float) -> int:
        self.x.append(x)
        self.y.append(y)
        self.times.append(self.time)
        return len(self.x) - 1

    def _close(self, v: _Vertex) -> int:
        """End the vertex's arc here (a node now), and start a new one from it."""
        if self.times[v.node] == self.time and self.x[v.node] == v.x and self.y[v.node] == v.y:
            return v.node
        node = self._node(v.x, v.y)
        self._arc(v.node, node, v.a, v.b)
        v.node = node
        return node

    def _arc(self, low: int, high: int, a: int, b: int) -> None:
        if low != high:
            self.segments[a].append((low, high))
            self.segments[b].append((high, low))

    # -- the simulation ---------------------------------------------------------------

    def _run(self) -> None:
        limit = MAX_EVENTS * self.outline.count + 50
        for _ in range(limit):
            self._settle()
            if not self.rings:
                return
            vertices, px, py, a, b, nxt = self._snapshot()
            vx, vy = self._speeds(a, b)
            step = self._next_event(px, py, vx, vy, a, b, nxt)
            if not math.isfinite(step):
                raise Degenerate("the wavefront stopped")
            for v, x, y in zip(
                vertices, (px + vx * step).tolist(), (py + vy * step).tolist(), strict=True
            ):
                v.x, v.y = x, y
            self.time += step
            while self.pending and self.pending[0][0] <= self.time + self.eps:
                _, e, speed = self.pending.pop(0)
                self.weight[e] = speed
                for v in vertices:
                    if e in (v.a, v.b):
                        self._close(v)
        raise Degenerate("too many events")

    def _snapshot(
        self,
    ) -> tuple[list[_Vertex], np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The wavefront as arrays: vertices, x, y, edges in and out, the next vertex."""
        vertices = [v for ring in self.rings for v in ring]
        data = np.array([(v.x, v.y, v.a, v.b) for v in vertices]).reshape(-1, 4)
        nxt: list[int] = []
        for ring in self.rings:
            start = len(nxt)
            nxt.extend(range(start + 1, start + len(ring)))
            nxt.append(start)
        a, b = data[:, 2].astype(int), data[:, 3].astype(int)
        return vertices, data[:, 0], data[:, 1], a, b, np.array(nxt)

    def _speeds(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each vertex's velocity: it stays on both its edges as they move at their
        weights (along the bisector when the weights are equal)."""
        ax, ay = self.normal[a, 0], self.normal[a, 1]
        bx, by = self.normal[b, 0], self.normal[b, 1]
        wa, wb = self.weight[a], self.weight[b]
        dot = ax * bx + ay * by
        det = ax * by - ay * bx
        scale = np.where(dot > -1 + 1e-12, wa / np.where(dot > -1 + 1e-12, 1 + dot, 1), 0.0)
        vx, vy = (ax + bx) * scale, (ay + by) * scale
        uneven = np.abs(wa - wb) >= 1e-12
        if uneven.any():
            ok = uneven & (np.abs(det) > 1e-9)
            safe = np.where(ok, det, 1.0)
            vx = np.where(ok, (wa * by - ay * wb) / safe, vx)
            vy = np.where(ok, (ax * wb - wa * bx) / safe, vy)
            flat = uneven & ~ok  # parallel edges of unequal weights: their mean
            vx = np.where(flat, (ax + bx) * (wa + wb) / 4, vx)
            vy = np.where(flat, (ay + by) * (wa + wb) / 4, vy)
        return vx, vy

    def _next_event(
        self,
        px: np.ndarray,
        py: np.ndarray,
        vx: np.ndarray,
        vy: np.ndarray,
        a: np.ndarray,
        b: np.ndarray,
        nxt: np.ndarray,
    ) -> float:
        """Time to the earliest event: an edge shrinking to nothing, a reflex vertex
        reaching another edge, an edge changing weight."""
        dx, dy = self.dirs[b, 0], self.dirs[b, 1]
        length = (px[nxt] - px) * dx + (py[nxt] - py) * dy
        rate = (vx[nxt] - vx) * dx + (vy[nxt] - vy) * dy
        shrinking = rate < -1e-12
        best = math.inf
        if shrinking.any():
            best = float((np.maximum(length[shrinking], 0) / -rate[shrinking]).min())
        reflex = np.flatnonzero(self.dirs[a, 0] * dy - self.dirs[a, 1] * dx < -1e-9)
        if len(reflex):
            rows = np.arange(len(reflex))
            nx, ny, w = -dy, dx, self.weight[b]
            ox = px[reflex][:, None] - px[None, :]
            oy = py[reflex][:, None] - py[None, :]
            gap = ox * nx + oy * ny  # how far each reflex vertex is in front of each edge
            closing = vx[reflex][:, None] * nx + vy[reflex][:, None] * ny - w
            ok = (closing < -1e-12) & (gap > -self.eps)
            ok[rows, reflex] = False  # its own edges
            ok[rows, np.argsort(nxt)[reflex]] = False
            if ok.any():
                when = np.where(ok, np.maximum(gap, 0) / np.where(ok, -closing, 1), np.inf)
                # where along the edge it arrives, and how long the edge is by then
                along = (
                    ox * dx
                    + oy * dy
                    + when * ((vx[reflex][:, None] - vx) * dx + (vy[reflex][:, None] - vy) * dy)
                )
                reach = length + rate * when
                ok &= (along > -self.eps) & (along < reach + self.eps)
                if ok.any():
                    best = min(best, float(when[ok].min()))
        if self.pending:
            best = min(best, max(self.pending[0][0] - self.time, 0.0))
        return best

    # -- tidying the wavefront at one time -------------------------------------------

    def _settle(self) -> None:
        for _ in range(4 * self.outline.count + 20):
            if not (self._merge() or self._fold() or self._die() or self._split()):
                return
        raise Degenerate("the wavefront does not settle")

    def _merge(self) -> bool:
        for index, ring in enumerate(self.rings):
            size = len(ring)
            for i in range(size):
                v, w = ring[i], ring[(i + 1) % size]
                dx, dy = self.unit[v.b]  # the edge from v to w has shrunk to nothing
                if size > 1 and (
                    (w.x - v.x) * dx + (w.y - v.y) * dy < self.eps
                    or math.hypot(w.x - v.x, w.y - v.y) < self.eps
                ):
                    x, y = (v.x + w.x) / 2, (v.y + w.y) / 2
                    node = self._node(x, y)
                    self._arc(v.node, node, v.a, v.b)
                    self._arc(w.node, node, w.a, w.b)
                    if size <= 2:
                        del self.rings[index]
                        return True
                    if v.a == w.b:  # a notch on one edge closed: the edge runs on through
                        del ring[max(i, (i + 1) % size)]
                        del ring[min(i, (i + 1) % size)]
                        return True
                    ring[i] = _Vertex(x, y, v.a, w.b, node)
                    del ring[(i + 1) % size]
                    return True
        return False

    def _fold(self) -> bool:
        """A spike (a vertex whose edges run back along each other) zips up."""
        for ring in self.rings:
            size = len(ring)
            if size < 3:
                continue
            for i in range(size):
                x = ring[i]
                (ax, ay), (bx, by) = self.unit[x.a], self.unit[x.b]
                if ax * bx + ay * by > -1 + 1e-6:
                    continue
                before, after = ring[i - 1], ring[(i + 1) % size]
                if (  # not a spike unless its sides lie on one line: a sharp corner, then
                    abs(bx * (before.y - x.y) - by * (before.x - x.x)) >= self.eps
                    or abs(ax * (after.y - x.y) - ay * (after.x - x.x)) >= self.eps
                ):
                    continue
                tip = self._close(x)
                if math.hypot(x.x - before.x, x.y - before.y) <= math.hypot(
                    x.x - after.x, x.y - after.y
                ):
                    other = self._close(before)
                    self.segments[x.a].append((tip, other))
                    self.segments[x.b].append((other, tip))
                    before.b = x.b
                else:
                    other = self._close(after)
                    self.segments[x.a].append((tip, other))
                    self.segments[x.b].append((other, tip))
                    after.a = x.a
                del ring[i]
                return True
        return False

    def _die(self) -> bool:
        """A ring without area (a ridge) ends: its edges' faces close along it."""
        for index, ring in enumerate(self.rings):
            size = len(ring)
            if size > 2:
                twice = perimeter = 0.0
                for i in range(size):
                    v, w = ring[i - 1], ring[i]
                    twice += v.x * w.y - w.x * v.y
                    perimeter += math.hypot(w.x - v.x, w.y - v.y)
                if abs(twice) >= 2 * self.eps * perimeter:
                    continue
            nodes = [self._close(v) for v in ring]
            for i, v in enumerate(ring):
                self.segments[v.b].append((nodes[(i + 1) % size], nodes[i]))
            del self.rings[index]
            return True
        return False

    def _split(self) -> bool:
        """A reflex vertex lying on another edge splits the ring (or joins two rings)."""
        vertices, px, py, a, b, nxt = self._snapshot()
        dx, dy = self.dirs[b, 0], self.dirs[b, 1]
        reflex = np.flatnonzero(self.dirs[a, 0] * dy - self.dirs[a, 1] * dx < -1e-9)
        if not len(reflex):
            return False
        length = (px[nxt] - px) * dx + (py[nxt] - py) * dy
        ox = px[reflex][:, None] - px[None, :]
        oy = py[reflex][:, None] - py[None, :]
        along = ox * dx + oy * dy
        # on the edge: the test that ends a reflex vertex's step towards it
        near = (np.abs(oy * dx - ox * dy) < self.eps) & (along > -self.eps)
        near &= along < length + self.eps
        rows = np.arange(len(reflex))
        near[rows, reflex] = False  # the reflex vertex's own edges
        near[rows, np.argsort(nxt)[reflex]] = False
        nodes = np.array([v.node for v in vertices])
        twins = nodes[reflex][:, None]  # the other half of the split that made it
        near &= (nodes[None, :] != twins) & (nodes[nxt][None, :] != twins)
        hits = np.argwhere(near)
        if not len(hits):
            return False
        row, j = hits[0].tolist()
        where = [(k, i) for k, ring in enumerate(self.rings) for i in range(len(ring))]
        self._split_at(*where[int(reflex[row])], *where[j])
        return True

    def _split_at(self, k: int, i: int, k2: int, i2: int) -> None:
        ring = self.rings[k]
        r = ring[i]
        q = self._close(r)
        e = self.rings[k2][i2].b
        first = _Vertex(r.x, r.y, r.a, e, q)  # comes in on r's edge, goes out along e
        second = _Vertex(r.x, r.y, e, r.b, q)  # comes in along e, goes out on r's edge
        if k == k2:
            turned = ring[i:] + ring[:i]
            at = turned.index(ring[i2])
            one = [second, *turned[1 : at + 1]]
            two = [first, *turned[at + 1 :]]
            self.rings[k : k + 1] = [one, two]
        else:
            other = self.rings[k2]
            there = other[i2 + 1 :] + other[: i2 + 1]  # from the edge's end round to its start
            here = ring[i + 1 :] + ring[:i]
            joined = [first, *there, second, *here]
            self.rings = [rg for n, rg in enumerate(self.rings) if n not in (k, k2)] + [joined]

    # -- faces -----------------------------------------------------------------------

    def _faces(self) -> dict[int, list[tuple[int, ...]]]:
        """Each edge's face: its segments chained into loops, after merging nodes that
        coincide (in x, y and time) and dropping segments that cancel out."""
        xyt = np.column_stack([self.x, self.y, self.times])
        alias = _dedupe(xyt, self.eps * 300)
        faces: dict[int, list[tuple[int, ...]]] = {}
        for e in range(self.outline.count):
            segments = [(int(alias[p]), int(alias[q])) for p, q in self.segments[e]]
            segments = [(p, q) for p, q in segments if p != q]
            counts: dict[tuple[int, int], int] = defaultdict(int)
            for seg in segments:
                counts[seg] += 1
            kept = []
            for p, q in segments:
                if counts[(q, p)] > 0 and counts[(p, q)] > 0:
                    counts[(q, p)] -= 1
                    counts[(p, q)] -= 1
                    continue
                if counts[(p, q)] > 0:
                    kept.append((p, q))
                    counts[(p, q)] -= 1
            faces[e] = _chain(kept, list(zip(self.x, self.y, strict=True)), e)
        return faces


def _chain(
    segments: list[tuple[int, int]], where: list[tuple[float, float]], first: int
) -> list[tuple[int, ...]]:
    """Directed segments into closed loops; at a node with several ways on, the leftmost
    turn (which keeps the face on the left)."""
    outgoing: dict[int, list[int]] = defaultdict(list)
    for p, q in segments:
        outgoing[p].append(q)
    loops: list[tuple[int, ...]] = []
    remaining = len(segments)
    while remaining:
        starts = [first] if outgoing.get(first) else sorted(n for n, qs in outgoing.items() if qs)
        start = starts[0]
        loop = [start]
        before, here = -1, start
        while True:
            options = outgoing[here]
            if not options:
                raise Degenerate("a face does not close")
            if len(options) == 1 or before < 0:
                step = options[0]
            else:
                bx, by = where[before]
                hx, hy = where[here]
                din = math.atan2(hy - by, hx - bx)

                def turn(n: int, hx: float = hx, hy: float = hy, din: float = din) -> float:
                    nx, ny = where[n]
                    angle = math.atan2(ny - hy, nx - hx) - din
                    return (angle + math.pi) % (2 * math.pi) - math.pi

                step = max(options, key=lambda n: (turn(n), -n))
            options.remove(step)
            remaining -= 1
            if step == start:
                break
            if len(loop) > len(segments):
                raise Degenerate("a face runs in circles")
            loop.append(step)
            before, here = here, step
        if len(loop) >= 3:
            loops.append(tuple(loop))
    return loops


def _dedupe(points: np.ndarray, eps: float) -> np.ndarray:
    """For each point the smallest index of the points within ``eps`` of it (chained)."""
    count = len(points)
    parent = list(range(count))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if count:
        order = np.argsort(points[:, 0], kind="stable")
        xs = points[order, 0]
        ends = np.searchsorted(xs, xs + eps, side="right")
        for position, i in enumerate(order.tolist()):
            for j in order[position + 1 : int(ends[position])].tolist():
                if np.abs(points[j] - points[i]).max() < eps:
                    ri, rj = root(i), root(j)
                    if ri != rj:
                        parent[max(ri, rj)] = min(ri, rj)
    return np.array([root(i) for i in range(count)], dtype=int)
