"""``--format usd`` (issue 16): a USD stage that usd-core opens, with a prim per layer,
instanced parts, their materials bound, and the glTF's extent."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from tests.running import facade

pxr = pytest.importorskip("pxr", reason="usd-core is a test dependency (make test installs it)")
from pxr import Usd, UsdGeom, UsdShade  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def test_the_usd_stage_has_layers_instances_materials_and_the_gltf_extent(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = ROOT / "specs" / "townhouse.yaml"
    code, _, err = facade(capsys, "solve", spec, "-o", tmp_path, "-f", "usd,glb")
    assert code == 0, err
    stage = Usd.Stage.Open(str(tmp_path / "townhouse.usda"))
    root = stage.GetDefaultPrim()
    assert root.GetName() == "townhouse" and UsdGeom.GetStageUpAxis(stage) == "Y"
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    layers = [p.GetName() for p in root.GetChildren() if p.GetTypeName() == "Xform"]
    assert layers == ["wall", "ledges", "windows", "pilasters"]
    instances = [p for p in stage.Traverse() if p.IsInstance()]
    assert len(instances) > len(stage.GetPrototypes()) > 1  # repeated parts share a mesh
    meshes = [p for p in Usd.PrimRange(root, Usd.TraverseInstanceProxies()) if p.IsA(UsdGeom.Mesh)]
    assert len(meshes) == len(instances)
    for mesh in meshes:
        material, _ = UsdShade.MaterialBindingAPI(mesh).ComputeBoundMaterial()
        assert material and material.GetPath().pathString.startswith("/townhouse/Materials/")
        shader = UsdShade.Shader(material.GetPrim().GetChild("Surface"))
        assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
    bound = (
        UsdGeom.BBoxCache(Usd.TimeCode.Default(), ["default"])
        .ComputeWorldBound(root)
        .ComputeAlignedRange()
    )
    gltf = trimesh.load(tmp_path / "townhouse.glb").bounds
    assert list(bound.GetMin()) == pytest.approx(gltf[0], abs=1e-5)
    assert list(bound.GetMax()) == pytest.approx(gltf[1], abs=1e-5)


def test_every_example_writes_a_stage_usd_opens(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for spec in sorted((ROOT / "specs").glob("*.yaml")):
        code, _, err = facade(capsys, "solve", spec, "-o", tmp_path, "-f", "usd")
        assert code == 0, err
        stage = Usd.Stage.Open(str(tmp_path / f"{spec.stem}.usda"))
        assert stage.GetDefaultPrim().IsValid(), spec.name
        assert any(p.IsInstance() for p in stage.Traverse()), spec.name


def test_a_city_stage_holds_every_building_as_a_payload(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.test_city_inputs import square, town

    manifest = town(tmp_path, [square("a", 0.0), square("b", 20.0, 10.0), square("c", 40.0)])
    code, _, err = facade(capsys, "city", manifest, "-o", tmp_path / "out", "-j", "1", "--usd")
    assert code == 0, err
    stage = Usd.Stage.Open(str(tmp_path / "out" / "town.usda"))
    root = stage.GetDefaultPrim()
    buildings = root.GetChildren()
    assert [p.GetName() for p in buildings] == ["a", "b", "c"]
    assert all(p.HasPayload() for p in buildings)
    meshes = [p for p in Usd.PrimRange(root, Usd.TraverseInstanceProxies()) if p.IsA(UsdGeom.Mesh)]
    assert meshes and {p.GetPath().pathString.split("/")[2] for p in meshes} == {"a", "b", "c"}
    closed = Usd.Stage.Open(str(tmp_path / "out" / "town.usda"), Usd.Stage.LoadNone)
    assert not any(p.IsA(UsdGeom.Mesh) for p in closed.Traverse())  # payloads load on demand
    bound = (
        UsdGeom.BBoxCache(Usd.TimeCode.Default(), ["default"])
        .ComputeWorldBound(root)
        .ComputeAlignedRange()
    )
    assert bound.GetMax()[0] - bound.GetMin()[0] > 45  # the three side by side, 50 m


def test_a_city_stage_gives_every_building_its_own_prim(tmp_path: Path) -> None:
    """Prim names are unique by construction (:func:`.building_prim`), for ids that read
    the same as USD names ('a-b', 'a.b', 'a_b'), ids that read like a hashed file name,
    and many generated ones; the plain ids of letters, digits and '_', and the hashed
    file names (OSM's ids), keep their names as before; the stage names them so."""
    import random
    import re

    from facadecli.city.folders import building_file, safe_name
    from facadecli.export.usd import building_prim, city_usda, usd_name

    rng = random.Random(7)
    alphabet = "ab1_.-/~AB "
    ids = ["a-b", "a.b", "a_b", "ab", "1ab", "_1ab", "way/12", "Way/12", "a_0123456789abcdef"]
    ids += [safe_name("way/12").replace("~", "_"), "x" * 130]
    ids += ["".join(rng.choice(alphabet) for _ in range(rng.randint(1, 6))) for _ in range(3000)]
    ids = list(dict.fromkeys(ids))
    stems = [safe_name(i) for i in ids]
    assert len(set(stems)) == len(stems)  # as a run's FileNames checks
    prims = [building_prim(stem) for stem in stems]
    assert len(set(prims)) == len(prims)
    assert all(usd_name(p) == p for p in prims)
    assert building_prim("ab") == "ab" and building_prim("t12") == "t12"
    assert building_prim("1ab") == "_1ab" and building_prim("a_b") == "a_b"
    hashed = safe_name("way/12")
    assert building_prim(hashed) == usd_name(hashed)
    assert building_prim("a-b") != building_prim("a_b") != building_prim("a.b")
    glbs = [tmp_path / building_file(i) for i in ids[:40]]
    text = city_usda("c", glbs, tmp_path)
    assert re.findall(r'    def Xform "(\w+)" \(', text) == prims[:40]
