"""Hostile and broken inputs at every door of the ``facade`` command: exit 2 with the
place (a file:line:col, or the option), no traceback, nothing written (SPEC 4)."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from facadecli.limits import CANVAS_MAX, SPEC_BYTES_MAX
from tests.running import facade, files

ROOT = Path(__file__).resolve().parent.parent
HOUSE = ROOT / "specs" / "residential-house.yaml"


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["--width", "inf"], "--width"),
        (["--width", "nan"], "--width"),
        (["--height", "1e308"], "--height"),
        (["--width", str(CANVAS_MAX * 2)], "--width"),
    ],
)
def test_solve_refuses_sizes_that_are_not_lengths(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: list[str], option: str
) -> None:
    code, _, err = facade(capsys, "solve", str(HOUSE), "-o", str(tmp_path / "out"), *args)
    assert code == 2 and option in err
    assert files(tmp_path / "out") == []


@pytest.mark.parametrize("widths", ["nan", "8,inf", "-3", "1e308", "x"])
def test_vary_refuses_sizes_that_are_not_lengths(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, widths: str
) -> None:
    code, _, err = facade(
        capsys, "vary", str(HOUSE), "--widths", widths, "-o", str(tmp_path / "out")
    )
    assert code == 2 and "--widths" in err
    assert files(tmp_path / "out") == []


@pytest.mark.parametrize("size", ["infx15", "nanx3", "1e308x1e308", "0x5", "12"])
def test_grammar_refuses_sizes_that_are_not_lengths(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, size: str
) -> None:
    rectangles = tmp_path / "rects.json"
    rectangles.write_text('[{"label": "window", "x": 1, "y": 1, "width": 1, "height": 1}]')
    code, _, err = facade(
        capsys, "grammar", str(rectangles), "--derive", size, "-o", str(tmp_path / "out")
    )
    assert code == 2 and "--derive" in err
    assert files(tmp_path / "out") == []


def test_an_output_folder_that_is_a_file_is_refused_before_the_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    blocker = tmp_path / "taken"
    blocker.write_text("not a folder")
    for target in (blocker, blocker / "below"):
        for command in (["solve", str(HOUSE)], ["vary", str(HOUSE), "--widths", "9"]):
            code, out, err = facade(capsys, *command, "-o", str(target))
            assert code == 2 and "--output" in err and "solved" not in out
    code, _, err = facade(capsys, "solve", str(HOUSE), "-o", "/dev/null")
    assert code == 2 and "--output" in err
    assert blocker.read_text() == "not a folder"


def test_outputs_appear_together_or_not_at_all(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A writer that fails half-way (a full disk) leaves nothing of the run behind."""
    from facadecli import export

    def full_disk(*_: object) -> list[Path]:
        raise OSError(28, "No space left on device")

    monkeypatch.setitem(export.WRITERS, "svg", full_disk)
    out = tmp_path / "out"
    code, _, err = facade(capsys, "solve", str(HOUSE), "-o", str(out), "-f", "json,glb,svg")
    assert code == 1 and "No space left on device" in err
    assert files(out) == []
    monkeypatch.undo()
    code, _, _ = facade(capsys, "solve", str(HOUSE), "-o", str(out), "-f", "json,svg")
    assert code == 0 and files(out) == ["residential-house.layout.json", "residential-house.svg"]


