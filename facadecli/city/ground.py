"""The ground under a district in its exported models (``facade city --ground``): a flat
mesh a game or film pipeline can import with the buildings, so they stand on something.

It is the district's base plane, the buildings' extent and :data:`.DISTRICT_MARGIN`
metres round it (the box the land cover is clipped to: :func:`.district_box`), in the
town's hard ground (:data:`GROUND_LOOKS` ``paving``), and the land cover the input maps
(landcover.py: parks, grass, woods, water, pitches, sand, car parks), each kind one mesh
in its own material. The pieces do not overlap: a kind is cut out of the kinds drawn
before it (a later kind covers an earlier one, as landcover.KINDS orders them) and all of
them out of the plane, so every piece lies in one plane, :data:`GROUND_LEVEL`, with no
two faces at one place for a renderer to fight over. The materials are the library's
(:mod:`facadecli.materials`), recoloured: each has its base colour, normal and
occlusion-roughness-metal pictures, tiled in metres, stored with the buildings' in the
run's ``textures/``.

The streets, pavements, kerbs, yards and trees the viewer lays out from the footprints
(facadecli/viewer/ground.py) are not here: they are computed in the page, over its plan
grid, in JavaScript (docs/reference/city.md, "The ground in the exported models").
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import shapely
import trimesh
from shapely.geometry import Polygon, box

from facadecli.city.building import MAP_TO_WORLD
from facadecli.city.landcover import KINDS, Area, district_box, oriented_parts
from facadecli.export.gltf import glb_bytes
from facadecli.export.texture_store import TextureStore, externalised
from facadecli.geometry.facade import pbr, plane_uv, tangent_space, texture_metres, weld
from facadecli.materials import LIBRARY
from facadecli.spec.model import Material

#: metres below the buildings' foot (their ground-floor slab's underside is at -0.01 m):
#: no face of the ground is where a face of a building is
GROUND_LEVEL = -0.02
PAVING = "paving"  # the base plane: the town's streets, pavements and yards, undrawn here
RESOLUTION = 256  # pixels a side of the ground's pictures: they tile every few metres


def _look(name: str, color: str, roughness: float) -> Material:
    return LIBRARY[name].model_copy(
        update={"color": color, "roughness": roughness, "resolution": RESOLUTION}
    )


#: the material of each piece of ground: the base plane's, then each land cover kind's
GROUND_LOOKS: dict[str, Material] = {
    PAVING: _look("concrete", "#8d8a84", 0.9),
    "wood": _look("gravel", "#55603c", 1.0),  # a wood's floor of leaves and moss
    "grass": _look("gravel", "#6f8f4a", 1.0),
    "park": _look("gravel", "#6a9148", 1.0),
    "sand": _look("gravel", "#d9c9a0", 1.0),
    "pitch": _look("render", "#5d8f4e", 0.9),
    "parking": _look("concrete", "#5a5b5e", 0.85),  # asphalt
    "water": _look("membrane", "#2e4d61", 0.08),
}
assert set(GROUND_LOOKS) == {PAVING, *KINDS}, "a land cover kind without a look"


def material_name(kind: str) -> str:
    """A piece's material in the model: ``ground-<kind>`` (a building's own ``ground``,
    the underside of its ground floor, is another)."""
    return f"ground-{kind}"


def ground_box(parts: Iterable[Polygon]) -> tuple[float, float, float, float]:
    """The district's box in local metres: the footprints' parts' extent grown by the
    land cover's margin (:func:`.district_box`)."""
    bounds = np.array([part.bounds for part in parts], dtype=float).reshape(-1, 4)
    return district_box(bounds)


def ground_pieces(
    extent: tuple[float, float, float, float], areas: Sequence[Area]
) -> dict[str, tuple[Polygon, ...]]:
    """Each kind's polygons inside ``extent``, the plane's (``paving``) first: every kind
    cut out of those drawn before it, all cut out of the plane. Kinds in landcover.KINDS'
    order; a kind with nothing left is not there."""
    plane = box(*extent)
    covered: dict[str, object] = {}
    for kind in KINDS:
        shapes = [part for area in areas if area.kind == kind for part in area.parts]
        if shapes:
            covered[kind] = shapely.intersection(shapely.union_all(shapes), plane)
    pieces: dict[str, tuple[Polygon, ...]] = {}
    above = shapely.union_all(list(covered.values())) if covered else Polygon()
    pieces[PAVING] = oriented_parts(shapely.difference(plane, above))
    later = list(covered)
    for index, kind in enumerate(later):
        over = [covered[k] for k in later[index + 1 :]]
        shape = covered[kind]
        if over:
            shape = shapely.difference(shape, shapely.union_all(over))
        found = oriented_parts(shape)
        if found:
            pieces[kind] = found
    return {kind: parts for kind, parts in pieces.items() if parts}


def flat_mesh(polygons: Sequence[Polygon]) -> trimesh.Trimesh:
    """The polygons triangulated (holes kept) at :data:`GROUND_LEVEL`, facing up, in the
    models' frame (glTF: y up)."""
    meshes = []
    for polygon in polygons:
        vertices, faces = trimesh.creation.triangulate_polygon(polygon)
        lifted = np.column_stack([vertices, np.full(len(vertices), GROUND_LEVEL)])
        mesh = trimesh.Trimesh(lifted, faces, process=False)
        if len(mesh.faces) and mesh.face_normals[:, 2].mean() < 0:
            mesh.invert()
        meshes.append(mesh)
    mesh = trimesh.util.concatenate(meshes)
    return mesh.apply_transform(MAP_TO_WORLD)


def ground_scene(pieces: dict[str, tuple[Polygon, ...]]) -> trimesh.Scene:
    """One mesh a kind, textured in metres (its library picture tiles over the plane) in
    its :data:`GROUND_LOOKS` material, named ``ground/<kind>``."""
    scene = trimesh.Scene()
    for kind, polygons in pieces.items():
        look = GROUND_LOOKS[kind]
        metres = texture_metres(look)
        assert metres is not None  # a library material: it has pictures
        mesh = weld(tangent_space(plane_uv(flat_mesh(polygons), metres)))
        mesh.visual.material = pbr(material_name(kind), look)
        scene.add_geometry(mesh, geom_name=f"ground/{kind}", node_name=f"ground/{kind}")
    return scene


def write_ground_glb(
    target: Path,
    parts: Iterable[Polygon],
    areas: Sequence[Area],
    store: TextureStore | None,
) -> dict[str, int]:
    """Write the district's ground to ``target`` (its pictures in ``store``, else in the
    glb); returns the triangles of each kind, for the report."""
    from facadecli.export.atomic import write_atomic

    pieces = ground_pieces(ground_box(parts), areas)
    scene = ground_scene(pieces)
    data = glb_bytes(scene)
    write_atomic(target, data if store is None else externalised(data, store, target))
    return {kind: len(scene.geometry[f"ground/{kind}"].faces) for kind in pieces}
