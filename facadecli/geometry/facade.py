"""The façade as a 3D scene: one node per layer, one child per visible shape.

Shapes with the same mesh, cell size, parameters, mirroring and material share one mesh
(glTF instancing), so a façade with a thousand windows stores one window. Coordinates: x
along the façade, y up, z towards the viewer (SPEC 2.1), metres: glTF's own frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from functools import lru_cache, partial
from pathlib import Path

import numpy as np
import trimesh
from trimesh.visual.material import PBRMaterial

from facadecli.errors import SpecError
from facadecli.geometry.primitives import (
    GLAZED,
    PANES,
    PRIMITIVES,
    RECESS_DEPTH,
    Cell,
    asset,
    open_box,
    recess,
)
from facadecli.geometry.rooms import Opening, Room, rooms
from facadecli.geometry.runs import built
from facadecli.geometry.walls import wall_mesh
from facadecli.layout import (
    BUILTIN_GLASS,
    BUILTIN_INTERIOR,
    INTERIOR_MATERIAL,
    LIT_INTERIOR,
    LIT_INTERIOR_MATERIAL,
    PANE_MATERIAL,
    Layout,
    Shape,
)
from facadecli.limits import SCENE_FACES_MAX
from facadecli.materials import images, resolve
from facadecli.materials.textures import (
    ROOM_BACK,
    ROOM_HEIGHT,
    ROOM_REVEAL,
    ROOM_WIDTH,
    ROOMS_GRID,
    linear,
)
from facadecli.spec.assets import load_mesh
from facadecli.spec.model import Material, Spec

FALLBACK_MATERIAL = Material(color="#bfbfbf", roughness=0.8)
TRANSMISSION = "KHR_materials_transmission"
IOR = "KHR_materials_ior"


def linear_rgb(colour: str) -> list[int]:
    """A ``#rrggbb`` colour (sRGB, as people write colours) as glTF's ``baseColorFactor``
    wants it: linear light, 0-255 (a renderer that reads the factor as linear, as the
    glTF specification says, would otherwise show every colour pale)."""
    digits = colour.lstrip("#")
    found = []
    for i in (0, 2, 4):
        found.append(round(255 * linear(int(digits[i : i + 2], 16) / 255.0)))
    return found


@lru_cache(maxsize=256)
def pbr(name: str, material: Material, base_dir: Path | None = None) -> PBRMaterial:
    """A glTF metallic-roughness material; see-through ones blend; a texture is tinted by
    the colour. A library material carries its drawn texture set instead (base colour,
    normal, and one image for occlusion, roughness and metallic), with factors of 1.
    Cached: a city builds the same materials for every wall, and reads each texture
    image once."""
    rgb = linear_rgb(material.color)
    alpha = round(255 * material.opacity)
    blend = "BLEND" if material.opacity < 1.0 else "OPAQUE"
    glow = material.emissive  # past 1, the glb writes KHR_materials_emissive_strength
    if material.library is not None:
        drawn = images(material)
        return PBRMaterial(
            name=name,
            baseColorFactor=[255, 255, 255, alpha],
            baseColorTexture=drawn.base_colour,
            normalTexture=drawn.normal,
            metallicRoughnessTexture=drawn.orm,
            occlusionTexture=drawn.orm,
            metallicFactor=1.0,
            roughnessFactor=1.0,
            alphaMode=blend,
            doubleSided=False,
            emissiveFactor=[glow, glow, glow] if glow else None,
            emissiveTexture=drawn.base_colour if glow else None,
        )
    texture = None
    if material.texture is not None:
        from PIL import Image

        with Image.open((base_dir or Path(".")) / material.texture) as image:
            texture = image.convert("RGBA" if material.opacity < 1.0 else "RGB")
    return PBRMaterial(
        name=name,
        baseColorFactor=[*rgb, alpha],
        baseColorTexture=texture,
        metallicFactor=material.metallic,
        roughnessFactor=material.roughness,
        alphaMode=blend,
        doubleSided=False,
        emissiveFactor=[glow * c / 255 for c in rgb] if glow else None,
        emissiveTexture=texture if glow else None,
    )


def texture_metres(material: Material) -> float | None:
    """Metres of surface one copy of a material's texture covers (None: no texture)."""
    if material.library is not None:
        return images(material).size
    return material.texture_size if material.texture is not None else None


