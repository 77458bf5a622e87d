"""Geometry and the 3D writers: glb (validated by Khronos' validator), glTF, OBJ."""

from __future__ import annotations

import dataclasses
import random
import shutil
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
import shapely
import trimesh

from facadecli import load_spec, parse_spec, solve
from facadecli.export.gltf import glb_bytes
from facadecli.export.obj import obj_files
from facadecli.geometry.facade import facade_scene, look, see_through
from facadecli.geometry.primitives import GLAZED, PANES, PRIMITIVES, Cell, asset
from facadecli.geometry.runs import built
from facadecli.layout import SOLID_BACK, Shape, _covered, cull, uncovered_area
from tests.khronos import VALIDATOR, validates
from tests.rays import directions, grid, missing, nearest, opaque_triangles, reach

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))


@pytest.mark.parametrize("name", sorted(PRIMITIVES))
@pytest.mark.parametrize("reflected", [False, True])
def test_primitives_fill_their_cell(name: str, reflected: bool) -> None:
    cell = Cell(width=1.2, height=2.4, thickness=0.3, segments=8)
    mesh = PRIMITIVES[name](cell)
    assert len(mesh.faces) >= 2
    low, high = mesh.bounds
    assert low[0] == pytest.approx(0.0, abs=1e-6) and high[0] == pytest.approx(1.2, abs=1e-6)
    assert low[1] == pytest.approx(0.0, abs=1e-6) and high[1] == pytest.approx(2.4, abs=1e-6)
    assert high[2] <= 1e-6 and low[2] >= -cell.width - 0.3  # in front of nothing, behind z=0


def test_frame_has_a_recessed_pane() -> None:
    mesh = PRIMITIVES["frame"](
        Cell(width=1.0, height=2.0, thickness=0.2, frame_width=0.1, pane_depth=0.08)
    )
    v = mesh.vertices
    opening = (
        (v[:, 0] > 0.1 + 1e-6)
        & (v[:, 0] < 0.9 - 1e-6)
        & (v[:, 1] > 0.1 + 1e-6)
        & (v[:, 1] < 1.9 - 1e-6)
    )
    assert not opening.any()  # nothing stands in the opening: bars are around it
    pane = PANES["frame"](
        Cell(width=1.0, height=2.0, thickness=0.2, frame_width=0.1, pane_depth=0.08)
    )
    assert (abs(pane.vertices[:, 2] + 0.08) < 1e-9).sum() >= 4  # the pane's front, 8 cm back
    assert np.allclose(pane.bounds, [[0.1, 0.1, -0.09], [0.9, 1.9, -0.08]])  # the opening


def test_mesh_assets_are_scaled_into_the_cell() -> None:
    door = trimesh.creation.box(extents=(10, 20, 5))
    fitted = asset(door, Cell(width=1.0, height=2.0, thickness=0.1))
    assert fitted.bounds.flatten().tolist() == pytest.approx([0, 0, -0.1, 1.0, 2.0, 0.0])


def _scene(path: Path) -> tuple[object, trimesh.Scene]:
    layout = solve(load_spec(path))
    return layout, facade_scene(layout, path.parent)


