"""A room behind every pane (issue 35): each window's recess shows one room of the
library's ``rooms`` atlas on its back plate, varied from window to window by its place,
from one material and one picture; the same model gives the same bytes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from facadecli import load_spec, solve
from facadecli.geometry.facade import facade_scene, room_uv, room_variant
from facadecli.materials import LIBRARY, images
from facadecli.materials.textures import ROOMS_GRID

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))


def _plates(scene: trimesh.Scene) -> list[tuple[trimesh.Trimesh, np.ndarray]]:
    """Every recess of a façade scene (the ``/recess`` nodes): its mesh and the texture
    coordinates of its back plate's corners (the faces facing the window, +z)."""
    found = []
    for node in scene.graph.nodes_geometry:
        if not node.endswith("/recess"):
            continue
        mesh = scene.geometry[scene.graph[node][1]]
        facing = np.asarray(mesh.face_normals)[:, 2] > 0.99
        uv = np.asarray(mesh.visual.uv)[mesh.faces[facing]].reshape(-1, 2)
        found.append((mesh, uv))
    return found


def _luminance(image: object, uv: np.ndarray) -> np.ndarray:
    """The luminance (0..1, of the sRGB values) of a picture's pixels inside the box the
    texture coordinates ``uv`` span (v up, as trimesh keeps it)."""
    pixels = np.asarray(image, dtype=float) / 255.0
    n = pixels.shape[0]
    (u0, v0), (u1, v1) = uv.min(axis=0), uv.max(axis=0)
    columns = slice(int(u0 * n), max(int(u0 * n) + 1, int(u1 * n)))
    rows = slice(int((1 - v1) * n), max(int((1 - v1) * n) + 1, int((1 - v0) * n)))
    part = pixels[rows, columns]
    luminance: np.ndarray = part @ np.array([0.2126, 0.7152, 0.0722])
    return luminance


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_every_window_of_the_examples_shows_a_room(path: Path) -> None:
    """Behind every pane of every example is a back plate in a base-colour texture, and
    what its texture coordinates show is a room, not a plain dark plate: a back wall
    lighter than its floor and its rim, so its luminance spreads (one deviation, over
    the plate: 0.039 to 0.15 on the examples; the dark render the recesses wore before
    spread 0.0034 over its whole picture). The rooms vary: a façade of four windows or
    more shows four different rooms or more."""
    scene = facade_scene(solve(load_spec(path)), path.parent)
    plates = _plates(scene)
    assert plates, "no recess"
    shown = set()
    for mesh, uv in plates:
        picture = mesh.visual.material.baseColorTexture
        assert picture is not None
        spread = float(_luminance(picture, uv).std())
        assert spread > 0.03, (path.stem, spread)
        shown.add(tuple(np.floor(uv.mean(axis=0) * ROOMS_GRID).astype(int)))
    windows = len({id(mesh) for mesh, _ in plates})
    assert len(shown) >= min(4, windows), (len(shown), windows)


def test_a_recess_maps_its_plate_across_one_room_and_its_reveals_onto_the_rim() -> None:
    """:func:`room_uv` on two recesses side by side: each back plate spans one room of
    the atlas from its left to its right (u rises along the wall, seen from outside), its
    reveals lie on that room's rim; a room asked for is the one shown."""
    from facadecli.geometry.primitives import recess

    left = recess(trimesh.creation.box(bounds=[(0, 0, -0.01), (1, 2, 0)]))
    right = recess(trimesh.creation.box(bounds=[(3, 0, -0.01), (4, 2, 0)]))
    both = trimesh.util.concatenate([left, right])
    for room in (None, 6):
        mapped = room_uv(both, seed=5, room=room)
        uv = np.asarray(mapped.visual.uv).reshape(-1, 3, 2)
        corners = np.asarray(mapped.vertices).reshape(-1, 3, 3)
        for piece in range(2):
            faces = slice(10 * piece, 10 * piece + 10)
            cell = np.floor(uv[faces].mean(axis=(0, 1)) * ROOMS_GRID)
            if room is not None:
                assert tuple(cell) == (room % ROOMS_GRID, room // ROOMS_GRID)
            inside = uv[faces] * ROOMS_GRID - cell
            assert inside.min() > 0 and inside.max() < 1  # within one room's square
            plate = inside[:2].reshape(-1, 2)  # the back plate: the first quad
            xs = corners[faces][:2].reshape(-1, 3)[:, 0]
            assert np.corrcoef(xs, plate[:, 0])[0, 1] > 0.99  # u along the wall
            assert np.ptp(plate[:, 0]) > 0.9 and np.ptp(plate[:, 1]) > 0.9  # the whole room
            rim = inside[2:].reshape(-1, 2)  # the reveals: on the room's edge
            edges = np.minimum(np.abs(rim - 0.02), np.abs(rim - 0.98))
            assert (edges.min(axis=1) < 1e-6).all(), rim


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
    render wall (mean sRGB value under 0.6; render is 0.9), with a rim round it."""
    drawn = np.asarray(images(LIBRARY["rooms"].model_copy(update={"resolution": 256})).base_colour)
    m = drawn.shape[0] // ROOMS_GRID
    rooms = [
        drawn[r * m : (r + 1) * m, c * m : (c + 1) * m].astype(int)
        for r in range(ROOMS_GRID)
        for c in range(ROOMS_GRID)
    ]
    for k, room in enumerate(rooms):
        assert room.mean() / 255 < 0.6
        assert (room[0] == room[0, 0]).all() and (room[:, 0] == room[0, 0]).all()  # the rim
        for other in rooms[k + 1 :]:
            assert np.abs(room - other).mean() > 5
