"""A room behind every pane (issue 35): behind each window a room box as deep as the
wall leaves room, showing one room of the library's ``rooms`` atlas on its back wall,
side walls, floor and ceiling at the room's own proportions, varied from window to
window by its place, from one material and one picture; the same model gives the same
bytes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from facadecli import load_spec, solve
from facadecli.geometry.facade import (
    HEAD_ROOM,
    _pieces,
    facade_scene,
    room_uv,
    room_variant,
    see_through,
)
from facadecli.geometry.primitives import RECESS_DEPTH, ROOM_DEPTH, recess
from facadecli.geometry.rooms import (
    ABOVE_HEAD,
    BELOW_SILL,
    ROOM_GAP,
    Opening,
    room_depth,
    rooms,
)
from facadecli.layout import Layout
from facadecli.materials import LIBRARY, images
from facadecli.materials.textures import (
    ROOM_BACK,
    ROOM_HEIGHT,
    ROOM_REVEAL,
    ROOM_WIDTH,
    ROOMS_GRID,
)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))


def _rooms(scene: trimesh.Scene) -> list[tuple[str, trimesh.Trimesh]]:
    """Every room box of a façade scene (the ``/recess`` nodes): its node and mesh."""
    return [
        (node, scene.geometry[scene.graph[node][1]])
        for node in sorted(scene.graph.nodes_geometry)
        if node.endswith("/recess")
    ]


def _luminance(image: object, uv: np.ndarray) -> np.ndarray:
    """The luminance (0..1, of the sRGB values) of a picture's pixels at the texture
    coordinates ``uv`` (v up, as trimesh keeps it)."""
    pixels = np.asarray(image, dtype=float) / 255.0
    n = pixels.shape[0]
    columns = np.clip((uv[:, 0] * n).astype(int), 0, n - 1)
    rows = np.clip(((1 - uv[:, 1]) * n).astype(int), 0, n - 1)
    luminance: np.ndarray = pixels[rows, columns] @ np.array([0.2126, 0.7152, 0.0722])
    return luminance


def _seen(mesh: trimesh.Trimesh) -> np.ndarray:
    """Texture coordinates all over a mesh's faces: 15 points of each (barycentric)."""
    steps = [(a, b) for a in range(5) for b in range(5 - a)]
    weights = np.array([(a, b, 4 - a - b) for a, b in steps], dtype=float) / 4
    corners = np.asarray(mesh.visual.uv)[mesh.faces]  # (faces, 3, 2)
    found: np.ndarray = np.einsum("wc,fcj->fwj", weights, corners).reshape(-1, 2)
    return found


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_every_window_of_the_examples_shows_a_room(path: Path) -> None:
    """Behind every pane of every example is a room box in a base-colour texture, all of
    it in one room of the atlas, and what it shows is a room, not a plain dark box: back
    wall, side walls, floor and ceiling of other tones, so its luminance spreads (one
    deviation over its faces: 0.021 to 0.18 on the examples; the dark render the recesses
    wore before spread 0.0034 over its whole picture). The rooms vary: a façade of four
    windows or more shows four different rooms or more."""
    scene = facade_scene(solve(load_spec(path)), path.parent)
    rooms = _rooms(scene)
    assert rooms, "no recess"
    shown = set()
    for node, mesh in rooms:
        picture = mesh.visual.material.baseColorTexture
        assert picture is not None
        uv = _seen(mesh)
        cell = np.floor(uv * ROOMS_GRID)
        assert (cell == cell[0]).all(), node  # one room's picture
        spread = float(_luminance(picture, uv).std())
        assert spread > 0.015, (path.stem, node, spread)
        shown.add(tuple(cell[0].astype(int)))
    windows = len({id(mesh) for _, mesh in rooms})
    assert len(shown) >= min(4, windows), (len(shown), windows)


def _box(x0: float, y0: float, wide: float, high: float) -> trimesh.Trimesh:
    """A room box 1 m deep behind a pane ``wide`` x ``high`` with its foot at (x0, y0)."""
    glass = trimesh.creation.box(bounds=[(x0, y0, -0.01), (x0 + wide, y0 + high, 0)])
    return recess(glass, 1.0)