def look(spec: Spec, name: str) -> Material:
    """The material a name stands for in a spec: its own (over the library entry it
    starts from), a library material, or a built-in (:func:`_builtin`); the lit
    ground floor's rooms, unless the spec names its own, its interior giving off
    :data:`LIT_INTERIOR` of its colour."""
    found = resolve(spec.materials, name)
    if found is None and name == LIT_INTERIOR_MATERIAL:
        return look(spec, INTERIOR_MATERIAL).model_copy(update={"emissive": LIT_INTERIOR})
    return found or _builtin(name)


def material_names(spec: Spec) -> list[str]:
    """Every material name a spec's model may use: its own, those its rules name, and
    the built-in glass and interior."""
    rules = [*spec.shapes, *(rule for layer in spec.layers for rule in layer.shapes)]
    named = (
        spec.defaults.material,
        *(rule.material for rule in rules),
        *(rule.pane_material for rule in rules),
        PANE_MATERIAL,
        INTERIOR_MATERIAL,
        LIT_INTERIOR_MATERIAL,
    )
    names = dict.fromkeys(spec.materials)
    for name in named:
        if name is not None:
            names.setdefault(name)
    return list(names)


def material_extensions(spec: Spec) -> dict[str, dict[str, dict[str, float]]]:
    """glTF material extensions by material name: light passing through glass
    (``KHR_materials_transmission``) and its index of refraction (``KHR_materials_ior``)."""
    found: dict[str, dict[str, dict[str, float]]] = {}
    for name in material_names(spec):
        material = look(spec, name)
        extensions: dict[str, dict[str, float]] = {}
        if material.transmission > 0:
            extensions[TRANSMISSION] = {"transmissionFactor": material.transmission}
        if material.ior is not None:
            extensions[IOR] = {"ior": material.ior}
        if extensions:
            found[name] = extensions
    return found


def metric_uv(mesh: trimesh.Trimesh, size: float) -> trimesh.Trimesh:
    """Texture coordinates in metres (one texture copy per ``size`` metres), projected on
    each face's dominant plane, so brick stays brick-sized in a cell of any size."""
    flat = mesh.copy()
    flat.unmerge_vertices()
    normals = np.abs(flat.face_normals)
    dominant = normals.argmax(axis=1)  # 0: facing x, 1: facing y, 2: facing z
    planes = np.array([(2, 1), (0, 2), (0, 1)])[dominant]  # the two axes of the plane
    uv = np.zeros((len(flat.vertices), 2))
    for corner in range(3):
        vertex = flat.faces[:, corner]
        rows = np.arange(len(vertex))
        uv[vertex, 0] = flat.vertices[vertex, planes[rows, 0]]
        uv[vertex, 1] = flat.vertices[vertex, planes[rows, 1]]
    flat.visual = trimesh.visual.TextureVisuals(uv=uv / size)
    return flat


ROOMS = "rooms"  # the library's interiors: an atlas of rooms, one a window (room_uv)
#: metres up a façade under which a room's floor is the ground floor's (lit: a shop, a
#: room seen from the street; the first floor's lies a storey, about 3 m, up)
GROUND_FLOOR_UNDER = 2.0


def room_variant(points: np.ndarray, seed: int) -> np.ndarray:
    """Which room of the atlas each of ``points`` (n x 3, metres) shows: a hash of the
    point to the centimetre and the material's seed, so that neighbouring windows show
    different rooms and the same model the same ones."""
    cells = np.round(np.asarray(points, dtype=float).reshape(-1, 3) * 100).astype(np.int64)
    mixed = np.full(len(cells), seed + 0x9E3779B97F4A7C15, dtype=np.uint64)
    with np.errstate(over="ignore"):
        for axis in range(3):
            mixed ^= cells[:, axis].astype(np.uint64)
            mixed *= np.uint64(0xBF58476D1CE4E5B9)
            mixed ^= mixed >> np.uint64(31)
    rooms: np.ndarray = (mixed % np.uint64(ROOMS_GRID * ROOMS_GRID)).astype(np.int64)
    return rooms


