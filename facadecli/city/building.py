"""A whole building: a volume a part of its footprint (s3db.py: walls from their base to
the eaves, the roof on them), every wall edge a façade facing outwards (the spec its wall
rule gives), corner posts where two façades meet outside, the roof (a flat one with its
coping and plant: rooftop.py) and the ground, as meshes in one scene (SPEC 5; DESIGN
"Buildings and cities").

The vertical axis of a spec is solved once per wall height, so floor lines meet at the
corners; the horizontal axis once per (spec, rung of wall lengths) for the whole run
(see :class:`AxisCache`). Party walls, walls shorter than ``min_facade_width``, and walls
no layout fits are plain walls.

World frame: glTF's, metres: x east, y up, z south (map north is -z).
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from shapely.geometry import Polygon

from facadecli.city.entrances import DOOR_MATERIAL, along_wall, with_doors
from facadecli.city.footprints import Footprint
from facadecli.city.manifest import Roof, WallRule
from facadecli.city.roofs import roof_meshes
from facadecli.city.rooftop import METAL_NAME, ROOFLIGHT_NAME, UNITS, coping, plant
from facadecli.city.s3db import (
    MIN_EDGE,
    POST,
    Heights,
    Post,
    Volume,
    along,
    party_zone,
    roof_only,
    roof_outlines,
    roof_solid,
    volume,
)
from facadecli.city.sides import facing, sides
from facadecli.errors import InfeasibleError, SearchLimitError
from facadecli.export.instancing import MIN_INSTANCES, MIN_TRIANGLES
from facadecli.geometry.facade import (
    ROOMS,
    facade_scene,
    look,
    material_names,
    metric_uv,
    pbr,
    plane_uv,
    projection,
    see_through,
    tangent_space,
    texture_metres,
    weld,
)
from facadecli.layout import (
    BUILTIN_INTERIOR,
    DEFAULT_MATERIAL,
    INTERIOR_MATERIAL,
    Layout,
    build_shapes,
)
from facadecli.materials import LIBRARY
from facadecli.solver.axis import AxisLayout, solve_axis_alternatives
from facadecli.solver.budgets import safety_clock
from facadecli.spec.model import Material, Spec

WALL = Material(color="#cfc6b8", roughness=0.9)
ROOF = LIBRARY["roof-tiles"]  # pitched roofs: clay tiles, courses along the eaves
FLAT_ROOF = LIBRARY["concrete"].model_copy(update={"color": "#77736c"})  # a flat roof's deck
# What a flat roof is covered with, one of these a building (:func:`flat_roof`): gravel
# ballast, dark bitumen felt, a light-grey single-ply sheet, a bare concrete deck. Four
# materials at most for all the flat roofs of a city, shared by the buildings that wear one
FLAT_ROOFS = (
    LIBRARY["gravel"],
    LIBRARY["membrane"],
    LIBRARY["membrane"].model_copy(update={"color": "#a3a5a2", "roughness": 0.6}),
    FLAT_ROOF,
)
GROUND = Material(color="#808080", roughness=1.0)
ROOF_METAL = LIBRARY["metal"]  # a flat roof's coping, plant and rooflights' kerbs (rooftop.py)
ROOFLIGHT = LIBRARY["float-glass"]  # the rooflights' glazing
DOOR = LIBRARY["timber"].model_copy(update={"color": "#5a3a22"})  # doors at entrances
WALL_NAME, ROOF_NAME, GROUND_NAME = "wall", "roof", "ground"  # a spec may define them
FLAT_ROOF_NAME = "flat_roof"
ROOFS = (ROOF_NAME, FLAT_ROOF_NAME)  # their textures lie in their slopes (plane_uv)
SLAB = 0.2  # metres: thickness of flat roofs and plain walls


STRETCH = 0.02  # rungs of the ladder of wall lengths are this share apart


def rung(length: float) -> int:
    """The step of the ladder of lengths STRETCH apart nearest to ``length``."""
    return round(math.log(length) / math.log1p(STRETCH))


def rung_length(step: int) -> float:
    return round(math.exp(step * math.log1p(STRETCH)), 6)


def solve_rung(spec: Spec, axis: str, canvas: float, variants: int = 1) -> tuple[AxisLayout, ...]:
    """An axis solved at a rung's length: the best layout and up to ``variants`` - 1 others
    nearly as good (as ``facade vary`` draws them); none where no layout fits."""
    try:
        deadline = safety_clock() + spec.solver.time_limit / 2
        found = solve_axis_alternatives(spec, axis, canvas, deadline, variants)  # type: ignore[arg-type]
    except (InfeasibleError, SearchLimitError):
        return ()
    return tuple(found)


FacadeMeshes = tuple[tuple[str, np.ndarray, np.ndarray], ...]  # (material, vertices, faces)
# a façade built: its spec's key, its rungs across and up, its layouts' indices, and the
# metres its rooms may reach behind the wall (room_reach)
FacadeSlot = tuple[str, int, int, int, int, float]
# a part a façade places again and again: its material, vertices, faces, placements
Part = tuple[str, np.ndarray, np.ndarray, tuple[np.ndarray, ...]]
PlacedParts = list[tuple[str, trimesh.Trimesh, list[np.ndarray]]]  # the same, on a wall
# a building's parts to instance: (material, vertices, faces) -> the material, the mesh
# and its placements
Instances = dict[tuple[str | bytes, ...], tuple[str, trimesh.Trimesh, list[np.ndarray]]]
Slot = tuple[str, str, int, int]  # a spec's cache key, an axis, a rung, how many variants


@dataclass
class AxisCache:
    """Solved axes and built façades of a run, shared by all buildings of a worker.

    Walls are solved at the nearest of a ladder of lengths STRETCH apart (2 % steps: 3 m
    to 60 m is 150 rungs) and stretched to their own size (by at most half a step, 1 %:
    a 1.3 m window grows or shrinks 13 mm); a façade's meshes are built once per pair of
    rungs, merged per material, and scaled onto each wall. A city of thousands of walls
    of as many lengths solves and builds a few hundred. Every worker makes a rung the
    same way, so the files do not depend on which worker built what."""

    axes: dict[Slot, tuple[AxisLayout, ...]] = field(default_factory=dict)
    facades: dict[FacadeSlot, FacadeMeshes] = field(default_factory=dict)
    parts: dict[FacadeSlot, tuple[FacadeMeshes, tuple[Part, ...]]] = field(default_factory=dict)
    solved: int = 0  # axes this cache solved itself (not given it solved ahead)

    def get(
        self, key: str, spec: Spec, axis: str, length: float, variants: int = 1, pick: int = 0
    ) -> AxisLayout | None:
        """The axis solved at the rung of ``length``, the ``pick``-th of its layouts (modulo
        how many there are); None: no layout, a plain wall."""
        found = self._layouts(key, spec, axis, length, variants)
        return found[pick % len(found)] if found else None

    def fits(self, key: str, spec: Spec, axis: str, length: float, variants: int = 1) -> bool:
        """Does some layout of the axis fit at the rung of ``length``?"""
        return bool(self._layouts(key, spec, axis, length, variants))

    def _layouts(
        self, key: str, spec: Spec, axis: str, length: float, variants: int
    ) -> tuple[AxisLayout, ...]:
        slot = (key, axis, rung(length), variants)
        if slot not in self.axes:
            self.axes[slot] = solve_rung(spec, axis, rung_length(slot[2]), variants)
            self.solved += 1
        return self.axes[slot]

    def _picked(
        self, key: str, spec: Spec, width: float, height: float, variants: int, pick: int
    ) -> tuple[int, int, AxisLayout, AxisLayout] | None:
        """The layouts of each axis a wall ``width`` x ``height`` takes (the ``pick``-th of
        each axis's ``variants``), with their indices; None where an axis has none."""
        across = self._layouts(key, spec, "x", width, variants)
        up = self._layouts(key, spec, "y", height, variants)
        if not across or not up:
            return None
        x, y = pick % len(across), pick % len(up)
        return x, y, across[x], up[y]

    def facade(
        self,
        key: str,
        spec: Spec,
        width: float,
        height: float,
        base_dir: Path | None,
        variants: int = 1,
        pick: int = 0,
        behind: float = math.inf,
    ) -> list[tuple[str, trimesh.Trimesh]] | None:
        """The façade of a wall ``width`` x ``height`` in its own frame (x along, y up, z
        out), one mesh per material, its rooms reaching ``behind`` the wall at the most
        (:func:`room_reach`); None where no layout fits (a plain wall)."""
        picked = self._picked(key, spec, width, height, variants, pick)
        if picked is None:
            return None
        x, y, horizontal, vertical = picked
        slot = (key, rung(width), rung(height), x, y, behind)
        if slot not in self.facades:
            layout = _facade(spec, horizontal, vertical)
            self.facades[slot] = _merged_facade(layout, base_dir, behind)
        scale = np.array([width / horizontal.canvas, height / vertical.canvas, 1.0])
        return _scaled(self.facades[slot], scale)

    def facade_with_doors(
        self,
        key: str,
        spec: Spec,
        width: float,
        height: float,
        base_dir: Path | None,
        doors: Sequence[float],
        variants: int = 1,
        pick: int = 0,
        behind: float = math.inf,
    ) -> list[tuple[str, trimesh.Trimesh]] | None:
        """:meth:`facade` with a door at each of ``doors`` (metres along the wall, where
        entrances are: :func:`.with_doors`); a wall's own, so not kept."""
        picked = self._picked(key, spec, width, height, variants, pick)
        if picked is None:
            return None
        _, _, horizontal, vertical = picked
        stretch = horizontal.canvas / width
        layout = with_doors(_facade(spec, horizontal, vertical), [d * stretch for d in doors])
        scale = np.array([1 / stretch, height / vertical.canvas, 1.0])
        return _scaled(_merged_facade(layout, base_dir, behind), scale)

    def facade_parts(
        self,
        key: str,
        spec: Spec,
        width: float,
        height: float,
        base_dir: Path | None,
        variants: int = 1,
        pick: int = 0,
        behind: float = math.inf,
    ) -> tuple[list[tuple[str, trimesh.Trimesh]], PlacedParts] | None:
        """:meth:`facade`, with the parts it places :data:`.MIN_INSTANCES` times or more
        apart, those of :data:`.MIN_TRIANGLES` triangles or more (each in its own frame,
        with its placements on the wall), and its panes and their recesses of every size
        as unit meshes scaled by their placements (:func:`_unit`), for instancing; the
        walls and the other parts merged per material."""
        picked = self._picked(key, spec, width, height, variants, pick)
        if picked is None:
            return None
        x, y, horizontal, vertical = picked
        slot = (key, rung(width), rung(height), x, y, behind)
        if slot not in self.parts:
            scene = facade_scene(_facade(spec, horizontal, vertical), base_dir, behind)
            self.parts[slot] = _parts(scene, _stretchable(spec))
        merged, parts = self.parts[slot]
        scale = np.array([width / horizontal.canvas, height / vertical.canvas, 1.0])
        stretch = np.diag([*scale, 1.0])
        return (
            _scaled(merged, scale),
            [
                (name, trimesh.Trimesh(points, faces, process=False), [stretch @ m for m in placed])
                for name, points, faces, placed in parts
            ],
        )


@dataclass(frozen=True)
class BuildingResult:
    scene: trimesh.Scene
    facades: int  # walls with a solved façade
    plain_walls: int  # walls without one (too short, no layout, or party walls)
    party_walls: int  # walls along a neighbour: blind
    top: float  # metres: the highest roof
    volumes: tuple[Volume, ...] = ()  # the solids: walls and roofs (on posts: the roof alone)
    plain: dict[str, int] = field(default_factory=dict)  # plain walls by reason (PLAIN_REASONS)
    doors: int = 0  # doors put where the footprint's entrances are


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


@dataclass(frozen=True)
class Looks:
    """Colours the tags give the building (None: the spec's, else the built-in ones)."""

    wall: str | None = None
    roof: str | None = None


def build_building(
    footprint: Footprint,
    spec: Spec,
    spec_key: str,
    heights: Heights,
    roof: Roof,
    min_facade_width: float,
    cache: AxisCache,
    base_dir: Path | None = None,
    looks: Looks = Looks(),
    shared: Any = None,
    tolerance: float = 0.3,
    walls: Sequence[tuple[WallRule, Facade]] = (),
    variants: int = 1,
    pick: int = 0,
    above: Any = None,
    instanced: bool = False,
    fallback: Facade | None = None,
) -> BuildingResult:
    """The building's scene: a volume a part of its footprint, as the heights say (walls
    from ``base`` to the eaves, the roof on them); façades on every wall but the party
    walls along a neighbour (``shared``, within ``tolerance``), which are blind; the
    ground under the parts that stand on it. A wall gets the façade of the first of
    ``walls`` that matches it (its side, the way it faces, its length), else ``spec``'s.
    ``base_dir`` is the spec's folder, where its mesh and texture files are. Each axis is
    the ``pick``-th of up to ``variants`` layouts, the same for all the building's walls.
    Roofs stand still at party walls (a gable end, not a hip down to the neighbour), and
    leave out ``above``, the taller parts standing on this one, running on into their
    walls. With ``instanced``, the parts a façade repeats are meshes of their own, each
    placed by a node per instance (:func:`.instance_nodes` makes them one node). A wall
    its façade does not fit (no layout for its height or its length) takes ``fallback``'s,
    in the building's wall material (:func:`_worn`), before it is left plain. A flat
    roof (not on posts) gets a coping on its walls and plant seeded by ``pick``
    (rooftop.py): its units merged with the building's meshes of their material, or,
    ``instanced``, placed as the façades' repeated parts are."""
    main = Facade(spec, spec_key, base_dir)
    scene = trimesh.Scene()
    parts: dict[str, list[trimesh.Trimesh]] = {}
    instances: Instances = {}
    facades = plain = party = entrances = 0
    reasons: dict[str, int] = {}
    volumes = party_volumes(footprint, heights, roof, shared, tolerance, above)
    on_roofs: dict[tuple[str, int, str], list[np.ndarray]] = {}  # plant: its placements
    posts_only = roof_only(footprint.properties)  # a carport: posts, no walls
    for block_number, block in enumerate(volumes):
        wall_height = _wall_height(block)
        lift = trimesh.transformations.translation_matrix((0.0, block.base, 0.0))
        proud: dict[tuple[float, float], tuple[tuple[float, float], float, str]] = {}
        ends: list[tuple[tuple[float, float], tuple[float, float], float]] = []
        laid = () if posts_only else _walls(block, main, walls)
        for a, b, length, party_wall, chosen in laid:
            direction = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
            placement = lift @ _to_world(a, direction)
            meshes: list[tuple[str, trimesh.Trimesh]] | None = None
            repeated: PlacedParts = []
            doors = along_wall(footprint.entrances, a, b)
            tried = _tried(chosen, fallback)
            dressed = chosen
            if length >= min_facade_width and not party_wall:
                behind = room_reach(block.part, a, b)
                for dressed in tried:
                    wall_args = (dressed.key, dressed.spec, length, wall_height, dressed.base_dir)
                    if doors:  # entrances on this wall: its façade with doors, its own
                        meshes = cache.facade_with_doors(*wall_args, doors, variants, pick, behind)
                        entrances += len(doors) if meshes is not None else 0
                    elif instanced:
                        found = cache.facade_parts(*wall_args, variants, pick, behind)
                        meshes, repeated = found if found is not None else (None, [])
                    else:
                        meshes = cache.facade(*wall_args, variants, pick, behind)
                    if meshes is not None:
                        break
            if meshes is None:
                wall = trimesh.creation.box(extents=(length, wall_height, SLAB))
                wall.apply_translation((length / 2, wall_height / 2, -SLAB / 2))
                wall.apply_transform(placement)
                parts.setdefault(_plain_material(chosen.spec), []).append(wall)
                plain += 1
                party += party_wall
                reason = _plain_reason(party_wall, length, min_facade_width)
                if reason is None:  # no façade tried fits: their heights, or their lengths
                    fits = any(cache.fits(f.key, f.spec, "y", wall_height, variants) for f in tried)
                    reason = "no_layout" if fits else "too_low"
                reasons[reason] = reasons.get(reason, 0) + 1
                continue
            facades += 1
            out = max(float(mesh.vertices[:, 2].max(initial=0.0)) for _, mesh in meshes)
            for _, mesh, placed in repeated:  # how far they stand out, on the wall
                corners = trimesh.bounds.corners(mesh.bounds)
                out = max(out, *(float((corners @ m[2, :3] + m[2, 3]).max()) for m in placed))
            worn = _worn(dressed, chosen)
            proud[a] = (direction, out, worn(_wall_material(dressed.spec)))
            ends.append((a, b, out))
            for name, mesh in meshes:
                mesh.apply_transform(placement)
                parts.setdefault(worn(name), []).append(mesh)
            for own, mesh, placed in repeated:
                name = worn(own)
                digest = (name, mesh.vertices.tobytes(), mesh.faces.tobytes())
                instances.setdefault(digest, (name, mesh, []))[2].extend(
                    placement @ m for m in placed
                )
        for name, post in _corner_posts(proud, ends, block.base, wall_height):
            parts.setdefault(name, []).append(post)
        if posts_only:
            parts.setdefault(_plain_material(spec), []).extend(_posts(post_places(block)))
        dressed_top = block.roof.type == "flat" and not posts_only  # a coping and plant
        if dressed_top:
            top = block.eaves + block.roof.parapet
            cap = coping(block.part, top, block.still, block.above)
            parts.setdefault(METAL_NAME, []).append(cap.apply_transform(MAP_TO_WORLD))
        for piece_number, (shape, still) in enumerate(roof_outlines(block)):
            cover, infill = roof_meshes(shape, block.eaves, block.roof, still)
            cover.apply_transform(MAP_TO_WORLD)
            flat = block.roof.type == "flat" and ROOF_NAME not in spec.materials
            kind = FLAT_ROOF_NAME if flat else ROOF_NAME  # a spec's own roof covers both
            parts.setdefault(kind, []).append(cover)
            for piece in [] if posts_only else infill:  # a roof on posts has open gables
                piece.apply_transform(MAP_TO_WORLD)
                parts.setdefault(_plain_material(spec), []).append(piece)
            seed = (pick, block_number, piece_number)
            for unit in plant(shape, block.eaves, still, seed) if dressed_top else []:
                for number, (own, _) in enumerate(UNITS[unit.shape].meshes):
                    name = _plain_material(spec) if own == WALL_NAME else own
                    on_roofs.setdefault((unit.shape, number, name), []).append(unit.matrix)
        bottom = trimesh.creation.extrude_polygon(block.part, 0.01)
        bottom.apply_translation((0, 0, block.base - 0.01))
        bottom.apply_transform(MAP_TO_WORLD)
        below = GROUND_NAME if block.base <= 0 else _plain_material(spec)
        parts.setdefault(below, []).append(bottom)
    for (shape, number, name), placed in on_roofs.items():  # as a façade's parts (_parts)
        mesh = UNITS[shape].meshes[number][1]
        if instanced and len(mesh.faces) >= MIN_TRIANGLES:
            digest = (name, mesh.vertices.tobytes(), mesh.faces.tobytes())  # one a city
            instances.setdefault(digest, (name, mesh.copy(), []))[2].extend(placed)
        else:
            parts.setdefault(name, []).extend(mesh.copy().apply_transform(m) for m in placed)
    instances = placed_often(instances, parts)
    materials: dict[str, tuple[Material, Path | None]] = {}
    if fallback is not None:
        materials.update(_materials(fallback.spec, fallback.base_dir, looks, pick))
    for _, other in walls:  # the building's own spec wins where two name one material
        materials.update(_materials(other.spec, other.base_dir, looks, pick))
    materials.update(_materials(spec, base_dir, looks, pick))
    for name in sorted(parts):
        builtin = BUILTIN_INTERIOR if name == INTERIOR_MATERIAL else Material()
        finished, folder = materials.get(name) or (builtin, None)  # the recesses stay dark
        project = plane_uv if name in ROOFS else projection(finished)
        merged = _merged(parts[name], texture_metres(finished), project)
        if finished.library is not None:  # a normal map: normals and tangents with it
            merged = tangent_space(merged)
        merged = weld(merged)
        merged.visual.material = pbr(name, finished, folder)
        scene.add_geometry(
            merged, geom_name=f"{footprint.id}/{name}", node_name=f"{footprint.id}/{name}"
        )
    for number, (name, mesh, placed) in enumerate(instances.values()):
        builtin = BUILTIN_INTERIOR if name == INTERIOR_MATERIAL else Material()
        finished, folder = materials.get(name) or (builtin, None)
        metres = texture_metres(finished)
        if metres is None:
            mesh.visual = trimesh.visual.TextureVisuals()
        else:  # in metres of the part's own frame
            mesh = projection(finished)(mesh, metres)
            if finished.library is not None:
                mesh = tangent_space(mesh)
        mesh = weld(mesh)
        mesh.visual.material = pbr(name, finished, folder)
        geometry = f"{footprint.id}/part-{number}"
        scene.add_geometry(mesh, geom_name=geometry, node_name=f"{geometry}/0", transform=placed[0])
        for k, matrix in enumerate(placed[1:], 1):
            scene.graph.update(
                frame_to=f"{geometry}/{k}",
                frame_from=scene.graph.base_frame,
                matrix=matrix,
                geometry=geometry,
            )
    solids, top = building_solids(footprint, volumes)
    return BuildingResult(
        scene,
        facades,
        plain,
        party,
        top,
        solids,
        dict(sorted(reasons.items())),
        entrances,
    )


def placed_often(instances: Instances, parts: dict[str, list[trimesh.Trimesh]]) -> Instances:
    """The parts a building places :data:`.MIN_INSTANCES` times or more, to be instanced;
    those it places fewer times (a plant unit alone on its roof, the panes of a size one
    window has) are put in place and merged with the building's meshes of their
    material (into ``parts``): a node of their own would cost a draw call that a merged
    mesh does not."""
    often: Instances = {}
    for digest, (name, mesh, placed) in instances.items():
        if len(placed) >= MIN_INSTANCES:
            often[digest] = (name, mesh, placed)
        else:
            parts.setdefault(name, []).extend(mesh.copy().apply_transform(m) for m in placed)
    return often


ROOM_STEPS = (1.2, 1.0, 0.8, 0.6, 0.4)  # metres a room behind a wall may reach, tried
ROOM_GAP = 0.1  # metres at the least between rooms behind facing walls


def room_reach(part: Polygon, a: tuple[float, float], b: tuple[float, float]) -> float:
    """How far behind the wall from ``a`` to ``b`` (outwards on its right) the rooms
    behind its windows may reach: the deepest of :data:`ROOM_STEPS` such that the
    building is twice as deep behind the wall (less its ends, which the rooms near a
    corner do not reach: :func:`.rooms.room_depth`) and :data:`ROOM_GAP` more, so that rooms
    behind facing walls of a narrow building stay apart and never come out at its far
    side; the least step where none fits."""
    length = math.dist(a, b)
    dx, dy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    inside = part.buffer(1e-6)
    for reach in ROOM_STEPS:
        end = min(2 * reach, length / 2 - 1e-3)
        start = (a[0] + dx * end, a[1] + dy * end)
        stop = (b[0] - dx * end, b[1] - dy * end)
        deep = (-dy * (2 * reach + ROOM_GAP), dx * (2 * reach + ROOM_GAP))  # inwards: left
        strip = Polygon(
            [
                start,
                stop,
                (stop[0] + deep[0], stop[1] + deep[1]),
                (start[0] + deep[0], start[1] + deep[1]),
            ]
        )
        if inside.contains(strip):
            return reach
    return ROOM_STEPS[-1]


def building_solids(
    footprint: Footprint, volumes: Sequence[Volume]
) -> tuple[tuple[Volume, ...], float]:
    """A building's solids, as its CityJSON gives them (:func:`written_volumes`: a roof on
    posts is its roof and its posts), and its top (metres, to the mm). What a coarser level
    of detail needs of a building, with no façade solved."""
    top = max(block.top for block in volumes)
    return tuple(written_volumes(footprint, volumes)), round(top, 3)


PLAIN_REASONS = ("party", "too_short", "too_low", "no_layout")


def _plain_reason(party: bool, length: float, min_facade_width: float) -> str | None:
    """Why a wall is plain before any layout is tried: a party wall, or shorter than
    ``min_facade_width``; None: a layout was tried (``too_low``: none fits its height,
    ``no_layout``: none fits its length)."""
    if party:
        return "party"
    if length < min_facade_width:
        return "too_short"
    return None


POST_SPACING = 6.0  # metres: posts along a side at most this far apart


def post_places(block: Volume) -> tuple[Post, ...]:
    """Posts from the base to the eaves under a roof with no walls: at each corner of
    its outline, and along the sides at most POST_SPACING apart, each inside the
    outline. The one place posts are placed: the glb's boxes and the CityJSON's solids
    (a ``BuildingInstallation``) are both made from these."""
    inset = block.part.buffer(-POST / 2, join_style="mitre")
    if not isinstance(inset, Polygon) or inset.is_empty:
        inset = block.part
    ring = _corners(list(inset.exterior.coords))
    height = max(_wall_height(block), POST)
    posts = []
    for a, b in itertools.pairwise(ring):
        steps = max(1, math.ceil(math.dist(a, b) / POST_SPACING))
        for k in range(steps):  # the corner a, then evenly along to b (b: the next side's)
            x = a[0] + (b[0] - a[0]) * k / steps
            y = a[1] + (b[1] - a[1]) * k / steps
            posts.append((x, y, block.base, block.base + height))
    return tuple(posts)


def _posts(places: Sequence[Post]) -> list[trimesh.Trimesh]:
    """The posts as boxes, in the glTF frame."""
    boxes = []
    for x, y, base, top in places:
        post = trimesh.creation.box(extents=(POST, POST, top - base))
        post.apply_translation((x, y, (base + top) / 2))
        post.apply_transform(MAP_TO_WORLD)
        boxes.append(post)
    return boxes


def written_volumes(footprint: Footprint, volumes: Sequence[Volume]) -> list[Volume]:
    """The volumes as the CityJSON has them: a roof on posts is its roof on a slab
    (:func:`.s3db.roof_solid`), with its posts; any other as it is."""
    if not roof_only(footprint.properties):
        return list(volumes)
    return [roof_solid(block, SLAB, post_places(block)) for block in volumes]


@dataclass(frozen=True)
class Facade:
    """A façade spec, its key in the caches, and its folder (for its mesh files)."""

    spec: Spec
    key: str
    base_dir: Path | None = None


Wall = tuple[tuple[float, float], tuple[float, float], float, bool, Facade]


def party_volumes(
    footprint: Footprint,
    heights: Heights,
    roof: Roof,
    shared: Any,
    tolerance: float,
    above: Any = None,
) -> list[Volume]:
    """The building's volumes (:func:`.s3db.volume`), each with its party walls
    (``still``): its walls along a neighbour (``shared``, within ``tolerance``), where
    its façades stop and its roof runs on at full height. A roof on posts has no walls,
    so none (its roof slopes down to its edges). Each carries ``above``, the taller
    parts standing on the building, which its roof leaves out (:func:`.s3db.roof_outlines`).
    The one place party walls are found: the glb's walls and roofs and the CityJSON's
    solids (LOD2, and the 3D Tiles' LOD1 and LOD2 made from them) all take them from
    here."""
    blocks = [replace(volume(part, heights, roof), above=above) for part in footprint.parts]
    if roof_only(footprint.properties) or shared is None:
        return blocks
    zone = party_zone(shared, tolerance)  # widened once for all the walls
    return [
        replace(block, still=tuple((a, b) for a, b in _edges(block.part) if along(a, b, zone)))
        for block in blocks
    ]


def building_walls(
    footprint: Footprint, heights: Heights, roof: Roof, shared: Any, tolerance: float
) -> list[tuple[tuple[float, float], tuple[float, float], bool]]:
    """A building's walls as its façades are laid on them: their ends and whether each
    is a party wall (:func:`party_volumes`); none under a roof on posts."""
    if roof_only(footprint.properties):
        return []
    return [
        (a, b, (a, b) in set(block.still))
        for block in party_volumes(footprint, heights, roof, shared, tolerance)
        for a, b in _edges(block.part)
    ]


def _walls(
    block: Volume,
    main: Facade,
    rules: Sequence[tuple[WallRule, Facade]],
) -> Iterator[Wall]:
    """The walls of a volume: ends, length, whether it is a party wall (one of its
    ``still`` walls: :func:`party_volumes`), and its façade (the first rule matching
    its side, the way it faces and its length, else ``main``)."""
    still = set(block.still)
    edges = [(a, b, (a, b) in still) for a, b in _edges(block.part)]
    for (a, b, party), side in zip(edges, sides(edges), strict=True):
        length = math.dist(a, b)
        chosen = next((f for rule, f in rules if rule.matches(side, facing(a, b), length)), main)
        yield a, b, length, party, chosen


def _wall_height(block: Volume) -> float:
    """From the base to the eaves, and the parapet of a flat roof."""
    height = block.eaves - block.base
    return height + (block.roof.parapet if block.roof.type == "flat" else 0.0)


Tries = tuple[tuple[Slot, Slot], ...]  # a wall's façades in turn: the axes (x, y) of each


def wall_tries(
    footprint: Footprint,
    heights: Heights,
    roof: Roof,
    min_facade_width: float,
    shared: Any,
    tolerance: float,
    main: Facade,
    rules: Sequence[tuple[WallRule, Facade]] = (),
    variants: int = 1,
    fallback: Facade | None = None,
) -> set[Tries]:
    """The axes a building's façades may need, as cache slots: for each wall a façade is
    tried on, those of the façades it tries in turn (its own, then the ``fallback``).
    What a run solves ahead, in parallel, before the buildings (:func:`axes_to_solve`
    tells which, as the axes come: a fallback's only where the wall's own does not fit;
    see :meth:`AxisCache.get`)."""
    needed: set[Tries] = set()
    if roof_only(footprint.properties):
        return needed  # no walls: no façades
    for block in party_volumes(footprint, heights, roof, shared, tolerance):
        height = rung(_wall_height(block))
        for _, _, length, party, chosen in _walls(block, main, rules):
            if length >= min_facade_width and not party:
                across = rung(length)
                needed.add(
                    tuple(
                        ((f.key, "x", across, variants), (f.key, "y", height, variants))
                        for f in _tried(chosen, fallback)
                    )
                )
    return needed


def axes_to_solve(tries: Iterable[Tries], solved: Mapping[Slot, Any]) -> set[Slot]:
    """The axes still to solve, given those ``solved`` (slot: its layouts, none where no
    layout fits): for each wall, those of the first façade it tries whose axes are not
    all solved, unless an earlier one fits (both its axes have a layout). Solving these
    and asking again until none is left solves what the buildings will ask for (a wall
    asks for a façade's axes only when the ones before did not fit it, and for each
    height it tried when none did: :func:`build_building`), and nothing else."""
    needed: set[Slot] = set()
    for tried in tries:
        for axes in tried:
            missing = [slot for slot in axes if slot not in solved]
            if missing:
                needed.update(missing)
                break
            if all(solved[slot] for slot in axes):
                break  # this façade fits: the wall tries no other
    return needed


def _tried(chosen: Facade, fallback: Facade | None) -> tuple[Facade, ...]:
    """The façades a wall tries, in turn: its own, then the fallback (if another)."""
    if fallback is None or fallback.key == chosen.key:
        return (chosen,)
    return (chosen, fallback)


def _worn(dressed: Facade, chosen: Facade) -> Callable[[str], str]:
    """The material a mesh of ``dressed`` wears on a wall whose own façade is ``chosen``:
    its own, but for a fallback's wall material, which becomes the building's (the one
    its plain walls wear: :func:`_plain_material`), so a shed's wall is the brick or
    render of the house, tinted as the house is."""
    if dressed is chosen:
        return lambda name: name
    own, building = _wall_material(dressed.spec), _plain_material(chosen.spec)
    return lambda name: building if name == own else name


CORNER_MIN = 0.01  # metres: façades standing out less than this need no corner post


def _wall_material(spec: Spec) -> str:
    return spec.defaults.material or DEFAULT_MATERIAL


def _plain_material(spec: Spec) -> str:
    """The material of the walls without a façade (plain and party walls, gable ends,
    posts) beside a façade of ``spec``: its own wall material, so that a brick terrace
    does not end in a grey blind wall; a spec's own ``wall`` material wins, and the
    built-in ``wall`` stands in when it names neither."""
    if WALL_NAME in spec.materials:
        return WALL_NAME
    return spec.defaults.material or WALL_NAME


def _corner_posts(
    starts: dict[tuple[float, float], tuple[tuple[float, float], float, str]],
    ends: list[tuple[tuple[float, float], tuple[float, float], float]],
    base: float,
    height: float,
) -> Iterator[tuple[str, trimesh.Trimesh]]:
    """A corner piece where two façades meet at an outside corner: a post filling the
    notch their ledges, pilasters and frames leave there (each stops at its wall's end),
    as far out as the prouder of the two, in the wall material of the wall it ends."""
    for a, b, out in ends:
        following = starts.get(b)
        if following is None:
            continue
        (dx, dy), after, material = following
        ax, ay = b[0] - a[0], b[1] - a[1]
        if ax * dy - ay * dx <= 1e-9:  # not a left turn: an inside corner
            continue
        depth = max(out, after)
        if depth < CORNER_MIN:
            continue
        length = math.hypot(ax, ay)
        first = (ay / length, -ax / length)  # outward normals: right of each wall
        second = (dy, -dx)
        outline = [
            b,
            (b[0] + depth * first[0], b[1] + depth * first[1]),
            (b[0] + depth * (first[0] + second[0]), b[1] + depth * (first[1] + second[1])),
            (b[0] + depth * second[0], b[1] + depth * second[1]),
        ]
        post = trimesh.creation.extrude_polygon(Polygon(outline).buffer(0), height)
        post.apply_translation((0, 0, base))
        post.apply_transform(MAP_TO_WORLD)
        yield material, post


def _facade(spec: Spec, horizontal: AxisLayout, vertical: AxisLayout) -> Layout:
    sized = spec.model_copy(
        update={
            "canvas": spec.canvas.model_copy(
                update={"width": horizontal.canvas, "height": vertical.canvas}
            )
        }
    )
    return Layout(
        sized,
        horizontal.canvas,
        vertical.canvas,
        horizontal,
        vertical,
        build_shapes(sized, horizontal, vertical),
        0.0,
    )


def flat_roof(pick: int) -> Material:
    """The covering of a building's flat roofs, of :data:`FLAT_ROOFS`, from its own number
    (``pick``: from the city's seed and its id). Its 17th and 18th bits choose, so the
    choice is independent of the palette's tone (``pick`` modulo the palette's four:
    its two lowest bits), and a dark wall does not always come with a dark roof."""
    return FLAT_ROOFS[(pick >> 16) % len(FLAT_ROOFS)]


def _materials(
    spec: Spec, base_dir: Path | None, looks: Looks, pick: int = 0
) -> dict[str, tuple[Material, Path | None]]:
    """The materials by name (with the folder their texture files are in): the spec's
    and the library's it names, the building's own (a spec material of that name wins
    over the built-in one; the flat roofs' covering is the one ``pick`` gives), and the
    tags' colours over both."""
    declared = {name: look(spec, name) for name in material_names(spec)}
    declared = {name: m for name, m in declared.items() if name in spec.materials or m.library}
    builtins = (
        (WALL_NAME, WALL),
        (ROOF_NAME, ROOF),
        (FLAT_ROOF_NAME, flat_roof(pick)),
        (DOOR_MATERIAL, DOOR),
        (METAL_NAME, ROOF_METAL),
        (ROOFLIGHT_NAME, ROOFLIGHT),
    )
    for name, builtin in (*builtins, (GROUND_NAME, GROUND)):
        declared.setdefault(name, builtin)
    if looks.wall is not None:
        walls = [WALL_NAME] + ([spec.defaults.material] if spec.defaults.material else [])
        for name in walls:
            declared[name] = declared.get(name, WALL).model_copy(
                update={"color": looks.wall, "texture": None}
            )
    if looks.roof is not None:
        for name in ROOFS:
            declared[name] = declared[name].model_copy(
                update={"color": looks.roof, "texture": None}
            )
    return {name: (m, base_dir) for name, m in declared.items()}


def _merged(
    meshes: list[trimesh.Trimesh],
    metres: float | None,
    project: Callable[[trimesh.Trimesh, float], trimesh.Trimesh] = metric_uv,
) -> trimesh.Trimesh:
    """The meshes of one material as one; for a textured material, with the texture
    coordinates they have, and for those without, ``project``'s in metres
    (:func:`.metric_uv`, or :func:`.plane_uv` for roofs)."""
    if metres is None:
        merged = trimesh.util.concatenate(meshes)
        merged.visual = trimesh.visual.TextureVisuals()
        return merged
    mapped = [
        m if getattr(m.visual, "uv", None) is not None else project(m, metres) for m in meshes
    ]
    offsets = np.cumsum([0] + [len(m.vertices) for m in mapped[:-1]])
    merged = trimesh.Trimesh(  # stacked by hand: trimesh would pack the pictures in an atlas
        np.vstack([m.vertices for m in mapped]),
        np.vstack([m.faces + offset for m, offset in zip(mapped, offsets, strict=True)]),
        process=False,
    )
    merged.visual = trimesh.visual.TextureVisuals(uv=np.vstack([m.visual.uv for m in mapped]))
    return merged


def _merged_facade(layout: Layout, base_dir: Path | None, behind: float = math.inf) -> FacadeMeshes:
    """A façade's meshes placed and merged per material (its rooms reaching ``behind``
    the wall at the most)."""
    merged: dict[str, list[trimesh.Trimesh]] = {}
    for mesh in _placed(facade_scene(layout, base_dir, behind)):
        merged.setdefault(mesh.visual.material.name, []).append(mesh)
    return tuple(
        (name, joined.vertices.copy(), joined.faces.copy())
        for name, meshes in sorted(merged.items())
        for joined in [trimesh.util.concatenate(meshes)]
    )


def _stretchable(spec: Spec) -> frozenset[str]:
    """The materials whose small parts may be stretched to any size (:func:`_unit`): the
    see-through ones (panes: a faint ripple, stretched, still reads as float glass) and
    the dark interior behind them (plain). A visible texture (brick, stone, timber)
    would be stretched with its part: those parts stay a mesh a size. The rooms behind
    windows (a ``rooms`` interior) are not: a room box shows as much of its room as its
    window is large (:func:`.room_uv`), so a unit mesh would be one a room, size and
    depth, most of them placed once or twice (on the 50-building block, 1,010 instanced
    meshes and 1,317 draw calls where 191 and 512 were); they are merged with their
    building's interior as a façade's small parts are, ten triangles a window and no
    draw call of their own."""
    names = {name for name in material_names(spec) if see_through(spec, name)}
    if look(spec, INTERIOR_MATERIAL).library != ROOMS:
        names.add(INTERIOR_MATERIAL)
    return frozenset(names)


def _unit(mesh: trimesh.Trimesh) -> tuple[tuple[bytes, bytes], np.ndarray, np.ndarray]:
    """A small part as a unit mesh and the matrix that makes it the part again: its
    vertices moved and scaled into the unit cube (an axis it does not span kept as it
    is), and the translation x scale back. Parts of one shape and any size (a window's
    panes, their recesses) give one unit mesh: its key (its rounded vertices and faces)
    tells them apart from other shapes."""
    low, high = mesh.bounds
    extent = high - low
    extent = np.where(extent > 1e-9, extent, 1.0)
    vertices = (mesh.vertices - low) / extent
    vertices = np.round(vertices, 6) + 0.0  # no -0.0: equal shapes give equal bytes
    back = trimesh.transformations.translation_matrix(low) @ np.diag([*extent, 1.0])
    key = (vertices.tobytes(), np.asarray(mesh.faces, dtype=np.int64).tobytes())
    return key, vertices, back


# A repeated part's vertices are kept to 10 micrometres: the same frame or door built on
# walls of other lengths comes out a float32 step apart (1e-6 m) and would be stored and
# drawn as another mesh (on the 50-building block, 39 of 160 instanced meshes were such
# twins: 424 -> 385 draw calls with --instance)
PART_DECIMALS = 5


def _parts(
    scene: trimesh.Scene, stretchable: frozenset[str] = frozenset()
) -> tuple[FacadeMeshes, tuple[Part, ...]]:
    """A façade's meshes placed fewer than :data:`.MIN_INSTANCES` times or of fewer than
    :data:`.MIN_TRIANGLES` triangles, placed and merged per material, and the others
    each once with their placements, in the order of the scene's nodes. A small part in
    a ``stretchable`` material is a unit mesh (:func:`_unit`), one for all its sizes,
    its placements scaling it: every pane of a glass, of any size, is one mesh."""
    uses = Counter(scene.graph[node][1] for node in scene.graph.nodes_geometry)
    merged: dict[str, list[trimesh.Trimesh]] = {}
    parts: dict[Any, Part] = {}
    for node in sorted(scene.graph.nodes_geometry):
        matrix, geometry = scene.graph[node]
        mesh = scene.geometry[geometry]
        name = mesh.visual.material.name
        if len(mesh.faces) < MIN_TRIANGLES and name in stretchable:
            key, vertices, back = _unit(mesh)
            unit = (name, *key)
            if unit not in parts:
                parts[unit] = (name, vertices, mesh.faces.copy(), ())
            material, points, faces, placed = parts[unit]
            placement = np.asarray(matrix, dtype=float) @ back
            parts[unit] = (material, points, faces, (*placed, placement))
            continue
        if uses[geometry] < MIN_INSTANCES or len(mesh.faces) < MIN_TRIANGLES:
            merged.setdefault(name, []).append(mesh.copy().apply_transform(matrix))
            continue
        if geometry not in parts:  # to 10 um: the same part built on two walls, equal bytes
            vertices = np.round(mesh.vertices, PART_DECIMALS) + 0.0  # no -0.0
            parts[geometry] = (name, vertices, mesh.faces.copy(), ())
        material, vertices, faces, placed = parts[geometry]
        matrix = np.asarray(matrix, dtype=float)
        parts[geometry] = (material, vertices, faces, (*placed, matrix))
    walls = tuple(
        (name, joined.vertices.copy(), joined.faces.copy())
        for name, meshes in sorted(merged.items())
        for joined in [trimesh.util.concatenate(meshes)]
    )
    return walls, tuple(parts.values())


def _placed(scene: trimesh.Scene) -> list[trimesh.Trimesh]:
    """The scene's meshes with their instance transforms applied."""
    meshes = []
    for node in sorted(scene.graph.nodes_geometry):
        matrix, geometry = scene.graph[node]
        mesh = scene.geometry[geometry].copy()
        mesh.apply_transform(matrix)
        meshes.append(mesh)
    return meshes


def _scaled(
    meshes: Sequence[tuple[str, np.ndarray, np.ndarray]], scale: np.ndarray
) -> list[tuple[str, trimesh.Trimesh]]:
    """A façade's meshes (name, vertices, faces) as trimeshes, their vertices scaled."""
    return [
        (name, trimesh.Trimesh(vertices * scale, faces, process=False))
        for name, vertices, faces in meshes
    ]
