"""Roofs on any footprint polygon, holes included, as OSM's Simple 3D Buildings draws them
(SPEC 5): flat, shed, gable, hip, pyramidal, half_hip, side_hip, dutch_gable, gambrel,
bellcast, mansard, saltbox, crosspitched, sawtooth, butterfly, dome, round, onion, zakomar.

Meshes are in map coordinates (x east, y north, z up), from the eaves at ``height``.

Every sloped roof but the shed and the pyramid is cut from a *weighted straight skeleton*
of the footprint, computed here by simulating its wavefront: each wall edge moves inwards
at its weight (speed), and the roof over a point is the time the wavefront reaches it.
Weight 1 everywhere gives the hip roof; weight 0 keeps an edge where it is, so the roof
planes next to it run on to the wall and a vertical gable end rises above it. Gable ends
are the short "caps" of a wing (an edge between two convex corners whose neighbours run
back parallel): on a convex footprint those across the ridge direction (the long side, or
``orientation: across``, or across ``direction``), on any other the ends of its wings,
which the unweighted skeleton shows as triangles under one ridge point. So an L gets a
cross gable with a valley, a T and a U likewise, a courtyard ring a ridge all round.

- flat: a slab (the walls carry the parapet; rooftop.py caps them and sets plant on it);
- shed: one plane, its low side facing ``direction`` (else across the main direction);
- gable: the skeleton with weight 0 on the gable ends; half_hip: the same, the ends
  turning to weight 1 at two thirds of their height (hipped over the top third);
  side_hip: one gable end (at a party wall if one is there), the other hipped;
  dutch_gable (OSM's hipped-and-gabled): the ends hipped up to DUTCH of their gable's
  height, a small gable end above (the edges stop moving there);
- hip: the plain skeleton; pyramidal: every edge slopes to one apex (hip on concave
  outlines and courtyards);
- saltbox: a gable whose side facing ``direction`` moves twice as fast: its slope runs
  twice as far, at half the pitch;
- gambrel and mansard: gable and hip with two slopes (steep to a third of the way in and
  two thirds of the height, then shallow); bellcast: a gable flaring out at the eaves
  (shallow for a quarter of the way in, a tenth of the height, then steep);
- butterfly: two sheds sloping down to a valley along the middle, their sides walls;
- sawtooth: sheds side by side on strips about TOOTH wide, their low sides facing
  ``direction`` (else the long side's southern face), a vertical wall at each high side;
- crosspitched: on a convex outline, a gable over every side, the ridges meeting in the
  middle (two gables crossing, on a rectangle); on any other, the gable roof, whose
  wings' gables cross;
- dome, onion and round: hip, hip and gable roofs whose height is a curve of the
  skeleton time: a quarter circle (round: a barrel with a half-circle section), an onion
  (a bulb that narrows to a point), in flat bands;
- zakomar: half-circle arches (ARCH_SEGMENTS straight pieces each) about ZAKOMARA wide
  along every wall, vertical gables under them, the roof running in from the arches to a
  point that sees the whole outline (a dome where there is none).

Heights: ``pitch`` is the slope of a plane moving at weight 1, unless ``height`` sets the
top; domes and barrels rise by their half width, onions by twice that. ``roof_height``
gives the rise of what ``roof_meshes`` builds. A shape that cannot be built on some
outline (a degenerate skeleton; more than MAX_SKELETON vertices) falls back to hip, then
flat; nothing raises. Walls given as ``fixed`` (party walls, a taller part standing on
the roof) stand still in the skeleton: the roof runs on to them at full height instead
of sloping down (a terrace of hipped houses has one ridge, no valleys between them).
Results are cached per (outline, roof shape, fixed walls), so asking for the height and
then the mesh builds the skeleton once.
"""

from __future__ import annotations

import itertools
import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
import trimesh
from shapely.geometry import Point, Polygon
from shapely.geometry.polygon import orient

from facadecli.city.manifest import Roof
from facadecli.city.skeleton import Degenerate, Skeleton

SLAB = 0.2  # metres: a flat roof's thickness
MAX_TRIANGLES = 2000  # a curved roof's bands are chosen to stay below this
SIDE_TURN = math.radians(10)  # edges turning less than this make one side of a footprint
CAP_CORNER = math.radians(20)  # a gable end's corners turn at least this, at most 180 - it
CAP_PARALLEL = -0.7  # the sides next to a gable end run back: cosine below this
ACROSS = 0.7072  # a gable end lies across the ridge: |cos| of their angle at most this (45°)
PYRAMID_HULL = 0.9  # a pyramid's outline fills this much of its convex hull at least
FACING = 0.5  # a saltbox's long slope: the sides facing its direction within 60°
HALF_HIP = 2 / 3  # a half hip's gable end goes up to this part of its height
DUTCH = 1 / 2  # a hipped-and-gabled roof's ends are hipped up to this part of its height
TOOTH = 6.0  # metres: a sawtooth roof's teeth are about this wide
ZAKOMARA = 6.0  # metres: a zakomar roof's arches are about this wide
ARCH_MIN = 3.0  # metres: walls shorter than this carry no arch
ARCH_SEGMENTS = 8  # straight pieces of a zakomar arch (a half circle)
BREAK = (1 / 3, 2 / 3)  # gambrel and mansard: where the slope changes (in, up)
FLARE = (1 / 4, 1 / 10)  # bellcast: the eaves' flare, this far in rising this much
CURVED = ("dome", "round", "onion")  # profiles in bands (zakomar: curved in plan)
GABLED = ("gable", "half_hip", "dutch_gable", "gambrel", "bellcast", "round", "saltbox", "side_hip")
FIXABLE = ("hip", "pyramidal", "mansard", *GABLED)  # roofs that keep still at party walls
ON_WALL = 0.05  # metres: an edge whose middle is this near a fixed segment, along it, is one


# ---------------------------------------------------------------------------------------
# the public interface


Segment = tuple[tuple[float, float], tuple[float, float]]


def roof_meshes(
    part: Polygon, height: float, roof: Roof, fixed: tuple[Segment, ...] = ()
) -> tuple[trimesh.Trimesh, list[trimesh.Trimesh]]:
    """(the roof, walls filling the space between the eaves and the roof: gable ends).
    ``fixed``: the walls the roof must not slope down to (party walls, a taller part
    standing on this one), as segments: edges along them stand still (weight 0), so the
    roof runs on to them with a gable end, or on into the neighbour's."""
    shape = _shape(part.wkb, *_key(roof), fixed if roof.type in FIXABLE else ())
    if shape.kind == "flat":
        return _slab(part, height), []
    return _mesh(shape, height, _rise(shape, roof))