@pytest.mark.parametrize("wide, high", [(1.0, 2.4), (2.4, 1.0), (1.0, 1.5), (4.0, 3.5)])
def test_a_room_keeps_its_proportions_behind_a_window_of_any_shape(
    wide: float, high: float
) -> None:
    """:func:`room_uv` shows a room at its own proportions (a tall window stretched it
    upright before, a wide one squashed it): the back plate spans as many metres of the
    room's back wall across as up for each metre of window, the window's own size when the
    wall is larger (its head :data:`HEAD_ROOM` under the ceiling, centred across), the
    whole wall in the side it overflows when it is not."""
    mapped = room_uv(_box(3.0, 7.0, wide, high), seed=2, room=5)
    uv = np.asarray(mapped.visual.uv).reshape(-1, 3, 2)
    normals = np.asarray(mapped.face_normals)
    plate = uv[normals[:, 2] > 0.99].reshape(-1, 2) * ROOMS_GRID - (1, 1)  # room 5: (1, 1)
    a0, a1, b0, b1 = ROOM_BACK
    across = np.ptp(plate[:, 0]) / (a1 - a0) * ROOM_WIDTH  # metres of wall shown
    up = np.ptp(plate[:, 1]) / (b1 - b0) * ROOM_HEIGHT
    assert across / wide == pytest.approx(up / high, rel=1e-6)  # never stretched
    assert across <= ROOM_WIDTH + 1e-9 and up <= ROOM_HEIGHT + 1e-9
    if wide <= ROOM_WIDTH and high <= ROOM_HEIGHT - HEAD_ROOM:
        assert (across, up) == pytest.approx((wide, high))
        top = b0 + (b1 - b0) * (ROOM_HEIGHT - HEAD_ROOM) / ROOM_HEIGHT
        assert plate[:, 1].max() == pytest.approx(top)
        assert plate[:, 0].mean() == pytest.approx((a0 + a1) / 2)
    else:
        assert max(across / ROOM_WIDTH, up / ROOM_HEIGHT) == pytest.approx(1.0)


