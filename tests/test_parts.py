"""The parts users model every day: doors, railings, balconies, shutters, sills, profiles
that run along a floor, and glass that lets light through."""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest

from facadecli import load_spec, parse_spec, solve
from facadecli.export.glb_merge import merge_glb, read_glb
from facadecli.export.gltf import EMISSIVE_STRENGTH, glb_bytes
from facadecli.export.svg import svg_text
from facadecli.geometry.cell import Cell, railing_plan, shutter_plan
from facadecli.geometry.facade import IOR, TRANSMISSION, facade_scene, material_extensions
from facadecli.geometry.primitives import PANES, PRIMITIVES
from facadecli.geometry.runs import built
from tests.rays import directions, missing, nearest, reach

ROOT = Path(__file__).resolve().parent.parent
STRAIGHT = np.array([0.0, 0.0, -1.0])
SVG = "{http://www.w3.org/2000/svg}"


def _grid(width: float, height: float, z: float = 5.0, n: int = 25) -> np.ndarray:
    xs, ys = np.linspace(0.01, width - 0.01, n), np.linspace(0.01, height - 0.01, n)
    return np.array([(x, y, z) for x in xs for y in ys])


def test_a_door_is_closed_and_has_glass_only_where_it_is_glazed() -> None:
    panelled = Cell(width=1.0, height=2.2, thickness=0.15)
    assert PANES["door"](panelled) is None
    glazed = Cell(width=1.0, height=2.2, thickness=0.15, glazing=0.5, panels=1)
    pane = PANES["door"](glazed)
    assert pane is not None
    low, high = pane.bounds
    assert low[1] > 1.0 and high[1] < 2.2 - 0.1  # the upper half of the leaf, under the head
    door = PRIMITIVES["door"](glazed)
    triangles = np.concatenate([door.triangles, pane.triangles])
    first = nearest(triangles, _grid(1.0, 2.2), STRAIGHT)
    assert (first >= 0).all()  # frame, leaf and glass close the opening
    at_glass = nearest(triangles, np.array([(0.5, (low[1] + high[1]) / 2, 5.0)]), STRAIGHT)
    assert at_glass[0] >= len(door.faces)  # the middle of the glazing is glass


def test_a_door_has_raised_panels_and_no_sill() -> None:
    door = PRIMITIVES["door"](Cell(width=1.0, height=2.2, thickness=0.2, panels=3))
    leaf_front = -0.1  # the pane depth: half the thickness
    raised = np.isclose(door.vertices[:, 2], leaf_front + 0.015)
    assert raised.sum() >= 4 * 3 * 2  # three rows of two panels stand out of the leaf
    bottom = door.vertices[door.vertices[:, 1] < 1e-9]
    assert bottom[:, 2].min() == pytest.approx(-0.2)  # jambs reach the floor
    assert not np.any((bottom[:, 0] > 0.2) & (bottom[:, 0] < 0.8) & (bottom[:, 2] > -0.09))


def test_you_see_through_a_railing_between_its_bars() -> None:
    cell = Cell(width=1.5, height=1.0, thickness=0.05, spacing=0.15)
    mesh = PRIMITIVES["railing"](cell)
    plan = railing_plan(1.5, 1.0, 0.15)
    gaps = [(a[1] + b[0]) / 2 for a, b in zip(plan.bars, plan.bars[1:], strict=False)]
    assert len(plan.bars) == round((1.5 - 0.1) / 0.15) - 1
    between = np.array([(x, 0.5, 5.0) for x in gaps])
    on_bars = np.array([((x0 + x1) / 2, 0.5, 5.0) for x0, x1, *_ in plan.bars])
    assert (nearest(mesh.triangles, between, STRAIGHT) < 0).all()
    assert (nearest(mesh.triangles, on_bars, STRAIGHT) >= 0).all()
    assert nearest(mesh.triangles, np.array([(0.75, 0.99, 5.0)]), STRAIGHT)[0] >= 0  # handrail


def test_a_balcony_is_a_slab_with_a_railing_on_three_sides() -> None:
    cell = Cell(width=2.0, height=1.2, thickness=1.0)
    mesh = PRIMITIVES["balcony"](cell)
    down = np.array([0.0, -1.0, 0.0])
    floor = nearest(mesh.triangles, np.array([(1.0, 5.0, -0.5)]), down)
    assert floor[0] >= 0  # there is a floor to stand on
    hit = mesh.triangles[floor[0]]
    assert hit[:, 1].max() == pytest.approx(0.15)  # the slab's top
    sideways = np.array([1.0, 0.0, 0.0])
    side = nearest(mesh.triangles, np.array([(-5.0, 1.19, -0.5)]), sideways)
    assert side[0] >= 0  # a handrail along each side
    gap = railing_plan(2.0, 1.2 - 0.15, None).bars
    middle = (gap[7][1] + gap[8][0]) / 2
    head_on = nearest(mesh.triangles, np.array([(middle, 0.6, 5.0)]), STRAIGHT)
    assert head_on[0] < 0  # between the bars: the wall behind shows