def roof_height(part: Polygon, roof: Roof) -> float:
    """The roof's top above the eaves: ``roof.height`` if set, else from the pitch and the
    footprint (0 for flat roofs); the top of what ``roof_meshes`` builds."""
    shape = _shape(part.wkb, *_key(roof))
    return _rise(shape, roof)


def _key(roof: Roof) -> tuple[str, float | None, str]:
    """What the shape depends on (not the pitch or height: they scale it)."""
    if roof.type in ("shed", "sawtooth"):
        return roof.type, roof.direction, "along"
    if roof.type in GABLED:
        return roof.type, roof.direction, roof.orientation
    if roof.type == "butterfly":
        return roof.type, None, roof.orientation
    return roof.type, None, "along"


def _rise(shape: _Shape, roof: Roof) -> float:
    if shape.kind == "flat" or shape.top <= 0:
        return 0.0
    if roof.height is not None:
        return float(roof.height)
    if shape.kind in ("dome", "round", "zakomar"):
        return shape.top
    if shape.kind == "onion":
        return 2 * shape.top
    return math.tan(math.radians(roof.pitch)) * shape.top


# ---------------------------------------------------------------------------------------
# shapes: a roof as nodes (x, y, t) with t the height in skeleton time, before a profile


@dataclass(frozen=True)
class _Shape:
    """A roof before its heights: ``t`` rises from 0 at the eaves to ``top``; ``cover``
    faces are lists of rings (outer first) of node indices, planar in (x, y, t);
    ``walls`` are vertical loops with their edge direction (gable ends, a shed's sides)."""

    kind: str
    xy: np.ndarray
    t: np.ndarray
    cover: tuple[tuple[tuple[int, ...], ...], ...]
    walls: tuple[tuple[tuple[int, ...], tuple[float, float]], ...]
    top: float


FLAT = _Shape("flat", np.zeros((0, 2)), np.zeros(0), (), (), 0.0)


@lru_cache(maxsize=512)
def _shape(
    wkb: bytes,
    kind: str,
    direction: float | None,
    orientation: str,
    fixed: tuple[Segment, ...] = (),
) -> _Shape:
    """The shape built for a footprint (as WKB, so it can be a cache key), falling back
    to the shape without its fixed walls, to a hip roof, then to a flat one, rather than
    raising."""
    import shapely

    part = shapely.from_wkb(wkb)
    if kind == "flat" or not isinstance(part, Polygon) or part.is_empty or part.area <= 0:
        return FLAT
    tries = [(kind, fixed)] + [(kind, ())] * bool(fixed)
    tries += [("dome", ())] * (kind == "zakomar")  # an outline no point sees whole
    tries += [] if kind == "hip" else [("hip", fixed)] * bool(fixed) + [("hip", ())]
    with np.errstate(all="ignore"):
        for attempt, still in tries:
            try:
                return _build(part, attempt, direction, orientation, still)
            except Exception:  # a degenerate skeleton, or worse: the simpler shape
                continue
    return FLAT


def _build(
    part: Polygon,
    kind: str,
    direction: float | None,
    orientation: str,
    fixed: tuple[Segment, ...] = (),
) -> _Shape:
    outline = _Outline(part, fixed)
    if kind == "shed":
        return outline.shed(direction)
    if kind == "sawtooth":
        return outline.sawtooth(direction)
    if kind == "butterfly":
        return outline.butterfly(orientation)
    if kind == "pyramidal":
        return outline.hipped("hip") if outline.still else outline.pyramid()
    if kind == "zakomar":
        return outline.zakomar()
    if kind == "crosspitched":  # on wings: their gables cross already
        if outline.convex:
            return outline.crossed()
        return replace(outline.gabled("gable", direction, orientation), kind=kind)
    if kind in GABLED:
        return outline.gabled(kind, direction, orientation)
    if kind in ("hip", "mansard", "dome", "onion"):
        return outline.hipped(kind)
    raise Degenerate(kind)


@dataclass(frozen=True)
class _Side:
    """A run of nearly collinear edges of one ring: its edges, its chord's ends, where it
    is."""

    edges: tuple[int, ...]
    start: np.ndarray
    end: np.ndarray
    ring: int
    index: int  # in its ring's sides