def _overlap(bounds: np.ndarray, shape: Shape) -> bool:
    """Whether a box (bounds) overlaps a shape's cell, seen head-on."""
    across = min(bounds[1, 0], shape.x1) > max(bounds[0, 0], shape.x0)
    return across and min(bounds[1, 1], shape.y1) > max(bounds[0, 1], shape.y0)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_glb_and_obj_load_back_with_the_canvas_bounds(path: Path, tmp_path: Path) -> None:
    layout, scene = _scene(path)
    pieces = built(layout.shapes)  # type: ignore[attr-defined]
    glb = tmp_path / "f.glb"
    glb.write_bytes(glb_bytes(scene))
    loaded = trimesh.load(glb, force="scene")
    width, height = layout.width, layout.height  # type: ignore[attr-defined]
    assert loaded.bounds[0][:2] == pytest.approx([0.0, 0.0], abs=1e-5)
    assert loaded.bounds[1][:2] == pytest.approx([width, height], abs=1e-5)
    instances = loaded.graph.nodes_geometry
    panes = [s for s in pieces if s.mesh in PANES and (s.mesh != "door" or s.look.glazing)]
    spec = layout.spec  # type: ignore[attr-defined]
    glazed = [s for s in pieces if s.mesh in GLAZED and see_through(spec, s.material)]
    glazed += [s for s in panes if see_through(spec, s.look.pane_material)]
    walls = [s for s in pieces if s.mesh == "box" and not see_through(spec, s.material)]
    groups = {(s.layer, s.material, min(s.z0, s.z1 - 1e-4), s.z1) for s in walls}
    # a node per piece (the walls of a layer: per material and depth), pane, and a recess
    # behind each glass; with a ``rooms`` interior, one room a window (a frame's pane and
    # the glazing behind it share one: :func:`.rooms.rooms`), holding each glass
    recesses = [n for n in instances if n.endswith("/recess")]
    assert len(instances) == len(pieces) - len(walls) + len(groups) + len(panes) + len(recesses)
    if look(spec, "interior").library != "rooms":
        assert len(recesses) == len(glazed)
    else:
        assert 0 < len(recesses) <= len(glazed)
        held = [
            trimesh.transform_points(loaded.geometry[loaded.graph[n][1]].bounds, loaded.graph[n][0])
            for n in recesses
        ]
        for s in glazed:  # a box's glass is its cell; a frame's pane is within its frame
            if s.mesh not in GLAZED:
                assert any(_overlap(b, s) for b in held), (s.layer, s.x, s.y)
                continue
            assert any(
                b[0, 0] <= s.x0 + 0.2
                and b[1, 0] >= s.x1 - 0.2
                and b[0, 1] <= s.y0 + 0.2
                and b[1, 1] >= s.y1 - 0.2
                for b in held
            ), (s.layer, s.x, s.y)
    assert all(len(loaded.geometry[loaded.graph[n][1]].faces) >= 1 for n in instances)
    text, files = obj_files(scene, "f")
    (tmp_path / "f.obj").write_text(text)
    material = files["f.mtl"]
    (tmp_path / "f.mtl").write_bytes(material)
    mesh = trimesh.load(tmp_path / "f.obj", force="mesh")
    assert mesh.bounds[1][:2] == pytest.approx([width, height], abs=1e-5)
    assert b"newmtl" in material


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_every_example_passes_the_khronos_validator(tmp_path: Path) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    files = []
    for path in EXAMPLES:
        _, scene = _scene(path)
        target = tmp_path / f"{path.stem}.glb"
        target.write_bytes(glb_bytes(scene))
        files.append(target)
    validates(*files)


def test_outputs_are_deterministic() -> None:
    path = ROOT / "specs" / "shop-front.yaml"
    first, second = _scene(path)[1], _scene(path)[1]
    assert glb_bytes(first) == glb_bytes(second)
    assert obj_files(first, "x") == obj_files(second, "x")


def test_a_thousand_windows_stay_small() -> None:
    text = """
version: 1
name: big
canvas: {width: 40, height: 30}
symbol_defaults: {opaque: true}
symbols: {E: 0.4, W: 0.8, S: 0.5, F: 1.2}
counters: {n: {min: 1}, m: {min: 1}}
patterns: {x: "E (W E)^n", y: "S (F S)^m"}
layers:
  - {name: wall, x: x, y: y}
  - {name: windows, x: x, y: y, shapes: [{match: {x: W, y: F}, mesh: frame, material: glass}]}
materials: {glass: {color: "#8fb3d9", opacity: 0.5}}
"""
    layout = solve(parse_spec(text))
    windows = [s for s in layout.shapes if s.layer == "windows" and s.x == "W" and s.y == "F"]
    assert len(windows) >= 500
    assert len(glb_bytes(facade_scene(layout))) < 2_000_000


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_elevations_match_the_golden_svgs(path: Path) -> None:
    from tests.golden import GOLDEN, elevation, same_drawing

    golden = GOLDEN / f"{path.stem}.svg"
    assert golden.exists(), "run 'make golden' to create it"
    assert same_drawing(elevation(path), golden.read_text()), (
        f"{path.name}: the elevation changed; look at it, then 'make golden'"
    )