def test_a_shutter_is_closed_from_every_side() -> None:
    cell = Cell(width=0.6, height=1.8, thickness=0.08)
    mesh = PRIMITIVES["shutter"](cell)
    assert len(shutter_plan(cell).bars) == int((1.8 - 2 * 0.06) / 0.06)
    targets = _grid(0.6, 1.8, z=0.0, n=20)
    targets = targets[
        (targets[:, 0] > 0.15)
        & (targets[:, 0] < 0.45)
        & (targets[:, 1] > 0.3)
        & (targets[:, 1] < 1.5)
    ]
    for direction in (*directions(), STRAIGHT):
        assert not missing(mesh.triangles, targets, direction).any()


def test_a_sill_stands_proud_of_the_frame() -> None:
    mesh = PRIMITIVES["frame"](Cell(width=1.2, height=1.6, thickness=0.1, sill=0.05))
    proud = mesh.vertices[mesh.vertices[:, 2] > 1e-9]
    assert proud[:, 2].max() == pytest.approx(0.05)
    assert proud[:, 1].max() <= 0.12 + 1e-9  # only the bottom bar


LEDGES = """
version: 1
name: ledges
canvas: {width: 6.0, height: 3.0}
symbol_defaults: {opaque: true}
symbols: {A: 1.0, B: 2.0, G: 2.6, K: 0.4}
patterns: {x: "A B A B", y: "G K"}
materials: {stone: {color: "#bdb3a1"}, brass: {color: "#b08d57", metallic: 1.0}}
layers:
  - name: wall
    x: x
    y: y
  - name: courses
    x: x
    y: y
    offset: 0.05
    visible: {y: [K]}
    shapes:
      - {match: {y: K}, mesh: ledge, material: stone, thickness: 0.2}
"""


def _pieces(text: str) -> list[str]:
    scene = facade_scene(solve(parse_spec(text)))
    return sorted(n for n in scene.graph.nodes_geometry if n.startswith("courses/"))


def test_a_profile_along_a_floor_is_one_piece() -> None:
    assert _pieces(LEDGES) == ["courses/A.K/0"]
    layout = solve(parse_spec(LEDGES))
    scene = facade_scene(layout)
    transform, geometry = scene.graph["courses/A.K/0"]
    low, high = scene.geometry[geometry].bounds + transform[:3, 3]
    assert (low[0], high[0]) == pytest.approx((0.0, 6.0))  # the whole floor, no seams
    root = ElementTree.fromstring(svg_text(layout))
    courses = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "layer-courses")
    assert len(courses.findall(f"{SVG}rect")) == 2  # the run and its corona, drawn once


def test_a_profile_breaks_where_its_material_or_a_gap_does() -> None:
    brass = LEDGES + "      - {match: {x: B, y: K}, material: brass}\n"
    assert len(_pieces(brass)) == 4  # stone, brass, stone, brass
    gap = LEDGES.replace("visible: {y: [K]}", "visible: {x: [A], y: [K]}")
    assert len(_pieces(gap)) == 2  # the two A cells are not side by side


@pytest.mark.parametrize(
    "path", [None, *sorted((ROOT / "specs").glob("*.yaml"))], ids=lambda p: p and p.stem
)
def test_a_string_course_closes_the_free_ends_of_its_facade(path: Path | None) -> None:
    """Rays along the façade plane, from beyond each free end (x = 0 and x = width), through
    every point of the section of a string course that reaches that end: each meets the
    model at the end itself. The grooves a ledge's profile leaves in its cell (under the
    cove, over the slope) are capped; nothing lets the sky through along the course."""
    layout = solve(parse_spec(LEDGES) if path is None else load_spec(path))
    courses = [s for s in built(layout.shapes) if s.mesh == "ledge"]
    ends = [s for s in courses if s.x0 < 1e-9 or s.x1 > layout.width - 1e-9]
    if not ends:
        pytest.skip("no string course reaches a free end")
    triangles = facade_scene(layout).to_geometry().triangles
    cast = 0
    for course in ends:
        ys = np.linspace(course.y0 + 1e-3, course.y1 - 1e-3, 24)
        zs = np.linspace(course.z0 + 1e-3, course.z1 - 1e-3, 24)
        section = np.array([(y, z) for y in ys for z in zs])
        for end, towards in ((0.0, 1.0), (layout.width, -1.0)):
            if abs(end - (course.x0 if towards > 0 else course.x1)) > 1e-9:
                continue
            origins = np.column_stack([np.full(len(section), end - towards), section])
            met = reach(triangles, origins, np.array([towards, 0.0, 0.0]))
            assert (met <= 1.0 + 1e-6).all(), section[met > 1.0 + 1e-6][:5].tolist()
            cast += len(section)
    assert cast > 0