class _Outline:
    """A footprint's rings, cleaned, relative to an origin (for precision), with its
    sides and main direction."""

    def __init__(self, part: Polygon, fixed: tuple[Segment, ...] = ()) -> None:
        part = orient(part, sign=1.0)  # exterior counter-clockwise, holes clockwise
        minx, miny, maxx, maxy = part.bounds
        self.origin = np.array([minx, miny])
        self.scale = max(maxx - minx, maxy - miny, 1e-9)
        self.eps = 1e-8 * max(self.scale, 1.0)
        self.rings: list[np.ndarray] = []
        for k, ring in enumerate((part.exterior, *part.interiors)):
            points = _clean(np.array(ring.coords)[:-1, :2], self.eps * 10)
            if len(points) < 3:
                if k == 0:
                    raise Degenerate("outline")
                continue
            self.rings.append(points)
        self.exact = np.concatenate(self.rings)  # map coordinates of the eave nodes
        self.local = [ring - self.origin for ring in self.rings]
        points = np.concatenate(self.local)
        self.count = len(points)
        sizes = [len(ring) for ring in self.local]
        self.heads = [sum(sizes[:k]) for k in range(len(sizes))]  # each ring's first edge
        nxt = np.concatenate(
            [np.roll(np.arange(h, h + n), -1) for h, n in zip(self.heads, sizes, strict=True)]
        )
        prv = np.concatenate(
            [np.roll(np.arange(h, h + n), 1) for h, n in zip(self.heads, sizes, strict=True)]
        )
        vectors = points[nxt] - points
        lengths = np.hypot(vectors[:, 0], vectors[:, 1])
        self.points, self.next, self.prev = points, nxt, prv
        self.direction = vectors / lengths[:, None]
        self.area = float(part.area)
        self.convex = len(self.local) == 1 and bool(
            (_cross(self.direction[prv], self.direction) >= -1e-9).all()
        )
        centre, main, normal = roof_axes(part)
        self.centre, self.main, self.normal = centre - self.origin, main, normal
        self.still = _still(self.exact, self.direction, self.next, fixed)
        if len(self.still) == self.count:
            raise Degenerate("every wall fixed: nothing to slope")

    # -- shapes -----------------------------------------------------------------------

    def sawtooth(self, direction: float | None) -> _Shape:
        """Sheds side by side on strips about TOOTH wide across ``direction`` (the way
        their slopes face, downhill; else the long side's southern face), each rising
        from its low side at the eaves to its high side, where a vertical wall (a
        factory's glazing) drops to the next strip's low side."""
        down = _compass(direction) if direction is not None else -_north(self.normal)
        reach = self.points @ down
        low, high = float(reach.min()), float(reach.max())
        count = max(1, round((high - low) / TOOTH))
        width = (high - low) / count
        return self._strips(
            "sawtooth", down, [(low + k * width, False) for k in range(count)], width
        )

    def butterfly(self, orientation: str) -> _Shape:
        """Two sheds sloping down to a valley along the middle of the footprint (along
        its long side, or across it with ``orientation: across``), high at the walls,
        their sides vertical walls up to the roof."""
        down = self.normal if orientation != "across" else self.main
        reach = self.points @ down
        low, high = float(reach.min()), float(reach.max())
        width = (high - low) / 2
        return self._strips("butterfly", down, [(low, False), (low + width, True)], width)

    def _strips(
        self, kind: str, down: np.ndarray, strips: list[tuple[float, bool]], width: float
    ) -> _Shape:
        """Sheds on strips ``width`` wide across ``down``, each starting where given
        (along ``down``), rising from 0 at its far side to ``width`` at its near side
        (flipped: the other way); vertical walls where a strip is higher than its
        neighbour or the eaves."""
        if width <= self.eps:
            raise Degenerate(f"{kind}: no room")
        across = _perpendicular(down)
        polygon = Polygon(self.local[0], self.local[1:])
        span = float(np.abs(self.points @ across).max()) * 2 + 1.0
        nodes: dict[tuple[float, float, float], int] = {}
        xy: list[np.ndarray] = []
        ts: list[float] = []

        def node(point: np.ndarray, t: float) -> int:
            key = (round(float(point[0]), 7), round(float(point[1]), 7), round(t, 7))
            if key not in nodes:
                nodes[key] = len(xy)
                xy.append(np.asarray(point, dtype=float))
                ts.append(t)
            return nodes[key]

        for point in self.points:  # the eave nodes first, in order, as _finish wants them
            node(point, 0.0)
        snap = 1e3 * self.eps
        cover: list[tuple[tuple[int, ...], ...]] = []
        walls: list[tuple[tuple[int, ...], tuple[float, float]]] = []
        outline = polygon.boundary.buffer(snap)
        for a, flipped in strips:
            b = a + width
            band = Polygon(
                [
                    down * a - across * span,
                    down * b - across * span,
                    down * b + across * span,
                    down * a + across * span,
                ]
            )
            piece = polygon.intersection(band)
            teeth = [piece] if isinstance(piece, Polygon) else list(getattr(piece, "geoms", []))
            for tooth in teeth:
                if not isinstance(tooth, Polygon) or tooth.area <= snap * self.scale:
                    continue
                tooth = orient(tooth, sign=1.0)
                rings = []
                for ring in (tooth.exterior, *tooth.interiors):
                    points = _clean(np.array(ring.coords)[:-1, :2], self.eps * 10)
                    heights = [
                        min(
                            width, max(0.0, float(p @ down) - a if flipped else b - float(p @ down))
                        )
                        for p in points
                    ]
                    heights = [
                        0.0 if h <= snap else width if h >= width - snap else h for h in heights
                    ]
                    roof = [node(p, h) for p, h in zip(points, heights, strict=True)]
                    rings.append(tuple(roof))
                    for i in range(len(points)):
                        j = (i + 1) % len(points)
                        p, q = points[i], points[j]
                        edge = q - p
                        size = float(np.hypot(*edge))
                        if size <= self.eps:
                            continue
                        d = (float(edge[0] / size), float(edge[1] / size))
                        on_outline = outline.contains(Point(*((p + q) / 2)))
                        riser = heights[i] >= width and heights[j] >= width and not on_outline
                        if not (on_outline or riser) or heights[i] + heights[j] <= 0:
                            continue
                        loop = [node(p, 0.0), node(q, 0.0)]
                        loop += [roof[j]] * (heights[j] > 0) + [roof[i]] * (heights[i] > 0)
                        walls.append((tuple(loop), d))
                cover.append(tuple(rings))
        return self._finish(kind, np.array(xy), np.array(ts), cover, walls, width)

    def shed(self, direction: float | None) -> _Shape:
        """One plane rising away from ``direction`` (its low side faces it)."""
        down = _compass(direction) if direction is not None else -self.normal
        rise = self.points @ -down
        t = rise - rise.min()
        t[t < self.eps] = 0.0
        top = float(t.max())
        if top <= self.eps:
            raise Degenerate("shed")
        xy = [*self.points]
        ts = [*([0.0] * self.count)]
        lifted = list(range(self.count))
        for i in range(self.count):
            if t[i] > 0:
                lifted[i] = len(xy)
                xy.append(self.points[i])
                ts.append(float(t[i]))
        rings = tuple(
            tuple(lifted[head + k] for k in range(len(ring)))
            for head, ring in zip(self.heads, self.local, strict=True)
        )
        walls = []
        for i in range(self.count):
            j = int(self.next[i])
            if t[i] == 0 and t[j] == 0:
                continue
            loop = [i, j] + [lifted[j]] * int(t[j] > 0) + [lifted[i]] * int(t[i] > 0)
            walls.append((tuple(loop), (float(self.direction[i, 0]), float(self.direction[i, 1]))))
        return self._finish("shed", np.array(xy), np.array(ts), (rings,), walls, top)

    def crossed(self) -> _Shape:
        """Crosspitched: a gable over every side of a convex outline, their ridges
        running in from the top of each gable end to the middle, valleys down to the
        corners (on a rectangle: two gable roofs crossing)."""
        if not self.convex:
            raise Degenerate("crosspitched needs a convex outline")
        centre = np.array(Polygon(self.points).centroid.coords[0])
        reach = _cross(self.direction, centre - self.points)  # distance in from each edge
        top = float(reach.min())
        if top <= self.eps:
            raise Degenerate("crosspitched: no room")
        middles = (self.points + self.points[self.next]) / 2
        xy = np.vstack([self.points, middles, centre])
        t = np.concatenate([np.zeros(self.count), np.full(self.count + 1, top)])
        apex = 2 * self.count
        cover = []
        walls = []
        for e in range(self.count):
            m, f = self.count + e, int(self.next[e])
            cover.extend([((e, m, apex),), ((m, f, apex),)])
            walls.append(((e, f, m), (float(self.direction[e, 0]), float(self.direction[e, 1]))))
        return self._finish("crosspitched", xy, t, cover, walls, top)

    def zakomar(self) -> _Shape:
        """Zakomar: the roof of a Russian church, a half-circle arch (a zakomara) about
        ZAKOMARA wide over each stretch of every wall at least ARCH_MIN long, its gable
        a vertical wall, and the roof running in from the arches to a point inside that
        sees the whole outline: over an arch's crest level at the arches' height, down to
        the eaves between two arches. The height over a point a share u of the way from
        the wall to the centre is u x the top + (1 - u) x the arch's over the wall, so
        each triangle from the centre to a piece of arch is one plane and the arches of
        two walls meet at the corner between them. The arches' height is half the width
        of the narrowest (flatter half-ellipses on wider ones)."""
        if len(self.local) != 1:
            raise Degenerate("zakomar: a courtyard")
        centre = self._kernel_point()
        lengths = np.hypot(*(self.points[self.next] - self.points).T)
        arches = [
            0 if size < ARCH_MIN else max(1, round(float(size) / ZAKOMARA)) for size in lengths
        ]
        widths = [size / n for size, n in zip(lengths.tolist(), arches, strict=True) if n]
        if not widths:
            raise Degenerate("zakomar: no wall long enough for an arch")
        top = min(widths) / 2
        xy: list[np.ndarray] = list(self.points)
        ts: list[float] = [0.0] * self.count
        apex = len(xy)
        xy.append(centre)
        ts.append(top)
        cover: list[tuple[tuple[int, ...], ...]] = []
        walls: list[tuple[tuple[int, ...], tuple[float, float]]] = []
        for e in range(self.count):
            a, f = self.points[e], int(self.next[e])
            b = self.points[f]
            d = (float(self.direction[e, 0]), float(self.direction[e, 1]))
            crest: list[int] = [e]  # the top of the wall, from a to b: eaves and arches
            for k in range(arches[e]):
                for step in range(1, ARCH_SEGMENTS + 1):
                    angle = math.pi * step / ARCH_SEGMENTS
                    share = (k + (1 - math.cos(angle)) / 2) / arches[e]
                    rise = top * math.sin(angle)
                    if step == ARCH_SEGMENTS and k == arches[e] - 1:
                        crest.append(f)
                        continue
                    xy.append(a + share * (b - a))
                    ts.append(rise if step < ARCH_SEGMENTS else 0.0)
                    crest.append(len(xy) - 1)
                start = crest[-1 - ARCH_SEGMENTS]
                lifted = crest[-ARCH_SEGMENTS:-1]
                walls.append(((start, crest[-1], *lifted[::-1]), d))
            if not arches[e]:
                crest.append(f)
            cover.extend(((p, q, apex),) for p, q in itertools.pairwise(crest))
        return self._finish("zakomar", np.array(xy), np.array(ts), cover, walls, top)

    def _kernel_point(self) -> np.ndarray:
        """A point inside that sees the whole (single-ring) outline, a share of its size
        in from every wall's line: its centroid, else the pole of inaccessibility."""
        import shapely.ops

        polygon = Polygon(self.points)
        for point in (
            np.array(polygon.centroid.coords[0]),
            np.array(shapely.ops.polylabel(polygon, self.scale * 1e-3).coords[0]),
        ):
            reach = _cross(self.direction, point - self.points)  # distance in from each edge
            if (reach > self.scale * 1e-3).all():
                return point
        raise Degenerate("no point sees the whole outline")

    def pyramid(self) -> _Shape:
        """Every edge slopes up to one apex, which must see the whole outline."""
        polygon = Polygon(self.points)
        if len(self.local) != 1 or polygon.area < PYRAMID_HULL * polygon.convex_hull.area:
            return self.hipped("hip")  # a courtyard or a concave outline
        try:
            apex = self._kernel_point()
        except Degenerate:
            return self.hipped("hip")
        reach = _cross(self.direction, apex - self.points)  # distance in from each edge
        top = float(reach.min())
        xy = np.vstack([self.points, apex])
        t = np.concatenate([np.zeros(self.count), [top]])
        faces = [((i, int(self.next[i]), self.count),) for i in range(self.count)]
        return self._finish("pyramidal", xy, t, faces, [], top)

    def hipped(self, kind: str) -> _Shape:
        weights = [0.0 if e in self.still else 1.0 for e in range(self.count)]
        skeleton = Skeleton(self, weights, {})
        return self._from_skeleton(kind, skeleton, {})

    def gabled(self, kind: str, direction: float | None, orientation: str) -> _Shape:
        sides = self._sides()
        caps = [side for side in sides if self._is_cap(side, sides)]
        if direction is not None:
            ridge = _perpendicular(_compass(direction))
        elif orientation == "across":
            ridge = self.normal
        else:
            ridge = self.main
        plain: Skeleton | None = None
        if direction is not None or orientation == "across" or self.convex:
            caps = [side for side in caps if abs(float(_chord(side) @ ridge)) < ACROSS]
        elif caps:  # the ends of the wings: triangles of the plain skeleton under one point
            plain = Skeleton(self, [1.0] * self.count, {})
            caps = [side for side in caps if self._under_one_point(side, plain)]
        caps.sort(key=lambda side: (round(abs(float(_chord(side) @ ridge)), 9), side.edges[0]))
        chosen: list[_Side] = []
        for side in caps:
            ring = [s for s in sides if s.ring == side.ring]
            neighbours = {ring[side.index - 1].edges, ring[(side.index + 1) % len(ring)].edges}
            if not any(other.edges in neighbours for other in chosen):
                chosen.append(side)
        weights = [1.0] * self.count
        if kind == "saltbox":
            facing = _compass(direction) if direction is not None else _north(self.normal)
            for side in sides:
                outward = -_perpendicular(_chord(side))
                if float(outward @ facing) > FACING:
                    for e in side.edges:
                        weights[e] = 2.0
        if kind == "side_hip":  # one gable end: at a fixed wall if one is, else the first
            fixed = any(e in self.still for side in chosen for e in side.edges)
            chosen = [] if fixed else chosen[:1]
        switches: dict[int, float] = {}
        stops: dict[int, float] = {}
        for side in chosen:
            if kind == "dutch_gable":  # hipped up to DUTCH of the way, then a gable end
                apex = self._gable_apex(side)
                if apex is not None:
                    for e in side.edges:
                        stops[e] = DUTCH * apex
                continue
            for e in side.edges:
                weights[e] = 0.0
            if kind == "half_hip":
                apex = self._gable_apex(side)
                if apex is not None:
                    for e in side.edges:
                        switches[e] = HALF_HIP * apex
        for e in self.still:  # party walls: gable ends too
            weights[e] = 0.0
            switches.pop(e, None)
            stops.pop(e, None)
        if plain is not None and all(w == 1.0 for w in weights) and not stops:
            return self._from_skeleton(kind, plain, {})  # no gable ends after all
        skeleton = Skeleton(self, weights, switches, stops)
        return self._from_skeleton(kind, skeleton, switches, stops)

    # -- sides and gable ends ---------------------------------------------------------

    def _sides(self) -> list[_Side]:
        sides: list[_Side] = []
        for k, (head, ring) in enumerate(zip(self.heads, self.local, strict=True)):
            size = len(ring)
            edges = list(range(head, head + size))
            turns = [_angle(self.direction[int(self.prev[e])], self.direction[e]) for e in edges]
            corners = [i for i, turn in enumerate(turns) if abs(turn) >= SIDE_TURN]
            if not corners:
                runs = [[e] for e in edges]
            else:
                first = corners[0]
                runs = []
                for step in range(size):
                    e = edges[(first + step) % size]
                    if runs and (
                        abs(turns[e - head]) < SIDE_TURN
                        and abs(_angle(self.direction[runs[-1][0]], self.direction[e])) < SIDE_TURN
                    ):
                        runs[-1].append(e)
                    else:
                        runs.append([e])
            for index, run in enumerate(runs):
                start = self.points[run[0]]
                end = self.points[int(self.next[run[-1]])]
                sides.append(_Side(tuple(run), start, end, k, index))
        return sides

    def _is_cap(self, side: _Side, sides: list[_Side]) -> bool:
        ring = [s for s in sides if s.ring == side.ring]
        if len(ring) < 3:
            return False
        before, after = ring[side.index - 1], ring[(side.index + 1) % len(ring)]
        into = _angle(self.direction[before.edges[-1]], self.direction[side.edges[0]])
        out = _angle(self.direction[side.edges[-1]], self.direction[after.edges[0]])
        convex = all(CAP_CORNER <= turn <= math.pi - CAP_CORNER for turn in (into, out))
        back = float(self.direction[before.edges[-1]] @ self.direction[after.edges[0]])
        return convex and back < CAP_PARALLEL

    def _under_one_point(self, side: _Side, plain: Skeleton) -> bool:
        """Whether the plain skeleton's faces over the side make one triangle."""
        loops = [loop for e in side.edges for loop in plain.faces[e]]
        nodes = {n for loop in loops for n in loop} - set(range(self.count))
        if not nodes:
            return False
        apex = max(nodes, key=lambda n: (plain.t[n], -n))
        triangle = _area(np.array([side.start, side.end, plain.xy[apex]]))
        total = sum(_area(plain.xy[list(loop)]) for loop in loops)
        return triangle > 0 and abs(total - triangle) <= 1e-6 * self.scale**2 + 1e-3 * triangle

    def _gable_apex(self, side: _Side) -> float | None:
        """The skeleton time where the roof planes of the sides next to a gable end meet
        above it (the top of the gable end), if they do above the side."""
        before = int(self.prev[side.edges[0]])
        after = int(self.next[side.edges[-1]])
        n1, n2 = _perpendicular(self.direction[before]), _perpendicular(self.direction[after])
        p1, p2 = self.points[before], self.points[after]

        def gap(p: np.ndarray) -> float:
            return float(n1 @ (p - p1) - n2 @ (p - p2))

        g0, g1 = gap(side.start), gap(side.end)
        if g0 * g1 >= 0:
            return None
        apex = side.start + g0 / (g0 - g1) * (side.end - side.start)
        height = float(n1 @ (apex - p1))
        return height if height > self.eps else None

    # -- from a skeleton to a shape ----------------------------------------------------

    def _from_skeleton(
        self,
        kind: str,
        skeleton: Skeleton,
        switches: dict[int, float],
        stops: dict[int, float] | None = None,
    ) -> _Shape:
        """The skeleton's faces as roof faces, and as walls where edges stood still
        (``switches``: still until then; ``stops``: still from then); each roof face must
        lie in its edge's plane: t = its start + distance / weight."""
        stops = stops or {}
        cover: list[tuple[tuple[int, ...], ...]] = []
        walls: list[tuple[tuple[int, ...], tuple[float, float]]] = []
        xy, t = skeleton.xy, skeleton.t
        for e in range(self.count):
            d = (float(self.direction[e, 0]), float(self.direction[e, 1]))
            slopes = skeleton.weights[e] > 0 and e not in switches and e not in stops
            start, weight = switches.get(e, 0.0), skeleton.weights[e] if slopes else 1.0
            for face in skeleton.faces[e]:
                if slopes:
                    wall, roofs = None, [face]
                elif e in stops:
                    wall, roofs = self._split_face(e, face, xy, t, stops[e], above=True)
                else:
                    wall, roofs = self._split_face(e, face, xy, t, switches.get(e))
                if wall is not None:
                    walls.append((wall, d))
                for roof in roofs:
                    distance = _cross(self.direction[e], xy[list(roof)] - self.points[e])
                    if np.abs(t[list(roof)] - start - distance / weight).max() > 1e3 * self.eps:
                        raise Degenerate(f"{kind}: a face is not flat")
                    cover.append((roof,))
        top = float(t.max()) if len(t) else 0.0
        if top <= self.eps:
            raise Degenerate("no rise")
        return self._finish(kind, xy, t, cover, walls, top)

    def _split_face(
        self,
        e: int,
        loop: tuple[int, ...],
        xy: np.ndarray,
        t: np.ndarray,
        switch: float | None,
        above: bool = False,
    ) -> tuple[tuple[int, ...] | None, list[tuple[int, ...]]]:
        """A face of an edge that first stood still: (its vertical part, its sloped
        parts). The wall is the face's nodes reached before the edge began to move (on
        its line), in order; each run of later nodes, with the nodes on either side, is a
        sloped part (a half hip's top; two, if the roof came down to the wall between).
        ``above``: an edge that moved, then stopped at ``switch``: the wall is the nodes
        reached after, the sloped part those before (a hipped-and-gabled roof's end)."""
        if e not in loop:
            return None, [loop] if abs(_area(xy[list(loop)])) > self.eps * self.scale else []
        start = loop.index(e)
        loop = loop[start:] + loop[:start]
        if switch is None:
            return loop, []
        if above:
            on_wall = t[list(loop)] >= switch - self.eps
            if not on_wall.any():  # the edge was gone before it stopped: all slope
                return None, [loop]
            first = int(np.argmax(on_wall))  # the loop from a wall node: runs of slope
            loop = loop[first:] + loop[:first]
        on = t[list(loop)] >= switch - self.eps if above else t[list(loop)] <= switch + self.eps
        wall = tuple(n for n, kept in zip(loop, on.tolist(), strict=True) if kept)
        slopes: list[tuple[int, ...]] = []
        size, i = len(loop), 1
        while i < size:
            if on[i]:
                i += 1
                continue
            j = i
            while j < size and not on[j]:
                j += 1
            piece = (loop[i - 1], *loop[i:j], loop[j % size])
            if len(set(piece)) >= 3:
                slopes.append(piece)
            i = j
        return (wall if len(set(wall)) >= 3 else None), slopes

    def _finish(
        self,
        kind: str,
        xy: np.ndarray,
        t: np.ndarray,
        cover: Sequence[tuple[tuple[int, ...], ...]],
        walls: Sequence[tuple[tuple[int, ...], tuple[float, float]]],
        top: float,
    ) -> _Shape:
        """Check that the cover tiles the footprint once, and go back to map coordinates."""
        signed = sum(
            _area(xy[list(face[0])]) - sum(abs(_area(xy[list(h)])) for h in face[1:])
            for face in cover
        )
        folded = sum(abs(_area(xy[list(face[0])])) for face in cover if len(face) == 1)
        tolerance = 1e-6 * self.area + 1e-9
        if abs(signed - self.area) > tolerance or (
            all(len(face) == 1 for face in cover) and abs(folded - self.area) > tolerance
        ):
            raise Degenerate(f"{kind}: the faces do not tile the footprint")
        cover, walls = self._mend(xy, t, cover, walls)
        world = xy + self.origin
        world[: self.count] = self.exact  # the eaves exactly where the walls are
        return _Shape(kind, world, t, tuple(cover), tuple(walls), top)

    def _mend(
        self,
        xy: np.ndarray,
        t: np.ndarray,
        cover: Sequence[tuple[tuple[int, ...], ...]],
        walls: Sequence[tuple[tuple[int, ...], tuple[float, float]]],
    ) -> tuple[
        list[tuple[tuple[int, ...], ...]], list[tuple[tuple[int, ...], tuple[float, float]]]
    ]:
        """Put into every loop the nodes that lie on its edges (where two faces meet a
        third along one line), so that faces share their edges and the mesh is closed."""
        loops = [ring for face in cover for ring in face] + [loop for loop, _ in walls]
        used = np.array(sorted({n for loop in loops for n in loop}))
        if not len(used):
            return list(cover), list(walls)
        points = np.column_stack([xy[used], t[used]])
        starts = np.array([p for loop in loops for p in loop])
        ends = np.array([loop[(i + 1) % len(loop)] for loop in loops for i in range(len(loop))])
        lookup = {int(n): i for i, n in enumerate(used.tolist())}
        a = points[[lookup[int(n)] for n in starts]]
        v = points[[lookup[int(n)] for n in ends]] - a
        length2 = np.maximum((v * v).sum(axis=1), 1e-300)
        offset = points[None, :, :] - a[:, None, :]  # (segments, nodes, 3)
        u = (offset * v[:, None, :]).sum(axis=2) / length2[:, None]
        miss = offset - u[..., None] * v[:, None, :]
        tolerance = 300 * self.eps
        on = (u > 1e-9) & (u < 1 - 1e-9) & ((miss * miss).sum(axis=2) < tolerance**2)
        if not on.any():
            return list(cover), list(walls)
        inserts: dict[tuple[int, int], list[int]] = {}
        for segment, node in np.argwhere(on).tolist():
            key = (int(starts[segment]), int(ends[segment]))
            inserts.setdefault(key, []).append(node)

        def mended(loop: tuple[int, ...]) -> tuple[int, ...]:
            out: list[int] = []
            for i, p in enumerate(loop):
                q = loop[(i + 1) % len(loop)]
                out.append(p)
                found = inserts.get((p, q), [])
                if found:
                    segment = np.flatnonzero((starts == p) & (ends == q))[0]
                    found = sorted(found, key=lambda n: float(u[segment, n]))
                    out.extend(int(used[n]) for n in found if int(used[n]) not in (p, q))
            return tuple(out)

        faces: list[tuple[tuple[int, ...], ...]] = []
        for face in cover:
            if len(face) == 1:  # a face pinched at a node: two faces
                faces.extend((ring,) for ring in _pinched(mended(face[0])))
            else:
                faces.append(tuple(mended(ring) for ring in face))
        return faces, [(mended(loop), d) for loop, d in walls]