def test_a_room_boxs_sides_show_its_walls_floor_and_ceiling_from_the_window_in() -> None:
    """The box's sides lie on the picture's bands round the back wall: the left wall
    (facing right) on the left band, from the picture's edge at the window to the back
    wall's edge at the back, the right wall, floor and ceiling likewise; two boxes side
    by side show their own rooms, the one asked for when asked."""
    both = trimesh.util.concatenate([_box(0.0, 0.0, 1.0, 2.0), _box(3.0, 0.0, 1.0, 2.0)])
    a0, a1, b0, b1 = ROOM_BACK
    for room in (None, 6):
        mapped = room_uv(both, seed=5, room=room)
        uv = np.asarray(mapped.visual.uv).reshape(-1, 3, 2)
        corners = np.asarray(mapped.vertices).reshape(-1, 3, 3)
        normals = np.asarray(mapped.face_normals)
        for piece in range(2):
            faces = slice(10 * piece, 10 * piece + 10)
            cell = np.floor(uv[faces].mean(axis=(0, 1)) * ROOMS_GRID)
            if room is not None:
                assert tuple(cell) == (room % ROOMS_GRID, room // ROOMS_GRID)
            inside = uv[faces] * ROOMS_GRID - cell
            deep = -corners[faces][:, :, 2]  # 0 at the glass, 1.01 at the back
            sides = {
                "left": (normals[faces, 0] > 0.99, 0, (ROOM_REVEAL, a0)),
                "right": (normals[faces, 0] < -0.99, 0, (1 - ROOM_REVEAL, a1)),
                "floor": (normals[faces, 1] > 0.99, 1, (ROOM_REVEAL, b0)),
                "ceiling": (normals[faces, 1] < -0.99, 1, (1 - ROOM_REVEAL, b1)),
            }
            for name, (chosen, axis, (window, back)) in sides.items():
                assert chosen.sum() == 2, name
                shown = inside[chosen][:, :, axis].reshape(-1)
                depth = deep[chosen].reshape(-1)
                expected = window + (back - window) * (depth - 0.01) / 1.0
                assert np.allclose(shown, expected, atol=1e-9), name


def test_rooms_are_deep_where_the_wall_leaves_room_and_stop_short_of_its_ends() -> None:
    """The townhouse's rooms: those of windows a room's depth or more from the façade's
    ends are :data:`ROOM_DEPTH` deep behind their glass (a recess was 12 cm); none
    reaches further behind the façade than its window stands from the nearer end (where
    a room of the other façade of a corner would be); a spec without the rooms keeps
    the 12 cm recess."""
    path = ROOT / "specs" / "townhouse.yaml"
    layout = solve(load_spec(path))
    scene = facade_scene(layout, path.parent)
    depths = []
    for node, mesh in _rooms(scene):
        matrix, _ = scene.graph[node]
        (x0, _, z0), (x1, _, z1) = trimesh.transform_points(mesh.bounds, matrix)
        depths.append(round(z1 - z0, 6))
        assert -z0 <= min(x0, layout.width - x1) + 1e-6, node
    assert max(depths) == pytest.approx(ROOM_DEPTH)
    assert np.mean(np.isclose(depths, ROOM_DEPTH)) >= 0.5  # the outer windows: 0.5 m
    plain = load_spec(path)
    plain = plain.model_copy(
        update={"materials": {k: v for k, v in plain.materials.items() if k != "interior"}}
    )
    scene = facade_scene(solve(plain), path.parent)
    for _, mesh in _rooms(scene):
        assert np.ptp(mesh.vertices[:, 2]) == pytest.approx(RECESS_DEPTH, abs=1e-9)


def test_neighbouring_windows_show_different_rooms() -> None:
    """The rooms chosen for a row of windows a metre apart: every room of the atlas
    comes up in 200 windows, none more than twice as often as the mean."""
    places = np.array([(x, 3.0, 0.0) for x in range(200)], dtype=float)
    rooms = room_variant(places, 0)
    counts = np.bincount(rooms, minlength=ROOMS_GRID * ROOMS_GRID)
    assert (counts > 0).all() and counts.max() < 2 * counts.mean()
    assert (room_variant(places, 0) == rooms).all()
    assert (room_variant(places, 1) != rooms).any()


def test_the_rooms_are_one_picture_of_sixteen_different_rooms() -> None:
    """The atlas is one picture of 4 x 4 rooms; no two alike, each darker than the
    render wall (mean sRGB value under 0.72; render is 0.9), with a rim round it."""
    drawn = np.asarray(images(LIBRARY["rooms"].model_copy(update={"resolution": 256})).base_colour)
    m = drawn.shape[0] // ROOMS_GRID
    rooms = [
        drawn[r * m : (r + 1) * m, c * m : (c + 1) * m].astype(int)
        for r in range(ROOMS_GRID)
        for c in range(ROOMS_GRID)
    ]
    for k, room in enumerate(rooms):
        assert room.mean() / 255 < 0.72  # 0.40 to 0.69: rooms by day, as bright as a pale wall
        assert (room[0] == room[0, 0]).all() and (room[:, 0] == room[0, 0]).all()  # the rim
        for other in rooms[k + 1 :]:
            assert np.abs(room - other).mean() > 5


L_SHAPE = [(0, 0), (12, 0), (12, 2), (2, 2), (2, 10), (0, 10)]  # an arm 2 m across


@pytest.mark.parametrize(
    "outline, wall, deep",
    [
        ([(0, 0), (12, 0), (12, 10), (0, 10)], ((0, 0), (12, 0)), 10.0),
        ([(0, 0), (12, 0), (12, 2.4), (0, 2.4)], ((0, 0), (12, 0)), 2.4),
        ([(0, 0), (12, 0), (12, 1.7), (0, 1.7)], ((0, 0), (12, 0)), 1.7),  # Delft's least
        (L_SHAPE, ((2, 2), (2, 10)), 2.0),  # the arm's wall
        (L_SHAPE, ((0, 0), (12, 0)), 2.0),  # the long wall the arm stands on
    ],
)
def test_a_room_reaches_no_further_than_half_its_building_behind_its_wall(
    outline: list[tuple[float, float]],
    wall: tuple[tuple[float, float], tuple[float, float]],
    deep: float,
) -> None:
    """:func:`.room_reach` (the wall from ``a`` to ``b``, the building on its left):
    behind a wall of a deep building a room is :data:`ROOM_DEPTH` deep; behind one of a
    narrow building (or of an L's narrow arm) no deeper than half the building less
    5 cm, so that the rooms behind its facing walls stay apart and never come out at the
    far side (Delft's footprints are from 1.7 m across); within a step (0.2 m) of that."""
    from shapely.geometry import Polygon

    from facadecli.city.building import room_reach

    found = room_reach(Polygon(outline), *wall)
    assert found <= min(ROOM_DEPTH, (deep - 0.1) / 2) + 1e-9
    assert found >= min(ROOM_DEPTH, (deep - 0.1) / 2) - 0.2 - 1e-9


# ---- the room's box (:mod:`facadecli.geometry.rooms`): as wide as a room, floor at the
# storey's floor, as deep as one decision says, never meeting a neighbour's


def _room_boxes(scene: trimesh.Scene) -> list[tuple[str, np.ndarray]]:
    """Every room box of a façade scene: its node and its bounds in the façade's frame."""
    return [
        (node, trimesh.transform_points(mesh.bounds, scene.graph[node][0]))
        for node, mesh in _rooms(scene)
    ]


def _windows(layout: Layout) -> list[np.ndarray]:
    """The see-through boxes and panels of a layout (the glass of its openings): bounds."""
    return [
        np.array([(s.x0, s.y0, s.z0), (s.x1, s.y1, s.z1)])
        for s in layout.shapes
        if s.visible and s.mesh in ("box", "panel") and see_through(layout.spec, s.material)
    ]


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """How far apart two boxes (bounds) stand: on the axis where they stand furthest apart
    (negative: they overlap)."""
    return float(max(*(b[0] - a[1]), *(a[0] - b[1])))


def test_a_room_is_wider_than_its_window_and_stays_in_its_bay() -> None:
    """The townhouse's rooms reach beyond their windows' jambs behind the piers (a room
    was as wide as its window: a shaft), each within its bay: no further than half way
    to the next window, and within the façade; towards the façade's end no further than
    leaves the corner's rooms apart (the room stands as far from the end as it is deep
    behind the façade's plane, :func:`.room_depth`)."""
    path = ROOT / "specs" / "townhouse.yaml"
    layout = solve(load_spec(path))
    boxes = _room_boxes(facade_scene(layout, path.parent))
    windows = _windows(layout)
    assert len(boxes) == len(windows) == 16  # one room a window
    for node, box in boxes:
        (window,) = [w for w in windows if _apart(w[:, :2], box[:, :2]) < 0]
        wider = (window[0, 0] - box[0, 0], box[1, 0] - window[1, 0])
        end = min(box[0, 0], layout.width - box[1, 0])
        assert end >= -box[0, 2] - 1e-6, node  # as far from the end as it reaches in
        free = (box[0, 0], layout.width - box[1, 0])
        inner = [w for w, f in zip(wider, free, strict=True) if f > 1]  # not towards an end
        assert inner and min(inner) > 0.3, (node, wider)  # 0.36 to 0.44 m
        for other in windows:
            level = min(other[1, 1], window[1, 1]) > max(other[0, 1], window[0, 1])
            if level and other[0, 0] > window[1, 0]:  # the next window on its right
                assert box[1, 0] <= (window[1, 0] + other[0, 0]) / 2
            if level and other[1, 0] < window[0, 0]:  # on its left
                assert box[0, 0] >= (other[1, 0] + window[0, 0]) / 2


def test_a_rooms_floor_is_its_storeys_floor() -> None:
    """A window with its sill 0.9 m up and its head 0.3 m under the ceiling (a storey
    3 m high, on the second floor of three) looks into a room from the storey's floor to
    its ceiling (a room's floor was at the sill); the rooms of the windows above and
    below stop short of it; a window at the foot of the façade (a door) keeps its floor
    at its foot, and no room goes below the façade's foot or above its top."""
    storey, sill, head = 3.0, 0.9, 2.7
    openings = [Opening(1.0, 2.2, floor + sill, floor + head, -0.25) for floor in (0.0, 3.0, 6.0)]
    door = Opening(4.0, 5.0, 0.0, 2.4, -0.25)
    found = rooms([*openings, door], 8.0, 3 * storey)
    for floor, room in zip((0.0, 3.0, 6.0), found, strict=False):
        assert room is not None
        assert room.y0 == pytest.approx(floor + sill - BELOW_SILL, abs=ROOM_GAP / 2 + 1e-9)
        assert room.y1 == pytest.approx(floor + head + ABOVE_HEAD, abs=ROOM_GAP / 2 + 1e-9)
    assert found[3] is not None and found[3].y0 == 0.0
    # the examples: every room's floor is under its window's sill, as far as the window
    # below (half way to its head) and the façade's foot leave room, and its ceiling
    # over its window's head
    for path in EXAMPLES:
        layout = solve(load_spec(path))
        boxes = [box for _, box in _room_boxes(facade_scene(layout, path.parent))]
        windows = _windows(layout)
        for window in windows:
            (box,) = [b for b in boxes if _apart(window[:, :2], b[:, :2]) < 0]
            sill = window[0, 1]
            column = [w for w in windows if min(w[1, 0], window[1, 0]) > max(w[0, 0], window[0, 0])]
            heads = [w[1, 1] for w in column if w[1, 1] <= sill]
            below = [(sill - head) / 2 - ROOM_GAP / 2 for head in heads if head > sill - 2]
            drop = min([BELOW_SILL, sill, *below])
            assert box[0, 1] <= sill - drop + 1e-6, (path.stem, sill, drop)
            assert box[1, 1] >= window[1, 1] - 1e-6, path.stem


def test_the_rooms_of_neighbouring_windows_never_meet() -> None:
    """On every example, and on 200 façades of windows in a grid of random sizes and
    gaps (seeded), the room boxes stand :data:`ROOM_GAP` apart at the least (no overlap,
    no z-fighting), each holds its window, and stays within the façade."""
    for path in EXAMPLES:
        boxes = [box for _, box in _room_boxes(facade_scene(solve(load_spec(path)), path.parent))]
        for k, a in enumerate(boxes):
            for b in boxes[k + 1 :]:
                assert _apart(a, b) >= ROOM_GAP - 1e-6, path.stem
    rng = np.random.default_rng(35)
    for _ in range(200):
        columns, rows = rng.integers(1, 6, size=2)
        wide, high = rng.uniform(0.4, 2.5), rng.uniform(0.5, 2.8)
        gap_x, gap_y = rng.uniform(0.05, 2.0), rng.uniform(0.05, 2.0)
        jitter = rng.uniform(-0.2, 0.2, size=(columns * rows, 2))
        openings = []
        for k in range(columns * rows):
            x = 0.6 + (k % columns) * (wide + gap_x) + jitter[k, 0] * gap_x
            y = 0.5 + (k // columns) * (high + gap_y) + jitter[k, 1] * gap_y
            openings.append(Opening(x, x + wide, y, y + high, float(rng.uniform(-0.3, 0))))
        width = max(o.x1 for o in openings) + 0.6
        height = max(o.y1 for o in openings) + 0.3
        found = rooms(openings, width, height, float(rng.uniform(0.3, 1.5)))
        boxes = []
        for room in found:
            if room is None:  # one window with an earlier opening: its room holds both
                continue
            assert room.x0 >= 0 and room.x1 <= width and room.y0 >= 0 and room.y1 <= height
            boxes.append(
                np.array([(room.x0, room.y0, room.front - room.depth), (room.x1, room.y1, 0)])
            )
        for opening in openings:  # every window has a room that holds it
            assert any(
                b[0, 0] <= opening.x0 + 1e-9
                and b[1, 0] >= opening.x1 - 1e-9
                and b[0, 1] <= opening.y0 + 1e-9
                and b[1, 1] >= opening.y1 - 1e-9
                for b in boxes
            )
        for k, a in enumerate(boxes):
            for b in boxes[k + 1 :]:
                assert _apart(a[:, :2], b[:, :2]) >= ROOM_GAP - 1e-9


def test_a_rooms_depth_is_decided_once_and_its_box_made_at_it() -> None:
    """The space behind the wall (``behind``, metres behind the façade's plane: in a city
    :func:`.room_reach`) goes into the one decision of a room's depth
    (:func:`.room_depth`); a city's wall is built with its rooms that deep, each still a
    box of eight corners as high as behind a deep building (they were made 1.2 m deep
    and flattened to the reach, squashing each room's picture into its back)."""
    from facadecli.city.building import AxisCache

    path = ROOT / "specs" / "townhouse.yaml"
    spec = load_spec(path)
    layout = solve(spec)
    for behind in (0.4, 0.8, ROOM_DEPTH):
        scene = facade_scene(layout, path.parent, behind)
        for node, box in _room_boxes(scene):
            window = Opening(box[0, 0], box[1, 0], box[0, 1], box[1, 1], box[1, 2])
            deep = box[1, 2] - box[0, 2]
            assert box[0, 2] >= -behind - 1e-9, node  # no further behind the façade's plane
            assert deep <= room_depth(window, layout.width, behind) + 1e-9
    cache = AxisCache()
    walls = {}
    for behind in (0.4, ROOM_DEPTH):
        meshes = cache.facade("townhouse", spec, 9.4, 15.0, path.parent, behind=behind)
        assert meshes is not None
        # the ground floor's rooms lit, the others not: sixteen between them
        interior = trimesh.util.concatenate(
            [mesh for name, mesh in meshes if name in ("interior", "interior-lit")]
        )
        walls[behind] = interior
        pieces = _pieces(np.asarray(interior.vertices), np.asarray(interior.faces))
        assert pieces.max() + 1 == 16
        for piece in range(16):
            corners = interior.vertices[interior.faces[pieces == piece]].reshape(-1, 3)
            corners = np.unique(np.round(corners, 6), axis=0)
            assert len(corners) == 8  # a box, not a box with its back flattened
            assert corners[:, 2].min() >= -behind - 1e-6
    shallow, deep_rooms = walls[0.4], walls[ROOM_DEPTH]
    assert len(shallow.faces) == len(deep_rooms.faces)  # the same rooms, as high
    assert np.allclose(shallow.vertices[:, 1], deep_rooms.vertices[:, 1])