def test_textures_get_uvs_in_metres(tmp_path: Path) -> None:
    from PIL import Image

    Image.new("RGB", (8, 8), (180, 80, 60)).save(tmp_path / "brick.png")
    (tmp_path / "wall.yaml").write_text(
        "version: 1\nname: wall\ncanvas: {width: 4, height: 3}\n"
        "symbols: {A: {size: 4, opaque: true}, H: {size: 3, opaque: true}}\n"
        "patterns: {x: A, y: H}\nlayers: [{name: wall, x: x, y: y}]\n"
        "materials: {brick: {texture: brick.png, texture_size: 0.5}}\n"
        "defaults: {material: brick}\n"
    )
    layout = solve(load_spec(tmp_path / "wall.yaml"))
    scene = facade_scene(layout, tmp_path)
    (tmp_path / "wall.glb").write_bytes(glb_bytes(scene))
    loaded = trimesh.load(tmp_path / "wall.glb", force="scene")
    (mesh,) = loaded.geometry.values()
    assert mesh.visual.material.baseColorTexture.size == (8, 8)
    # the 4 m x 3 m front face spans 8 x 6 copies of a 0.5 m texture
    assert mesh.visual.uv.max(axis=0) == pytest.approx([8.0, 6.0])
    _, files = obj_files(scene, "wall")
    assert "brick.png" in files and b"map_Kd brick.png" in files["wall.mtl"]


HIDDEN = """
version: 1
name: hidden
canvas: {{width: 4, height: 3}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1, B: 2, H: 3, F: 4}}
patterns: {{back: "A B A", front: F}}
defaults: {{thickness: 0.3}}
layers:
  - {{name: back, x: back, y: H}}
  - {{name: front, x: front, y: H, offset: {offset}{mesh}}}
"""


def test_hidden_shapes_are_culled_from_the_mesh_not_the_report() -> None:
    layout = solve(parse_spec(HIDDEN.format(offset=0.3, mesh="")))
    back = [s for s in layout.shapes if s.layer == "back"]
    assert len(back) == 3 and not any(s.visible for s in back)  # flush behind the front wall
    scene = facade_scene(layout)
    assert len(scene.graph.nodes_geometry) == 1  # only the front wall is built