# ---------------------------------------------------------------------------------------
# meshes


def _slab(part: Polygon, height: float) -> trimesh.Trimesh:
    try:
        slab = trimesh.creation.extrude_polygon(part, SLAB)
    except Exception:  # a sliver that cannot be triangulated: nothing to see
        return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), process=False)
    slab.apply_translation((0, 0, height - SLAB))
    return slab


def _profile(kind: str, bands: int) -> tuple[np.ndarray, np.ndarray]:
    """The roof's section, from the eaves (0, 0) to the top (1, 1): (in, up) fractions."""
    if kind in ("gambrel", "mansard"):
        return np.array([0.0, BREAK[0], 1.0]), np.array([0.0, BREAK[1], 1.0])
    if kind == "bellcast":  # shallow at the eaves, then steep
        return np.array([0.0, FLARE[0], 1.0]), np.array([0.0, FLARE[1], 1.0])
    if kind in ("dome", "round"):
        angle = np.linspace(0, math.pi / 2, bands + 1)
        return 1 - np.cos(angle), np.sin(angle)
    if kind == "onion":  # the section narrows from the eaves, convex then concave, to a point
        up = np.linspace(0, 1, bands + 1)
        return (1 - np.cos(math.pi * up**1.5)) / 2, up
    return np.array([0.0, 1.0]), np.array([0.0, 1.0])