def room_uv(mesh: trimesh.Trimesh, seed: int = 0, room: int | None = None) -> trimesh.Trimesh:
    """Texture coordinates that lay one room of the interiors' atlas on each room box
    behind a window: each connected piece of ``mesh`` (a box, :func:`.recess`: its back
    plate and four sides, open to the window) shows one room (``room``, else
    :func:`room_variant` of the piece's centre). Its back plate shows a piece of the
    room's back wall at the room's own scale (:func:`room_crop`: a window of any shape
    sees the room unstretched), its sides the room's side walls, floor and ceiling (the
    picture's bands round the back wall, from the window's edge at the picture's edge to
    the back wall), at the heights and across the widths the back plate shows. Each face
    gets its own corners."""
    points = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    pieces = _pieces(points, faces)
    count = int(pieces.max(initial=-1)) + 1
    corners = points[faces]  # (faces, 3, 3)
    areas = np.asarray(mesh.area_faces, dtype=float)
    normals = np.asarray(mesh.face_normals, dtype=float)
    facing = np.zeros((count, 3))
    np.add.at(facing, pieces, normals * areas[:, None])
    centre = np.zeros((count, 3))
    np.add.at(centre, pieces, corners.mean(axis=1) * areas[:, None])
    weight = np.zeros(count)
    np.add.at(weight, pieces, areas)
    centre /= np.where(weight > 0, weight, 1.0)[:, None]
    # the plate faces out of the window: the sides' normals cancel in pairs
    facing[:, 1] = 0.0
    level = np.linalg.norm(facing, axis=1) < 1e-9
    facing[level] = (0.0, 0.0, 1.0)
    facing /= np.linalg.norm(facing, axis=1)[:, None]
    along = np.stack([facing[:, 2], np.zeros(count), -facing[:, 0]], axis=1)  # up x facing
    u = np.einsum("fcj,fj->fc", corners, along[pieces])
    v = corners[:, :, 1]
    w = np.einsum("fcj,fj->fc", corners, facing[pieces])  # out of the room, to the window
    low_u, high_u = _spans(u, pieces, count)
    low_v, high_v = _spans(v, pieces, count)
    low_w, high_w = _spans(w, pieces, count)
    shown, up = room_crop(high_u - low_u, high_v - low_v)  # metres of wall shown, its foot
    scale = (high_u - low_u) / np.maximum(shown[:, 0], 1e-9)  # window metres a wall metre
    a0, a1, b0, b1 = ROOM_BACK
    # where each corner lies on the room's back wall (metres: across from its left, up
    # from its floor) and how deep in (0 at the window, 1 at the back wall)
    x = (ROOM_WIDTH - shown[:, 0])[pieces, None] / 2 + (u - low_u[pieces, None]) / scale[
        pieces, None
    ]
    y = up[pieces, None] + (v - low_v[pieces, None]) / scale[pieces, None]
    deep = (high_w[pieces, None] - w) / np.maximum(high_w - low_w, 1e-9)[pieces, None]
    across = a0 + (a1 - a0) * x / ROOM_WIDTH
    upward = b0 + (b1 - b0) * y / ROOM_HEIGHT
    rim = ROOM_REVEAL
    side = _side(normals, facing[pieces], along[pieces])
    left, right, floor, ceiling = (side == k for k in range(4))
    across[left] = (rim + (a0 - rim) * deep)[left]
    across[right] = (1 - rim - (1 - rim - a1) * deep)[right]
    upward[floor] = (rim + (b0 - rim) * deep)[floor]
    upward[ceiling] = (1 - rim - (1 - rim - b1) * deep)[ceiling]
    chosen = room_variant(centre, seed) if room is None else np.full(count, room)
    number = chosen[pieces]
    column, row = (number % ROOMS_GRID)[:, None], (number // ROOMS_GRID)[:, None]
    inside = (rim / 2, 1 - rim / 2)  # never a neighbouring room's picture
    across = (column + np.clip(across, *inside)) / ROOMS_GRID
    upward = (row + np.clip(upward, *inside)) / ROOMS_GRID
    flat = trimesh.Trimesh(
        corners.reshape(-1, 3), np.arange(3 * len(faces)).reshape(-1, 3), process=False
    )
    flat.visual = trimesh.visual.TextureVisuals(
        uv=np.stack([across.reshape(-1), upward.reshape(-1)], axis=1)
    )
    return flat


def room_crop(wide: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What a window ``wide`` x ``high`` metres (arrays) shows of a room's back wall
    (:data:`ROOM_WIDTH` x :data:`ROOM_HEIGHT`): (n, 2) metres across and up, and the
    metres from the floor to its foot. A window shows as much wall as it is large, its
    head :data:`HEAD_ROOM` under the ceiling (or less, when it is taller), centred across;
    one larger than the wall shows the whole wall in the side it overflows and less in
    the other, so the room keeps its proportions and is never stretched."""
    wide, high = np.asarray(wide, dtype=float), np.asarray(high, dtype=float)
    over = np.maximum.reduce([np.ones_like(wide), wide / ROOM_WIDTH, high / ROOM_HEIGHT])
    shown = np.stack([wide / over, high / over], axis=1)
    head = np.maximum(shown[:, 1], ROOM_HEIGHT - HEAD_ROOM)
    return shown, head - shown[:, 1]


#: metres from the head of a window to the ceiling of the room behind it
HEAD_ROOM = 0.3


def _spans(values: np.ndarray, pieces: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest of each piece's ``values`` (faces x 3 corners)."""
    low, high = np.full(count, np.inf), np.full(count, -np.inf)
    np.minimum.at(low, pieces, values.min(axis=1))
    np.maximum.at(high, pieces, values.max(axis=1))
    return low, high


def _side(normals: np.ndarray, facing: np.ndarray, along: np.ndarray) -> np.ndarray:
    """Which of a room box's faces each is, by its normal: 0 the left wall (facing right,
    along the wall), 1 the right, 2 the floor (facing up), 3 the ceiling, 4 the back."""
    across = np.einsum("ij,ij->i", normals, along)
    side = np.full(len(normals), 4)
    side[across > 0.5] = 0
    side[across < -0.5] = 1
    side[normals[:, 1] > 0.5] = 2
    side[normals[:, 1] < -0.5] = 3
    back = np.einsum("ij,ij->i", normals, facing) > 0.5
    side[back] = 4
    return side


def _pieces(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The connected piece each face belongs to (faces meeting at a corner, by position
    to the micrometre), numbered in order of their first face."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    if len(faces) == 0:
        return np.zeros(0, dtype=np.int64)
    keys = np.round(points * 1e6).astype(np.int64)
    _, corner = np.unique(keys, axis=0, return_inverse=True)
    corner = corner.reshape(-1)[faces]  # (faces, 3): each corner's place
    rows = np.repeat(np.arange(len(faces)), 3)
    links = coo_matrix(
        (np.ones(rows.size), (rows, len(faces) + corner.reshape(-1))),
        shape=(len(faces) + int(corner.max()) + 1,) * 2,
    )
    _, labels = connected_components(links, directed=False)
    labels = labels[: len(faces)]
    _, first, renumbered = np.unique(labels, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first, kind="stable"), kind="stable")
    pieces: np.ndarray = order[renumbered.reshape(-1)]
    return pieces


def projection(material: Material) -> Callable[[trimesh.Trimesh, float], trimesh.Trimesh]:
    """How a material's texture is laid on a mesh: the rooms one a window
    (:func:`room_uv`), any other texture in metres on each face's dominant plane
    (:func:`metric_uv`)."""
    if material.library == ROOMS:
        return lambda mesh, _size: room_uv(mesh, material.seed)
    return metric_uv


def plane_uv(mesh: trimesh.Trimesh, size: float) -> trimesh.Trimesh:
    """Texture coordinates in metres (one texture copy per ``size`` metres) in each face's
    own plane: u level along it, v up its slope. A roof's tiles run along its eaves and
    keep their size however steep it is (a projection on a dominant plane would stretch
    them by 1 / cos(pitch) and turn their courses on a hip); a wall reads as
    :func:`metric_uv` does, seen from outside; a level face takes x and north."""
    flat = mesh.copy()
    flat.unmerge_vertices()
    normal = np.asarray(flat.face_normals, dtype=float)
    along = np.stack([normal[:, 2], np.zeros(len(normal)), -normal[:, 0]], axis=1)  # up x n
    length = np.linalg.norm(along, axis=1)
    level = length < 1e-6
    along[level] = (1.0, 0.0, 0.0)
    along[~level] /= length[~level, None]
    up = np.cross(normal, along)
    up[level] = (0.0, 0.0, -1.0)
    corners = flat.vertices[flat.faces]  # (faces, 3, 3)
    uv = np.zeros((len(flat.vertices), 2))
    for corner in range(3):
        vertex = flat.faces[:, corner]
        uv[vertex, 0] = np.einsum("ij,ij->i", corners[:, corner], along)
        uv[vertex, 1] = np.einsum("ij,ij->i", corners[:, corner], up)
    flat.visual = trimesh.visual.TextureVisuals(uv=uv / size)
    return flat


def tangent_space(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """Give a mesh whose faces have their own vertices (as :func:`metric_uv` leaves them)
    the normals and tangents a normal map is read in: each face's normal, and its
    tangent along increasing u with the handedness of v (glTF 3.7.2.1's ``TANGENT``), so
    that every viewer reads the normal map the same way. They go out as ``NORMAL`` and
    ``TANGENT`` (see :mod:`facadecli.export.gltf`)."""
    corners = mesh.vertices[mesh.faces]  # (faces, 3, 3)
    uv = np.asarray(mesh.visual.uv)[mesh.faces]  # (faces, 3, 2)
    edge1, edge2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    du1, dv1 = uv[:, 1, 0] - uv[:, 0, 0], uv[:, 1, 1] - uv[:, 0, 1]
    du2, dv2 = uv[:, 2, 0] - uv[:, 0, 0], uv[:, 2, 1] - uv[:, 0, 1]
    det = du1 * dv2 - du2 * dv1
    det = np.where(np.abs(det) < 1e-12, 1.0, det)[:, None]
    tangent = (edge1 * dv2[:, None] - edge2 * dv1[:, None]) / det
    bitangent = (edge2 * du1[:, None] - edge1 * du2[:, None]) / det
    normal = np.asarray(mesh.face_normals, dtype=float)
    tangent -= normal * np.einsum("ij,ij->i", tangent, normal)[:, None]  # in the face's plane
    length = np.linalg.norm(tangent, axis=1)
    fallback = np.cross(normal, [0.0, 1.0, 0.0])  # a face with no u direction: any tangent
    fallback[np.linalg.norm(fallback, axis=1) < 1e-6] = (1.0, 0.0, 0.0)
    tangent = np.where(length[:, None] > 1e-9, tangent, fallback)
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    handed = np.where(np.einsum("ij,ij->i", np.cross(normal, tangent), bitangent) < 0, -1.0, 1.0)
    normals = np.zeros((len(mesh.vertices), 3))
    tangents = np.zeros((len(mesh.vertices), 4))
    for corner in range(3):
        normals[mesh.faces[:, corner]] = normal
        tangents[mesh.faces[:, corner], :3] = tangent
        tangents[mesh.faces[:, corner], 3] = handed
    mesh.vertex_attributes["NORMAL"] = normals.astype(np.float32)
    mesh.vertex_attributes["TANGENT"] = tangents.astype(np.float32)
    return mesh


def weld(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The mesh with each vertex stored once: corners that agree in every attribute the
    file will carry (position, texture coordinates, normal and tangent, as float32) become
    one, in the order they first appear. :func:`metric_uv` gives every face its own
    corners; welding them back is about a third fewer vertices (a box's face: 4, not 6)."""
    uv = getattr(mesh.visual, "uv", None)
    attributes = {name: mesh.vertex_attributes.get(name) for name in ("NORMAL", "TANGENT")}
    attributes = {name: value for name, value in attributes.items() if value is not None}
    columns = [mesh.vertices, *([] if uv is None else [uv]), *attributes.values()]
    rows = np.hstack(
        [np.asarray(c, dtype=np.float32).reshape(len(mesh.vertices), -1) for c in columns]
    )
    _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # the welded vertices in order of appearance
    renumber = np.empty(len(order), dtype=np.int64)
    renumber[order] = np.arange(len(order))
    keep = first[order]
    welded = trimesh.Trimesh(
        mesh.vertices[keep], renumber[inverse.reshape(-1)][mesh.faces], process=False
    )
    material = getattr(mesh.visual, "material", None)
    welded.visual = trimesh.visual.TextureVisuals(
        uv=None if uv is None else np.asarray(uv)[keep], material=material
    )
    for name, value in attributes.items():
        welded.vertex_attributes[name] = np.asarray(value)[keep]
    return welded


def _mirror(mesh: trimesh.Trimesh, cell: Cell, x: bool, y: bool) -> None:
    """Mirror a mesh within its cell on the axes whose letters are reflected."""
    if not (x or y):
        return
    matrix = np.eye(4)
    if x:
        matrix[0, 0], matrix[0, 3] = -1.0, cell.width
    if y:
        matrix[1, 1], matrix[1, 3] = -1.0, cell.height
    mesh.apply_transform(matrix)  # trimesh flips the winding of a reflection


def facade_scene(
    layout: Layout, base_dir: Path | None = None, behind: float = math.inf
) -> trimesh.Scene:
    """The visible shapes of a layout as a scene (hidden ones are culled). A frame or an
    arch is two meshes: its bars in the shape's material and its pane in the pane's. The
    walls (opaque boxes) of a layer are one mesh per material and depth, whatever their
    cells (:func:`.wall_mesh`): no seams between the cells. Every
    window is backed here, in one place: behind each see-through pane, and behind each box
    or panel of a see-through material, a closed dark recess (:func:`.recess`) in the
    ``interior`` material, so that no view through a window passes through the model;
    with a ``rooms`` interior, one room box a window instead, as :func:`.rooms.rooms`
    decides them (``behind``: metres behind the façade's plane a room may reach, the
    building behind the wall; a façade alone has nothing behind it)."""
    spec = layout.spec
    assets: dict[str, trimesh.Trimesh] = {}
    scene = trimesh.Scene()
    world = scene.graph.base_frame
    shared: dict[tuple[object, ...], str | None] = {}  # a part already built -> its geometry
    faces: dict[str, int] = {}  # triangles of each shared mesh
    total = 0  # triangles of the whole model (every node)

    def dress(mesh: trimesh.Trimesh, material: str, room: int | None = None) -> trimesh.Trimesh:
        """The mesh in a material (with texture coordinates in metres if it has a
        texture; behind a window, the ``room`` of the atlas it shows)."""
        finished = look(spec, material)
        appearance = pbr(material, finished, base_dir)
        metres = texture_metres(finished)
        if metres is not None and finished.library == ROOMS:
            mesh = tangent_space(room_uv(mesh, finished.seed, room))
            mesh.visual.material = appearance
        elif metres is not None:
            mesh = metric_uv(mesh, metres)
            if finished.library is not None:  # a normal map: normals and tangents with it
                mesh = tangent_space(mesh)
            mesh.visual.material = appearance
        else:
            mesh.visual = trimesh.visual.TextureVisuals(material=appearance)
        return mesh

    def place(
        shape: Shape,
        part: str,
        material: str,
        build: Callable[[], trimesh.Trimesh | None],
        node: str,
    ) -> None:
        """Add a node for a part of a shape (nothing when its builder makes none), sharing
        the mesh of an identical part already built."""
        nonlocal total
        cell = Cell.of(shape)
        key: tuple[object, ...] = (
            shape.mesh,
            part,
            cell,
            material,
            shape.reflected_x,
            shape.reflected_y,
        )
        where = np.array([shape.x0, shape.y0, shape.z1])
        placement = trimesh.transformations.translation_matrix(where)
        room = None
        if look(spec, material).library == ROOMS:  # a recess behind another room: its own
            room = int(room_variant(where, look(spec, material).seed)[0])
            key = (*key, room)
        parent = f"layer:{shape.layer}"
        if key in shared:
            existing = shared[key]
            if existing is not None:
                total = _count(spec.name, total, faces[existing])
                scene.graph.update(
                    frame_to=node, frame_from=parent, matrix=placement, geometry=existing
                )
            return
        mesh = build()
        if mesh is None:
            shared[key] = None
            return
        _mirror(mesh, cell, shape.reflected_x, shape.reflected_y)
        mesh = dress(mesh, material, room)
        name = f"{shape.mesh.replace('/', '_')}-{material}-{len(shared)}"
        shared[key] = name
        faces[name] = len(mesh.faces)
        total = _count(spec.name, total, faces[name])
        scene.add_geometry(
            mesh, geom_name=name, node_name=node, parent_node_name=parent, transform=placement
        )

    def furnish(room: Room, shape: Shape, node: str) -> None:
        """Add the node of a room box (sharing the mesh of an equal room built already);
        a room of the ground floor (its floor under :data:`GROUND_FLOOR_UNDER`) lit."""
        nonlocal total
        where = np.array([shape.x0, shape.y0, shape.z1])
        number = int(room_variant(where, look(spec, INTERIOR_MATERIAL).seed)[0])
        size = (room.x1 - room.x0, room.y1 - room.y0, room.depth)
        lit = room.y0 < GROUND_FLOOR_UNDER
        material = LIT_INTERIOR_MATERIAL if lit else INTERIOR_MATERIAL
        key: tuple[object, ...] = ("room", *np.round(size, 6).tolist(), number, lit)
        placement = trimesh.transformations.translation_matrix((room.x0, room.y0, room.front))
        parent = f"layer:{shape.layer}"
        existing = shared.get(key)
        if existing is None:
            existing = f"room-{material}-{len(shared)}"
            box = open_box((0.0, 0.0, -room.depth), (*size[:2], 0.0))
            mesh = dress(box, material, number)
            shared[key] = existing
            faces[existing] = len(mesh.faces)
            scene.add_geometry(mesh, geom_name=existing, node_name=node, parent_node_name=parent)
            scene.graph.update(frame_to=node, frame_from=parent, matrix=placement)
        else:
            scene.graph.update(
                frame_to=node, frame_from=parent, matrix=placement, geometry=existing
            )
        total = _count(spec.name, total, faces[existing])

    pieces = built(layout.shapes)
    furnished = look(spec, INTERIOR_MATERIAL).library == ROOMS
    backed = _backed(layout, pieces, base_dir, assets) if furnished else {}
    placed_rooms = dict(
        zip(backed, rooms(list(backed.values()), layout.width, layout.height, behind), strict=True)
    )
    for layer in spec.layers:
        if not layer.enabled:
            continue
        scene.graph.update(frame_to=f"layer:{layer.name}", frame_from=world)
        count = 0
        walls: dict[tuple[str, float, float], list[tuple[float, float, float, float]]] = {}
        for shape in pieces:
            if shape.layer != layer.name:
                continue
            if shape.mesh == "box" and not see_through(spec, shape.material):
                z0 = min(shape.z0, shape.z1 - 1e-4)  # as thin as a box may be
                group = walls.setdefault((shape.material, z0, shape.z1), [])
                group.append((shape.x0, shape.x1, shape.y0, shape.y1))
                continue
            node = f"{layer.name}/{shape.x}.{shape.y}/{count}"
            count += 1
            cell = Cell.of(shape)
            build = partial(_build, shape, cell, base_dir, assets)
            place(shape, "", shape.material, build, node)
            if shape.mesh in GLAZED and see_through(spec, shape.material):
                if furnished:
                    if (room := placed_rooms.get((id(shape), ""))) is not None:
                        furnish(room, shape, f"{node}/recess")
                else:
                    dark = partial(_recess, build, RECESS_DEPTH)
                    place(shape, "recess", INTERIOR_MATERIAL, dark, f"{node}/recess")
            pane = PANES.get(shape.mesh)
            if pane is not None:
                glass = shape.look.pane_material if shape.look else PANE_MATERIAL
                place(shape, "pane", glass, partial(pane, cell), f"{node}/pane")
                if see_through(spec, glass) and furnished:
                    if (room := placed_rooms.get((id(shape), "pane"))) is not None:
                        furnish(room, shape, f"{node}/recess")
                elif see_through(spec, glass):
                    back = partial(_recess, partial(pane, cell), RECESS_DEPTH)
                    place(shape, "pane-recess", INTERIOR_MATERIAL, back, f"{node}/recess")
        for (material, z0, z1), cells in walls.items():  # one mesh each: no seams
            mesh = dress(wall_mesh(cells, z0, z1), material)
            name = f"walls-{layer.name}-{material}-{count}"
            total = _count(spec.name, total, len(mesh.faces))
            scene.add_geometry(
                mesh,
                geom_name=name,
                node_name=f"{layer.name}/walls-{material}/{count}",
                parent_node_name=f"layer:{layer.name}",
            )
            count += 1
    return scene


def see_through(spec: Spec, name: str) -> bool:
    """Whether a material lets the view through (blended or transmitting): glass."""
    material = look(spec, name)
    return material.opacity < 1.0 or material.transmission > 0.0


def _recess(glass: Callable[[], trimesh.Trimesh | None], depth: float) -> trimesh.Trimesh | None:
    """The recess ``depth`` deep behind the glass a builder makes (none when it makes none)."""
    mesh = glass()
    return None if mesh is None else recess(mesh, depth)


def _backed(
    layout: Layout,
    pieces: Sequence[Shape],
    base_dir: Path | None,
    assets: dict[str, trimesh.Trimesh],
) -> dict[tuple[int, str], Opening]:
    """The openings of a layout's windows, each keyed by its shape (``id``) and part (``""``:
    a see-through box or panel, its glass; ``"pane"``: a frame's, an arch's or a door's
    pane in a see-through material), in the order :func:`facade_scene` places them: what
    the glass of each covers seen head-on (as its mesh is built and mirrored in its
    cell), the back of that glass, and a door's threshold (its room's floor)."""
    spec = layout.spec
    found: dict[tuple[int, str], Opening] = {}
    enabled = {layer.name for layer in spec.layers if layer.enabled}
    for shape in pieces:
        if shape.layer not in enabled:
            continue
        cell = Cell.of(shape)
        glass: list[tuple[str, Callable[[], trimesh.Trimesh | None]]] = []
        if shape.mesh in GLAZED and see_through(spec, shape.material):
            glass.append(("", partial(_build, shape, cell, base_dir, assets)))
        pane = PANES.get(shape.mesh)
        pane_glass = shape.look.pane_material if shape.look else PANE_MATERIAL
        if pane is not None and see_through(spec, pane_glass):
            glass.append(("pane", partial(pane, cell)))
        for part, build in glass:
            mesh = build()
            if mesh is None:
                continue
            _mirror(mesh, cell, shape.reflected_x, shape.reflected_y)
            (x0, y0, z0), (x1, y1, _) = mesh.bounds
            threshold = shape.y0 if shape.mesh == "door" else None  # the storey's floor
            found[(id(shape), part)] = Opening(
                shape.x0 + x0, shape.x0 + x1, shape.y0 + y0, shape.y0 + y1, shape.z1 + z0, threshold
            )
    return found


def _builtin(material: str) -> Material:
    """The built-in material of a name a spec does not define."""
    if material == INTERIOR_MATERIAL:
        return BUILTIN_INTERIOR
    return BUILTIN_GLASS if material == PANE_MATERIAL else FALLBACK_MATERIAL


def _count(name: str, total: int, more: int) -> int:
    """Triangles of the model so far, within :data:`SCENE_FACES_MAX`."""
    total += more
    if total > SCENE_FACES_MAX:
        raise SpecError.at(
            name,
            None,
            None,
            f"the model would have more than {SCENE_FACES_MAX:,} triangles",
            "use a lighter mesh file, or fewer cells that show it (masks, counters)",
        )
    return total


def _build(
    shape: Shape, cell: Cell, base_dir: Path | None, assets: dict[str, trimesh.Trimesh]
) -> trimesh.Trimesh:
    builder = PRIMITIVES.get(shape.mesh)
    if builder is not None:
        return builder(cell)
    if shape.mesh not in assets:
        path = (base_dir or Path(".")) / shape.mesh
        assets[shape.mesh] = load_mesh(path)
    return asset(assets[shape.mesh], cell)