@pytest.mark.parametrize(
    ("offset", "mesh"),
    [(0.5, ""), (0.3, ", shapes: [{match: {x: F, y: H}, mesh: frame}]")],
)
def test_what_an_oblique_view_sees_is_never_culled(offset: float, mesh: str) -> None:
    """A wall behind a layer that stands proud of it (air between), or behind a frame (open
    in the middle), can be seen from the side: it stays."""
    layout = solve(parse_spec(HIDDEN.format(offset=offset, mesh=mesh)))
    assert all(s.visible for s in layout.shapes if s.layer == "back")


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_no_ray_at_35_degrees_passes_through_an_example(path: Path) -> None:
    """Rays at 35° from the normal, from eight directions, at a 0.5 m grid over the façade:
    every one meets geometry (no see-through holes, slots or missing walls)."""
    layout = solve(load_spec(path))
    triangles = facade_scene(layout, path.parent).to_geometry().triangles
    xs = np.arange(0.25, layout.width - 0.2, 0.5)
    ys = np.arange(0.25, layout.height - 0.2, 0.5)
    targets = np.array([(x, y, 0.0) for x in xs for y in ys])
    for direction in directions():
        through = targets[missing(triangles, targets, direction)]
        assert len(through) == 0, f"rays along {direction} pass at {through[:5].tolist()}"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_no_view_through_a_window_passes_through_an_example(path: Path, tmp_path: Path) -> None:
    """The example solved to a glb and read back, its glass left out (blended or
    transmitting materials): rays at 35° from eight directions, every 25 cm over the
    façade (about 150,000 rays over the examples; 57,000 passed before windows were
    backed), still all meet the front of something opaque (a viewer draws no back face).
    Behind every pane is a dark recess, open towards the glass, so the far side of a
    building never shows through its near wall."""
    from facadecli.geometry.facade import TRANSMISSION, material_extensions

    command = [
        sys.executable,
        "-m",
        "facadecli",
        "solve",
        str(path),
        "-o",
        str(tmp_path),
        "-f",
        "glb",
    ]
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
    scene = trimesh.load(tmp_path / f"{path.stem}.glb")
    spec = load_spec(path)
    glass = {name for name, found in material_extensions(spec).items() if TRANSMISSION in found}
    triangles = opaque_triangles(scene, glass)
    targets = grid(scene.bounds[0], scene.bounds[1], step=0.25, margin=0.25)
    for direction in directions():
        through = targets[missing(triangles, targets, direction, culled=True)]
        assert len(through) == 0, f"{len(through)} rays along {direction}: {through[:5].tolist()}"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_the_walls_of_a_layer_are_one_seamless_mesh_per_material(path: Path) -> None:
    """The opaque boxes of a layer, of one material and depth, are one mesh: closed and
    consistently wound (every corner one vertex shared by the cells that meet there, no
    crack), as large as its cells (no faces left between them), and a ray straight at the
    edge between two of its cells meets its front, never a side face behind a seam."""
    layout = solve(load_spec(path))
    scene = facade_scene(layout, path.parent)
    spec = layout.spec
    groups: dict[tuple[str, str, float, float], list[Shape]] = {}
    for s in built(layout.shapes):
        if s.mesh == "box" and not see_through(spec, s.material):
            key = (s.layer, s.material, min(s.z0, s.z1 - 1e-4), s.z1)
            groups.setdefault(key, []).append(s)
    nodes = [n for n in scene.graph.nodes_geometry if "/walls-" in n]
    assert len(nodes) == len(groups) > 0
    meshes = {node: scene.geometry[scene.graph[node][1]] for node in nodes}
    for mesh in meshes.values():  # a textured wall's faces have their own corners: weld them
        welded = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        welded.merge_vertices(merge_tex=True, merge_norm=True)
        assert welded.is_watertight and welded.is_winding_consistent
    volume = sum((s.x1 - s.x0) * (s.y1 - s.y0) * (s.z1 - s.z0) for g in groups.values() for s in g)
    assert sum(m.volume for m in meshes.values()) == pytest.approx(volume, rel=1e-6)
    seams = 0
    for (layer, material, _, front), cells in groups.items():
        lefts = {(round(s.x0, 6), s.y0, s.y1) for s in cells}
        edges = [s for s in cells if (round(s.x1, 6), s.y0, s.y1) in lefts]
        if not edges:
            continue
        origins = np.array([(s.x1, (s.y0 + s.y1) / 2, 10.0) for s in edges])
        candidates = [m for n, m in meshes.items() if n.startswith(f"{layer}/walls-{material}/")]
        triangles = np.concatenate([m.triangles for m in candidates])
        met = reach(triangles, origins, np.array([0.0, 0.0, -1.0]))
        assert met == pytest.approx(np.full(len(origins), 10.0 - front), abs=1e-6)
        seams += len(origins)
    assert seams > 0