def _mesh(
    shape: _Shape, eaves: float, rise: float
) -> tuple[trimesh.Trimesh, list[trimesh.Trimesh]]:
    """The shape's faces in triangles (a curved roof's cut in as many bands as keep it
    under MAX_TRIANGLES), its heights from the eaves up to ``eaves + rise``, and its
    walls closed up to the roof."""
    xy = [tuple(p) for p in shape.xy.tolist()]
    t = shape.t.tolist()
    triangles: list[tuple[int, int, int]] = []
    for face in shape.cover:
        triangles.extend(_triangulate(face, shape.xy))
    bands = 1
    if shape.kind in CURVED:
        span = np.array([[t[i] for i in tri] for tri in triangles]).reshape(-1, 3)
        for bands in (24, 16, 12, 8, 6, 4, 3, 2, 1):
            edges = _profile(shape.kind, bands)[0][1:-1] * shape.top
            crossing = (
                np.searchsorted(edges, span.max(axis=1)) - np.searchsorted(edges, span.min(axis=1))
            ).sum()
            if len(triangles) + 2 * crossing <= MAX_TRIANGLES - 200:
                break
    inward, upward = _profile(shape.kind, bands)
    levels = inward[1:-1] * shape.top
    cuts: dict[tuple[int, int], list[int]] = defaultdict(list)
    if len(levels):
        triangles = _slice(triangles, xy, t, levels, cuts)
    z = eaves + rise * np.interp(np.array(t) / shape.top, inward, upward)
    vertices = np.column_stack([np.array(xy), z])
    cover = _trimesh(vertices, triangles)
    walls: list[tuple[int, int, int]] = []
    for loop, direction in shape.walls:
        walls.extend(_wall(loop, direction, vertices, t, cuts))
    return cover, ([_trimesh(vertices, walls)] if walls else [])