def test_glass_lets_light_through_in_the_glb(tmp_path: Path) -> None:
    spec = load_spec(ROOT / "specs" / "centred-bay.yaml")
    # the example's glass is the library's float glass: it lets light through, and bends it
    glass_light = {TRANSMISSION: {"transmissionFactor": 1.0}, IOR: {"ior": 1.52}}
    assert material_extensions(spec) == {"glass": glass_light}
    layout = solve(spec)
    document, _ = read_glb(glb_bytes(facade_scene(layout), material_extensions(spec)))
    glass = [m for m in document["materials"] if m["name"] == "glass"]
    assert glass and glass[0]["extensions"] == glass_light
    assert {TRANSMISSION, IOR} <= set(document["extensionsUsed"])
    others = {m["name"]: m.get("extensions", {}) for m in document["materials"]}
    del others["glass"]
    # no other material lets light through; the one given off by a lit ground floor's
    # rooms is stronger than 1 by an extension of its own
    assert {name for name, found in others.items() if found} <= {"interior-lit"}
    assert all(set(found) <= {EMISSIVE_STRENGTH} for found in others.values())
    # a city merges building files: the extension stays declared
    for name in ("a", "b"):
        (tmp_path / f"{name}.glb").write_bytes(
            glb_bytes(facade_scene(layout), {"glass": glass_light})
        )
    merge_glb([(n, tmp_path / f"{n}.glb") for n in ("a", "b")], tmp_path / "city.glb")
    merged, _ = read_glb((tmp_path / "city.glb").read_bytes())
    assert merged["extensionsUsed"] == [EMISSIVE_STRENGTH, IOR, TRANSMISSION]


def test_without_transmission_no_extension_is_declared() -> None:
    layout = solve(parse_spec(LEDGES))
    document, _ = read_glb(glb_bytes(facade_scene(layout), material_extensions(layout.spec)))
    assert "extensionsUsed" not in document


PARTS = """
version: 1
name: parts
canvas: {width: 4.4, height: 3.2}
symbol_defaults: {opaque: true}
symbols: {E: 0.4, S: 0.5, D: 1.2, W: 1.0, G: 2.2, T: 1.0}
patterns: {x: "E S D S E W E", y: "G T"}
materials: {wood: {color: "#5a3a22"}, green: {color: "#3f6b4a"}, iron: {color: "#2b2b2b"}}
layers:
  - name: wall
    x: x
    y: y
  - name: parts
    x: x
    y: y
    offset: 0.05
    visible: {x: [S, D, W], y: [G]}
    shapes:
      - {match: {x: D}, mesh: door, material: wood, glazing: 0.4, panels: 2, thickness: 0.1}
      - {match: {x: S}, mesh: shutter, material: green, thickness: 0.05}
      - {match: {x: W}, mesh: railing, material: iron, thickness: 0.05}
"""


def test_the_elevation_draws_doors_railings_and_shutters_from_their_plans() -> None:
    layout = solve(parse_spec(PARTS))
    root = ElementTree.fromstring(svg_text(layout))
    parts = next(g for g in root.iter(f"{SVG}g") if g.get("id") == "layer-parts")
    fills = [r.get("fill") for r in parts.iter(f"{SVG}rect")]
    door = 3 + 4 + 2 * 2 + 1  # frame, leaf around the glazing, 2 x 2 panels, glass
    railing = len(railing_plan(1.0, 2.2, None).rails) + len(railing_plan(1.0, 2.2, None).bars)
    shutters = 2 * (1 + len(shutter_plan(Cell(0.5, 2.2, 0.05)).bars))
    assert fills.count("#5a3a22") == door - 1 and fills.count("#a9c8e4") == 1
    assert fills.count("#2b2b2b") == railing
    assert fills.count("#3f6b4a") == shutters