def test_a_mesh_file_next_to_the_spec_is_scaled_into_its_cells(tmp_path: Path) -> None:
    statue = trimesh.creation.icosphere(subdivisions=1, radius=5.0)
    statue.export(tmp_path / "statue.obj")
    (tmp_path / "niche.yaml").write_text(
        "version: 1\nname: niche\ncanvas: {width: 3, height: 3}\nsymbol_defaults: {opaque: true}\n"
        "symbols: {A: 1, S: 1, H: 3}\npatterns: {x: A S A, y: H}\n"
        "layers: [{name: wall, x: x, y: y}]\n"
        "shapes: [{match: {x: S}, mesh: statue.obj, thickness: 0.5}]\n"
    )
    layout = solve(load_spec(tmp_path / "niche.yaml"))
    scene = facade_scene(layout, tmp_path)
    placed = [
        scene.geometry[scene.graph[n][1]].bounds + scene.graph[n][0][:3, 3]
        for n in scene.graph.nodes_geometry
        if "/S." in n
    ]
    assert len(placed) == 1
    assert placed[0].flatten().tolist() == pytest.approx([1, 0, -0.5, 2, 3, 0], abs=1e-6)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_a_ray_at_the_middle_of_a_window_meets_glass_first(path: Path) -> None:
    """Straight at the middle of every frame or arch with nothing in front of it, the first
    thing met is see-through:
    its pane, or glass the spec put there (never a frame's solid panel)."""
    layout = solve(load_spec(path))
    order = {layer.name: i for i, layer in enumerate(layout.spec.layers)}
    shown = [s for s in layout.shapes if s.visible]
    windows = [
        s
        for s in shown
        if s.mesh in ("frame", "arch")
        and not any(  # a balcony or a railing stands in front of it by design
            order[o.layer] > order[s.layer]
            and o.x0 < (s.x0 + s.x1) / 2 < o.x1
            and o.y0 < (s.y0 + s.y1) / 2 < o.y1
            for o in shown
        )
    ]
    if not windows:
        pytest.skip("no frame or arch in this example")
    scene = facade_scene(layout, path.parent)
    parts, see_through = [], []
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        mesh = scene.geometry[geometry]
        parts.append(mesh.copy().apply_transform(transform).triangles)
        alpha = mesh.visual.material.baseColorFactor[3]
        see_through.extend([alpha < 255] * len(mesh.faces))
    triangles = np.concatenate(parts)
    origins = np.array([((s.x0 + s.x1) / 2, (s.y0 + s.y1) / 2, 50.0) for s in windows])
    first = nearest(triangles, origins, np.array([0.0, 0.0, -1.0]))
    assert (first >= 0).all() and np.array(see_through)[first].all()


@pytest.mark.parametrize(("width", "height"), [(1.2, 2.4), (3.0, 1.2)])
def test_an_arch_fills_its_cell(width: float, height: float) -> None:
    """Straight rays anywhere over an arch's cell meet the arch or its pane: the spandrels
    above the round top are wall, tall arches and low wide ones alike."""
    cell = Cell(width=width, height=height, thickness=0.2, frame_width=0.1, segments=12)
    triangles = np.concatenate([PRIMITIVES["arch"](cell).triangles, PANES["arch"](cell).triangles])
    xs, ys = np.linspace(0.01, width - 0.01, 30), np.linspace(0.01, height - 0.01, 40)
    origins = np.array([(x, y, 5.0) for x in xs for y in ys])
    assert (nearest(triangles, origins, np.array([0.0, 0.0, -1.0])) >= 0).all()


ARCHES = """
version: 1
name: arches
canvas: {width: 9.0, height: 4.0}
symbol_defaults: {opaque: true}
symbols: {E: 1.0, W: 1.6, G: 3.0, T: 1.0}
counters: {n: {min: 1}}
patterns: {x: "E (W E)^n", y: "G T"}
materials: {stone: {color: "#bdb3a1"}, white: {color: "#f4f1ea"}}
layers:
  - name: wall
    x: x
    y: y
    shapes:
      - {match: {x: W, y: G}, mesh: arch, material: stone, frame_width: 0.12}
      - {match: {x: W, y: T}, mesh: frame, material: white}
"""


def test_the_elevation_draws_frames_and_arches_with_their_panes() -> None:
    from xml.etree import ElementTree

    from facadecli.export.svg import svg_text

    layout = solve(parse_spec(ARCHES))
    root = ElementTree.fromstring(svg_text(layout))
    ns = "{http://www.w3.org/2000/svg}"
    arches = [p for p in root.iter(f"{ns}path") if " A " in p.get("d", "")]
    panes = [r for r in root.iter(f"{ns}rect") if r.get("fill") == "#a9c8e4"]
    windows = [s for s in layout.shapes if s.x == "W"]
    assert len(arches) == len(panes) == len(windows) // 2  # a round top, a glass pane each
    assert all(p.get("fill") == "#a9c8e4" and p.get("fill-opacity") for p in arches)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_labels_never_print_over_each_other(path: Path) -> None:
    from facadecli.export.svg import LABEL_CHAR, LABEL_LINE, PIXELS_PER_METRE, _labels

    layout = solve(load_spec(path))
    boxes = []
    for x, y, text in _labels(layout, PIXELS_PER_METRE):
        half = LABEL_CHAR * len(text) / PIXELS_PER_METRE / 2
        line = LABEL_LINE / PIXELS_PER_METRE
        boxes.append((x - half, x + half, y - line / 2, y + line / 2))
    assert len(boxes) >= len({(s.x0, s.y0) for s in layout.shapes if s.visible}) // 2
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not (
                a[0] < b[1] - 1e-9
                and b[0] < a[1] - 1e-9
                and a[2] < b[3] - 1e-9
                and b[2] < a[3] - 1e-9
            )


