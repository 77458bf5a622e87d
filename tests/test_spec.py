"""Loading specs: the examples are valid; every kind of mistake is caught and located."""

from __future__ import annotations

import json
import re
from pathlib import Path

import jsonschema
import pytest
import yaml

from facadecli import SpecError, load_spec, parse_spec
from facadecli.spec import spec_schema_text
from facadecli.spec.source import MAX_BYTES

ROOT = Path(__file__).resolve().parent.parent
CASES = Path(__file__).parent / "cases"
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))
VALID = [*EXAMPLES, *sorted((CASES / "valid").glob("*.yaml"))]
INVALID = sorted((CASES / "invalid").glob("*.yaml"))


def expectation(path: Path) -> tuple[int, int, str]:
    """The ``# expect: LINE:COL text`` header of an invalid case."""
    match = re.match(r"# expect: (\d+):(\d+) (.+)", path.read_text().splitlines()[0])
    assert match, f"{path.name} needs a '# expect: LINE:COL text' first line"
    return int(match[1]), int(match[2]), match[3]


def test_there_are_enough_examples() -> None:
    assert len(EXAMPLES) >= 5
    assert len(INVALID) >= 15


@pytest.mark.parametrize("path", VALID, ids=lambda p: p.name)
def test_valid_specs_load(path: Path) -> None:
    spec = load_spec(path)
    assert spec.layers


@pytest.mark.parametrize("path", VALID, ids=lambda p: p.name)
def test_valid_specs_match_the_json_schema(path: Path) -> None:
    schema = json.loads(spec_schema_text())
    jsonschema.validate(yaml.safe_load(path.read_text()), schema)


@pytest.mark.parametrize("path", INVALID, ids=lambda p: p.stem)
def test_invalid_specs_are_located_and_explained(path: Path) -> None:
    line, col, text = expectation(path)
    with pytest.raises(SpecError) as caught:
        load_spec(path)
    located = [p for p in caught.value.problems if (p.line, p.col) == (line, col)]
    assert located, str(caught.value)
    problem = located[0]
    assert text in problem.message, str(caught.value)
    assert problem.hint, "every error says how to fix it"
    rendered = str(problem)
    assert rendered.startswith(f"{path}:{line}:{col}: error: ")
    assert rendered.endswith(")")


def test_all_problems_are_reported_at_once(tmp_path: Path) -> None:
    text = (CASES / "valid" / "spec-md-example.yaml").read_text()
    text = text.replace('"A (B A)^k"', '"A (BA)^k"').replace("material: stone", "material: ston")
    spec = tmp_path / "two.yaml"
    spec.write_text(text)
    with pytest.raises(SpecError) as caught:
        load_spec(spec)
    messages = [p.message for p in caught.value.problems]
    assert any("unknown symbol 'BA'" in m for m in messages)
    assert any("unknown material 'ston'" in m for m in messages)
    assert [p.line for p in caught.value.problems] == sorted(
        p.line or 0 for p in caught.value.problems
    )


def test_did_you_mean_splits_run_together_symbols() -> None:
    with pytest.raises(SpecError) as caught:
        load_spec(CASES / "invalid" / "unknown-symbol.yaml")
    assert "did you mean 'B A'?" in caught.value.problems[0].hint


@pytest.mark.parametrize(
    ("raw", "fragment"),
    [
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe", "not UTF-8"),
        (bytes(range(256)) * 4, "not UTF-8"),
        (b"a: 1\x00\x00", "NUL"),
        (b"[" * 200_000, "nested too deeply"),
        (b"- " * 50_000 + b"x", "nested too deeply"),
        (b"x: " + b"a" * (MAX_BYTES + 1), "limited to"),
        (b"a: &a [*a]", "recursive alias"),
        (b"", "empty"),
    ],
)
def test_hostile_input_is_refused_quickly(raw: bytes, fragment: str) -> None:
    with pytest.raises(SpecError) as caught:
        parse_spec(raw, "hostile.yaml")  # refused at once: no timing assert (CI is shared)
    assert fragment in str(caught.value)
    assert str(caught.value).startswith("hostile.yaml")


def test_merge_keys_and_anchors_are_supported() -> None:
    text = (CASES / "valid" / "spec-md-example.yaml").read_text()
    text = text.replace(
        '  stone: {color: "#d8d2c4", roughness: 0.8}',
        '  stone: &stone {color: "#d8d2c4", roughness: 0.8}\n'
        "  marble: {<<: *stone, roughness: 0.2}",
    )
    spec = parse_spec(text)
    assert spec.materials["marble"].color == "#d8d2c4"
    assert spec.materials["marble"].roughness == 0.2


def test_names_are_never_booleans() -> None:
    text = (CASES / "valid" / "spec-md-example.yaml").read_text()
    text = text.replace("  Q: 1.4", "  Q: 1.4\n  on: 0.5").replace('"P Q"', '"P Q on"')
    assert "on" in parse_spec(text).symbols


def test_the_model_is_frozen() -> None:
    spec = load_spec(CASES / "valid" / "spec-md-example.yaml")
    with pytest.raises(Exception, match="frozen"):
        spec.name = "other"  # type: ignore[misc]


def test_checked_in_schema_is_current() -> None:
    on_disk = (ROOT / "specs" / "facade.schema.json").read_text()
    assert on_disk == spec_schema_text(), "run 'make schema' to regenerate it"


def test_mesh_files_next_to_the_spec_are_accepted(tmp_path: Path) -> None:
    import trimesh

    (tmp_path / "assets").mkdir()
    (tmp_path / "assets" / "door.glb").write_bytes(trimesh.creation.box().export(file_type="glb"))
    text = (CASES / "valid" / "spec-md-example.yaml").read_text()
    text = text.replace("mesh: column ", "mesh: assets/door.glb ")
    (tmp_path / "spec.yaml").write_text(text)
    assert load_spec(tmp_path / "spec.yaml").shapes[1].mesh == "assets/door.glb"
    (tmp_path / "outside.glb").write_bytes(b"glTF")
    (tmp_path / "assets" / "link.glb").symlink_to(tmp_path / ".." / "nowhere.glb")
    text = text.replace("mesh: assets/door.glb ", "mesh: assets/link.glb ")
    (tmp_path / "spec.yaml").write_text(text)
    with pytest.raises(SpecError, match="leaves the spec's folder"):
        load_spec(tmp_path / "spec.yaml")


def test_the_tutorials_first_spec_is_valid() -> None:
    tutorial = (ROOT / "docs" / "tutorials" / "first-facade.md").read_text()
    first = tutorial.split("```yaml\n", 1)[1].split("```", 1)[0]
    spec = parse_spec(first, "first-facade.md")
    assert [layer.name for layer in spec.layers] == ["wall"]