def _trimesh(vertices: np.ndarray, triangles: list[tuple[int, int, int]]) -> trimesh.Trimesh:
    if not triangles:
        return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int), process=False)
    faces = np.array(triangles, dtype=np.int64)
    used, inverse = np.unique(faces, return_inverse=True)
    return trimesh.Trimesh(vertices[used], inverse.reshape(-1, 3), process=False)


def _triangulate(face: tuple[tuple[int, ...], ...], xy: np.ndarray) -> list[tuple[int, int, int]]:
    """A planar face (rings of nodes) in triangles turning counter-clockwise in plan."""
    if len(face) == 1:
        loop = list(face[0])
        if _area(xy[loop]) < 0:
            loop.reverse()
        return _ears(loop, xy[loop])
    import mapbox_earcut

    rings = [list(r) for r in face]
    nodes = [n for r in rings for n in r]
    ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
    found = mapbox_earcut.triangulate_float64(xy[nodes].astype(np.float64), ends)
    result = []
    for i, j, k in np.asarray(found).reshape(-1, 3).tolist():
        tri = (nodes[i], nodes[j], nodes[k])
        if _area(xy[list(tri)]) < 0:
            tri = (tri[0], tri[2], tri[1])
        result.append(tri)
    return _through(result, nodes, xy)