def test_a_spec_longer_than_the_limit_is_refused_without_reading_it_all(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    big = tmp_path / "big.yaml"
    big.write_text("# " + "x" * SPEC_BYTES_MAX + "\n")
    code, _, err = facade(capsys, "validate", str(big))
    assert code == 2 and "longer than specs are limited to" in err


SPEC_WITH_ASSETS = """\
version: 1
name: assets
canvas: {{width: 4.0, height: 3.0}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1.0, F: 3.0}}
patterns: {{x: "A^+", y: F}}
materials:
  brick: {{color: "#aa5533", texture: {texture}}}
layers:
  - {{name: wall, x: x, y: y, shapes: [{{match: {{x: A, y: F}}, mesh: {mesh}, material: brick}}]}}
"""

GOOD_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _png(width: int, height: int) -> bytes:
    """A PNG header declaring a size, with no pixel data (a decompression bomb's shape)."""
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IEND", b"")


def _good_png() -> bytes:
    from io import BytesIO

    from PIL import Image

    buffer = BytesIO()
    Image.new("RGB", (4, 4), "#aa5533").save(buffer, "PNG")
    return buffer.getvalue()


@pytest.mark.parametrize(
    ("name", "mesh", "texture", "expected"),
    [
        ("thing.obj", b"", None, "is empty"),
        ("thing.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", None, "holds no triangles"),
        ("thing.obj", b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", None, "not finite"),
        ("thing.glb", b"glTF\x02\x00\x00\x00" + b"\x00" * 12, None, "does not match"),
        ("thing.glb", b"not a glb at all, just text", None, "not a binary glTF"),
        ("thing.stl", b"\x00" * 80 + struct.pack("<I", 10**6), None, "declares 1,000,000"),
        ("thing.obj", None, b"", "is empty"),
        ("thing.obj", None, b"this is no image", "not a PNG or JPEG"),
        ("thing.obj", None, _png(13370, 13370), "more than a texture may be"),
        ("thing.obj", None, _png(4, 4), "cannot be read as an image"),
    ],
)
def test_validate_checks_the_files_solve_will_read(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    name: str,
    mesh: bytes | None,
    texture: bytes | None,
    expected: str,
) -> None:
    (tmp_path / name).write_bytes(GOOD_OBJ.encode() if mesh is None else mesh)
    (tmp_path / "brick.png").write_bytes(_good_png() if texture is None else texture)
    spec = tmp_path / "assets.yaml"
    spec.write_text(SPEC_WITH_ASSETS.format(mesh=name, texture="brick.png"))
    for command in (["validate"], ["solve", "-o", str(tmp_path / "out")]):
        code, _, err = facade(capsys, *command, str(spec))
        assert code == 2 and expected in err and "assets.yaml:" in err, err
    assert files(tmp_path / "out") == []


def test_the_same_spec_with_good_files_solves(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "thing.obj").write_text(GOOD_OBJ)
    (tmp_path / "brick.png").write_bytes(_good_png())
    spec = tmp_path / "assets.yaml"
    spec.write_text(SPEC_WITH_ASSETS.format(mesh="thing.obj", texture="brick.png"))
    code, _, err = facade(capsys, "solve", str(spec), "-o", str(tmp_path / "out"), "-f", "glb")
    assert code == 0, err
    assert files(tmp_path / "out") == ["assets.glb"]


def test_a_mesh_path_with_a_nul_is_an_error_with_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    (tmp_path / "brick.png").write_bytes(_good_png())
    spec = tmp_path / "assets.yaml"
    spec.write_text(SPEC_WITH_ASSETS.format(mesh='"thing\\0.obj"', texture="brick.png"))
    code, _, err = facade(capsys, "validate", str(spec))
    assert code == 2 and "control character" in err and "assets.yaml:10:" in err, err


def test_a_mesh_with_too_many_triangles_is_refused_before_it_is_loaded(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.spec import assets

    monkeypatch.setattr(assets, "MESH_FACES_MAX", 2)
    lines = ["v 0 0 0", "v 1 0 0", "v 0 1 0", "v 1 1 0", "f 1 2 3", "f 2 4 3", "f 1 2 4"]
    (tmp_path / "thing.obj").write_text("\n".join(lines) + "\n")
    (tmp_path / "brick.png").write_bytes(_good_png())
    spec = tmp_path / "assets.yaml"
    spec.write_text(SPEC_WITH_ASSETS.format(mesh="thing.obj", texture="brick.png"))
    code, _, err = facade(capsys, "validate", str(spec))
    assert code == 2 and "has 3 triangles" in err