def _culled_by_brute_force(shapes: list[Shape]) -> list[bool]:
    """Which shapes are hidden, looking at every pair (what the cull's grid must find)."""
    order = {name: i for i, name in enumerate(dict.fromkeys(s.layer for s in shapes))}
    solid = [s for s in shapes if s.opaque and s.mesh in SOLID_BACK]
    hidden = []
    for shape in shapes:
        occluders = [
            o
            for o in solid
            if order[o.layer] > order[shape.layer]
            and o.z1 >= shape.z1
            and getattr(o, SOLID_BACK[o.mesh]) <= shape.z1 + 1e-9
            and o.x0 < shape.x1
            and o.x1 > shape.x0
            and o.y0 < shape.y1
            and o.y1 > shape.y0
        ]
        rectangles = [(o.x0, o.x1, o.y0, o.y1) for o in occluders]
        hidden.append(
            bool(occluders) and _covered((shape.x0, shape.x1, shape.y0, shape.y1), rectangles)
        )
    return hidden


@pytest.mark.parametrize("seed", range(8))
def test_the_cull_hides_what_looking_at_every_pair_hides(seed: int) -> None:
    """Random stacks of layers on a long façade: cells of a common grid (flush, proud or
    behind), some shapes many cells wide or tall, some not opaque or not solid."""
    rng = random.Random(seed)
    shapes = []
    for layer in range(6):
        z = rng.choice([0.0, 0.1, 0.2]) + 0.1 * layer
        for _ in range(rng.randint(20, 120)):
            x0, y0 = rng.randint(0, 60) * 0.5, rng.randint(0, 12) * 0.5
            wide = rng.random() < 0.1
            x1 = x0 + 0.5 * (rng.randint(10, 60) if wide else rng.randint(1, 3))
            y1 = y0 + 0.5 * (rng.randint(4, 12) if rng.random() < 0.1 else rng.randint(1, 2))
            shapes.append(
                Shape(
                    layer=f"layer{layer}",
                    x="A",
                    y="B",
                    x0=x0,
                    x1=x1,
                    y0=y0,
                    y1=y1,
                    z0=round(z - 0.1, 6),
                    z1=round(z, 6),
                    material="m",
                    mesh=rng.choice(["box", "box", "box", "frame", "panel"]),
                    reflected_x=False,
                    reflected_y=False,
                    opaque=rng.random() < 0.8,
                )
            )
    culled = cull(shapes)
    expected = _culled_by_brute_force(shapes)
    assert [not s.visible for s in culled] == expected
    assert sum(expected) > 10  # the case hides something


def test_a_hidden_shape_keeps_every_other_field() -> None:
    layout = solve(parse_spec(HIDDEN.format(offset=0.3, mesh="")))
    for shape in layout.shapes:
        assert shape.hidden() == dataclasses.replace(shape, visible=False)


@pytest.mark.parametrize("seed", range(6))
def test_the_uncovered_area_is_the_canvas_less_the_union_of_the_shapes(seed: int) -> None:
    rng = random.Random(seed)
    rectangles = []
    for _ in range(rng.randint(5, 60)):
        x0, y0 = rng.uniform(0, 9), rng.uniform(0, 5)
        rectangles.append(
            (x0, min(10.0, x0 + rng.uniform(0.1, 4)), y0, min(6.0, y0 + rng.uniform(0.1, 3)))
        )
    shapes = [
        Shape("l", "A", "B", x0, x1, y0, y1, 0.0, 0.1, "m", "box", False, False, True)
        for x0, x1, y0, y1 in rectangles
    ]
    layout = types.SimpleNamespace(width=10.0, height=6.0, shapes=shapes)
    union = shapely.unary_union([shapely.box(x0, y0, x1, y1) for x0, x1, y0, y1 in rectangles])
    assert uncovered_area(layout) == pytest.approx(60.0 - union.area, abs=1e-9)  # type: ignore[arg-type]