def _through(
    triangles: list[tuple[int, int, int]], nodes: list[int], xy: np.ndarray
) -> list[tuple[int, int, int]]:
    """Triangles split where a node lies on one of their edges (earcut may run an edge
    through vertices of rings in line with it), so that the walls meet every vertex."""
    points = xy[nodes]
    tolerance = 1e-9 * max(1.0, float(np.abs(points).max()))
    done: list[tuple[int, int, int]] = []
    todo = list(triangles)
    while todo:
        tri = todo.pop()
        for n in range(3):
            a, b, c = tri[n], tri[(n + 1) % 3], tri[(n + 2) % 3]
            v = xy[b] - xy[a]
            offset = points - xy[a]
            u = (offset @ v) / max(float(v @ v), 1e-300)
            gap = np.abs(offset[:, 0] * v[1] - offset[:, 1] * v[0]) / max(math.hypot(*v), 1e-300)
            on = np.flatnonzero((u > 1e-9) & (u < 1 - 1e-9) & (gap < tolerance))
            if len(on):
                m = nodes[int(on[np.argmin(u[on])])]
                todo.extend([(a, m, c), (m, b, c)])
                break
        else:
            done.append(tri)
    return done


def _ears(loop: list[int], points: np.ndarray) -> list[tuple[int, int, int]]:
    """Ear clipping of a counter-clockwise loop that keeps every vertex, collinear ones
    too (so faces meet without cracks). It cuts a well-shaped ear when there is one, the
    best there is otherwise, so that slivers along a straight run of vertices stay out."""
    index = list(range(len(loop)))
    pts = points.tolist()
    tiny = 1e-14 * max(1.0, float(np.abs(points).max())) ** 2
    result: list[tuple[int, int, int]] = []
    while len(index) > 3:
        size = len(index)
        best, chosen = 0.0, -1
        for k in range(size):
            i0, i1, i2 = index[k - 1], index[k], index[(k + 1) % size]
            (ax, ay), (bx, by), (cx, cy) = pts[i0], pts[i1], pts[i2]
            cross = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
            if cross <= tiny:
                continue
            longest = max((bx - ax) ** 2 + (by - ay) ** 2, (cx - bx) ** 2 + (cy - by) ** 2)
            shape = cross / max(longest, (ax - cx) ** 2 + (ay - cy) ** 2)
            if shape <= best:
                continue
            blocked = False
            for m in index:
                if m in (i0, i1, i2):
                    continue
                px, py = pts[m]
                if (px, py) in ((ax, ay), (bx, by), (cx, cy)):
                    continue
                if (
                    (bx - ax) * (py - ay) - (by - ay) * (px - ax) >= -tiny
                    and (cx - bx) * (py - by) - (cy - by) * (px - bx) >= -tiny
                    and (ax - cx) * (py - cy) - (ay - cy) * (px - cx) >= -tiny
                ):
                    blocked = True
                    break
            if not blocked:
                best, chosen = shape, k
                if shape > 0.1:  # good enough: no need to look further
                    break
        if chosen < 0:  # only degenerate ears left: a fan keeps the loop closed
            break
        k = chosen
        result.append((loop[index[k - 1]], loop[index[k]], loop[index[(k + 1) % len(index)]]))
        del index[k]
    for k in range(1, len(index) - 1):
        result.append((loop[index[0]], loop[index[k]], loop[index[k + 1]]))
    return result


def _slice(
    triangles: list[tuple[int, int, int]],
    xy: list[tuple[float, ...]],
    t: list[float],
    levels: np.ndarray,
    cuts: dict[tuple[int, int], list[int]],
) -> list[tuple[int, int, int]]:
    """Cut triangles along the profile's levels (lines of equal skeleton time), so each
    piece lies in one band. A cut point is made once per edge and level, so triangles
    (and gable walls) sharing an edge share its cut points."""
    made: dict[tuple[int, int, int], int] = {}
    tol = 1e-9 * max(1.0, float(levels.max()))  # a node this near a level lies on it
    bounds = [-math.inf, *levels.tolist(), math.inf]

    def cut(p: int, q: int, k: int) -> int:
        low, high = (p, q) if p < q else (q, p)
        key = (low, high, k)
        if key not in made:
            f = (float(levels[k]) - t[low]) / (t[high] - t[low])
            (x0, y0), (x1, y1) = xy[low], xy[high]
            made[key] = len(xy)
            xy.append((x0 + f * (x1 - x0), y0 + f * (y1 - y0)))
            t.append(float(levels[k]))
            cuts[(low, high)].append(made[key])
        return made[key]

    result: list[tuple[int, int, int]] = []
    for tri in triangles:
        ts = [t[n] for n in tri]
        first = int(np.searchsorted(levels, min(ts) + tol, side="left"))
        last = int(np.searchsorted(levels, max(ts) - tol, side="right"))
        if first >= last:
            result.append(tri)
            continue
        ring: list[int] = []  # the triangle's outline with its cut points
        for n, p in enumerate(tri):
            q = tri[(n + 1) % 3]
            ring.append(p)
            lo, hi = min(t[p], t[q]) + tol, max(t[p], t[q]) - tol
            ks = [k for k in range(first, last) if lo < levels[k] < hi]
            ring.extend(cut(p, q, k) for k in (ks if t[p] < t[q] else ks[::-1]))
        for k in range(first, last + 1):  # the band from level k - 1 to level k
            low, high = bounds[k] - tol, bounds[k + 1] + tol
            band = [n for n in ring if low <= t[n] <= high]
            result.extend(_fan(band, xy))
    return result


def _fan(poly: list[int], xy: list[tuple[float, ...]]) -> list[tuple[int, int, int]]:
    """A convex counter-clockwise polygon in triangles, from a corner that makes none flat
    (its collinear points stay vertices, so neighbours meet them)."""
    size = len(poly)
    if size < 3:
        return []
    if size == 3:
        return [(poly[0], poly[1], poly[2])]
    for apex in range(size):
        fan = [
            (poly[apex], poly[(apex + k) % size], poly[(apex + k + 1) % size])
            for k in range(1, size - 1)
        ]
        if all(_flat_area(xy, tri) > 1e-14 for tri in fan):
            return fan
    return [(poly[0], poly[k], poly[k + 1]) for k in range(1, size - 1)]


def _flat_area(xy: list[tuple[float, ...]], tri: tuple[int, int, int]) -> float:
    (ax, ay), (bx, by), (cx, cy) = xy[tri[0]], xy[tri[1]], xy[tri[2]]
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def _wall(
    loop: tuple[int, ...],
    direction: tuple[float, float],
    vertices: np.ndarray,
    t: list[float],
    cuts: dict[tuple[int, int], list[int]],
) -> list[tuple[int, int, int]]:
    """A vertical wall loop (with the cut points of the roof bands on its edges) in
    triangles facing out of the building."""
    nodes: list[int] = []
    for n, p in enumerate(loop):
        q = loop[(n + 1) % len(loop)]
        nodes.append(p)
        between = cuts.get((min(p, q), max(p, q)), [])
        nodes.extend(sorted(between, key=lambda c: t[c], reverse=t[p] > t[q]))
    d = np.array(direction)
    plane = np.column_stack([vertices[nodes, :2] @ d, vertices[nodes, 2]])
    if _area(plane) < 0:
        nodes.reverse()
        plane = plane[::-1]
    return [(nodes[i], nodes[j], nodes[k]) for i, j, k in _ears(list(range(len(nodes))), plane)]


# ---------------------------------------------------------------------------------------
# small geometry


def _still(
    points: np.ndarray, direction: np.ndarray, following: np.ndarray, fixed: tuple[Segment, ...]
) -> frozenset[int]:
    """The edges (from ``points[e]`` to ``points[following[e]]``) lying along a fixed
    segment: parallel, their middle within ON_WALL of it."""
    found: set[int] = set()
    for a, b in fixed:
        start, end = np.array(a, dtype=float), np.array(b, dtype=float)
        span = end - start
        size = float(np.hypot(*span))
        if size <= 0:
            continue
        along = span / size
        middle = (points + points[following]) / 2 - start
        u = middle @ along
        off = np.abs(_cross(np.broadcast_to(along, middle.shape), middle))
        parallel = np.abs(_cross(direction, np.broadcast_to(along, direction.shape))) < 0.05
        near = (u >= -ON_WALL) & (u <= size + ON_WALL) & (off <= ON_WALL) & parallel
        found.update(int(e) for e in np.flatnonzero(near))
    return frozenset(found)


def _clean(points: np.ndarray, eps: float) -> np.ndarray:
    """A ring without repeated points and spikes (edges turning right back)."""
    pts = [tuple(p) for p in points.tolist()]
    changed = True
    while changed and len(pts) >= 3:
        changed = False
        for i in range(len(pts)):
            a, b, c = np.array(pts[i - 1]), np.array(pts[i]), np.array(pts[(i + 1) % len(pts)])
            if np.hypot(*(b - a)) < eps:
                del pts[i]
                changed = True
                break
            u, v = b - a, c - b
            lu, lv = np.hypot(*u), np.hypot(*v)
            if lv >= eps and float(u @ v) / (lu * lv) < -1 + 1e-9:
                del pts[i]
                changed = True
                break
    return np.array(pts, dtype=float)


def _pinched(loop: tuple[int, ...]) -> list[tuple[int, ...]]:
    """A loop that passes a node twice, as the simple loops it is made of."""
    seen: dict[int, int] = {}
    for i, n in enumerate(loop):
        if n in seen:
            inner = loop[seen[n] : i]
            outer = loop[: seen[n]] + loop[i:]
            return [part for piece in (outer, inner) if len(piece) >= 3 for part in _pinched(piece)]
        seen[n] = i
    return [loop]


def _area(points: np.ndarray) -> float:
    """Signed area of a ring (counter-clockwise positive)."""
    if len(points) < 3:
        return 0.0
    x, y = points[:, 0], points[:, 1]
    return float((x[:-1] @ y[1:] - x[1:] @ y[:-1] + x[-1] * y[0] - x[0] * y[-1]) / 2)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.asarray(u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0])


def _cross1(u: np.ndarray | tuple[float, float], v: np.ndarray | tuple[float, float]) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    """The turn from direction u to v (left positive), in radians."""
    return math.atan2(_cross1(u, v), float(u @ v))


def _perpendicular(v: np.ndarray) -> np.ndarray:
    """Turned a quarter left (the inward normal of an edge along v)."""
    return np.array([-v[1], v[0]])


def _chord(side: _Side) -> np.ndarray:
    v = side.end - side.start
    return np.asarray(v / max(float(np.hypot(*v)), 1e-300))


def _compass(degrees: float) -> np.ndarray:
    """A compass bearing (0 north, 90 east) as a map vector (x east, y north)."""
    a = math.radians(degrees)
    return np.array([math.sin(a), math.cos(a)])


def _north(normal: np.ndarray) -> np.ndarray:
    """The normal, or its opposite, whichever faces north (east if neither)."""
    if abs(normal[1]) > 1e-9:
        return normal if normal[1] > 0 else -normal
    return normal if normal[0] > 0 else -normal


def roof_axes(part: Polygon) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centre, main direction (the long side of the minimum rotated rectangle) and its
    normal; the direction points east-ish (north for a north-south building)."""
    corners = np.array(part.minimum_rotated_rectangle.exterior.coords)[:4]
    sides = [corners[1] - corners[0], corners[2] - corners[1]]
    long_side = max(sides, key=lambda v: (round(float(np.hypot(*v)), 9), float(v[0])))
    direction = long_side / max(float(np.hypot(*long_side)), 1e-300)
    if direction[0] < -1e-9 or (abs(direction[0]) <= 1e-9 and direction[1] < 0):
        direction = -direction
    return corners.mean(axis=0), direction, _perpendicular(direction)
