"""The ``facade`` command as a user runs it: exit codes, messages, no tracebacks."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli import __version__

ROOT = Path(__file__).resolve().parent.parent
CASES = Path(__file__).parent / "cases"
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))


def facade(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": "200", "NO_COLOR": "1"}
    return subprocess.run(
        [sys.executable, "-m", "facadecli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
    )


def test_version() -> None:
    """The version, and a line saying the searches run in pure Python where this install
    has no compiled ones (pip hides the build's note)."""
    from facadecli import native

    result = facade("--version")
    assert result.returncode == 0
    lines = result.stdout.splitlines()
    assert lines[0] == f"facade {__version__}"
    searches = (native.EXACT_SEARCH, native.GRAMMAR_SEARCH)
    compiled = all(native.compiled(native.load(name)) for name in searches)
    assert len(lines) == (1 if compiled else 2)


def test_validate_accepts_every_example() -> None:
    result = facade("validate", *map(str, EXAMPLES), str(CASES / "valid" / "spec-md-example.yaml"))
    assert result.returncode == 0, result.stderr
    assert result.stdout.count(": ok (") == len(EXAMPLES) + 1


@pytest.mark.parametrize("path", sorted((CASES / "invalid").glob("*.yaml")), ids=lambda p: p.stem)
def test_validate_rejects_with_position_and_no_traceback(path: Path) -> None:
    result = facade("validate", str(path))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr + result.stdout
    line, col = path.read_text().split()[2].split(":")
    assert f"{path}:{line}:{col}: error: " in result.stderr


def test_binary_garbage_and_missing_files(tmp_path: Path) -> None:
    garbage = tmp_path / "garbage.yaml"
    garbage.write_bytes(os.urandom(4096))
    result = facade("validate", str(garbage), str(tmp_path / "missing.yaml"), str(tmp_path))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert f"{garbage}" in result.stderr
    assert f"{tmp_path / 'missing.yaml'}: error: no such file" in result.stderr
    assert "is a folder" in result.stderr


def test_bad_options_exit_2() -> None:
    result = facade("validate", "--no-such-option")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_schema_is_json_and_matches_the_checked_in_copy(tmp_path: Path) -> None:
    result = facade("schema")
    assert result.returncode == 0
    schema = json.loads(result.stdout)
    assert schema["title"] == "facadecli façade spec"
    assert result.stdout == (ROOT / "specs" / "facade.schema.json").read_text()
    assert facade("schema", "-o", str(tmp_path / "s.json")).returncode == 0
    assert (tmp_path / "s.json").read_text() == result.stdout


def test_words_previews_each_layer() -> None:
    result = facade("words", str(CASES / "valid" / "spec-md-example.yaml"), "-n", "2")
    assert result.returncode == 0, result.stderr
    assert "A B A B A B A   (k=3)" in result.stdout
    assert "C [e] C" in result.stdout


REPORT_KEYS = {
    "version",
    "name",
    "canvas",
    "counters",
    "symbols",
    "layers",
    "shapes",
    "alignment",
    "objective",
    "stats",
}


def test_solve_writes_the_report_and_the_elevation(tmp_path: Path) -> None:
    spec = ROOT / "specs" / "residential-house.yaml"
    result = facade("solve", str(spec), "-o", str(tmp_path))
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "residential-house.layout.json").read_text())
    assert set(report) >= REPORT_KEYS
    assert report["canvas"] == {"width": 6.0, "height": 3.0}
    assert report["counters"]["k"] == 4  # 0.4 + 4 x 1.4 = 6 m: every symbol at its size
    assert {"time_ms"} <= set(report["stats"])
    base = report["layers"][0]
    assert base["x"][0]["start"] == 0.0 and base["x"][-1]["end"] == 6.0
    shape = report["shapes"][0]
    assert {
        "layer",
        "x",
        "y",
        "x0",
        "x1",
        "y0",
        "y1",
        "z0",
        "z1",
        "material",
        "mesh",
        "visible",
    } <= set(shape)
    assert (tmp_path / "residential-house.svg").read_text().startswith("<?xml")
    assert not list(tmp_path.glob(".*.tmp"))  # atomic writes leave nothing behind


def test_solve_is_deterministic(tmp_path: Path) -> None:
    spec = ROOT / "specs" / "terraced-house.yaml"
    for run in ("a", "b"):
        assert facade("solve", str(spec), "-o", str(tmp_path / run)).returncode == 0
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    pictures = [name for name in names if name.endswith(".png")]  # the library's, for the OBJ
    assert [name for name in names if name not in pictures] == [
        "terraced-house.glb",
        "terraced-house.layout.json",
        "terraced-house.mtl",
        "terraced-house.obj",
        "terraced-house.svg",
    ]  # SPEC 4's default formats
    mtl = (tmp_path / "a" / "terraced-house.mtl").read_text()
    assert pictures and all(name in mtl for name in pictures)
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_gltf_is_json_and_a_buffer_that_load_back(tmp_path: Path) -> None:
    import trimesh

    spec = ROOT / "specs" / "shop-front.yaml"
    assert facade("solve", str(spec), "-o", str(tmp_path), "-f", "gltf").returncode == 0
    gltf = json.loads((tmp_path / "shop-front.gltf").read_text())
    (buffer,) = gltf["buffers"]
    assert (tmp_path / buffer["uri"]).stat().st_size == buffer["byteLength"]
    scene = trimesh.load(tmp_path / "shop-front.gltf", force="scene")
    assert scene.bounds[1][:2] == pytest.approx([14.4, 18.0], abs=1e-5)


def test_solve_retargets_and_picks_formats(tmp_path: Path) -> None:
    spec = ROOT / "specs" / "residential-house.yaml"
    result = facade("solve", str(spec), "-o", str(tmp_path), "--width", "9.0", "--format", "json")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "residential-house.layout.json").read_text())
    # k = 6 deviates 0.0241 m2 (A and C meet at 0.47 m), k = 5 deviates 0.0433
    assert report["canvas"]["width"] == 9.0 and report["counters"]["k"] == 6
    assert not (tmp_path / "residential-house.svg").exists()
    bad = facade("solve", str(spec), "-o", str(tmp_path), "--format", "gif")
    assert bad.returncode == 2 and "available" in bad.stderr


def test_solve_exit_codes(tmp_path: Path) -> None:
    infeasible = tmp_path / "tight.yaml"
    infeasible.write_text(
        "version: 1\nname: tight\ncanvas: {width: 10, height: 3}\n"
        "symbols: {A: {size: 1, max: 1.2, opaque: true}, H: {size: 3, opaque: true}}\n"
        'counters: {n: 3}\npatterns: {row: "A^n"}\n'
        "layers: [{name: wall, x: row, y: H}]\n"
    )
    result = facade("solve", str(infeasible), "-o", str(tmp_path / "out"))
    assert result.returncode == 3
    assert "no layout" in result.stderr and "x axis" in result.stderr
    # proven from the pattern before any search: the reason names the layer and the range
    assert "layer wall reaches at most 3.60 m, the canvas is 10.00 m" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()  # nothing written for a failed spec
    invalid = CASES / "invalid" / "unknown-symbol.yaml"
    assert facade("solve", str(invalid), "-o", str(tmp_path / "out")).returncode == 2
    good = ROOT / "specs" / "residential-house.yaml"
    mixed = facade("solve", str(good), str(infeasible), "-o", str(tmp_path / "mixed"))
    assert mixed.returncode == 1  # some specs of a multi-spec run failed
    assert (tmp_path / "mixed" / "residential-house.layout.json").exists()


def test_vary_writes_each_variant_and_a_contact_sheet(tmp_path: Path) -> None:
    spec = ROOT / "specs" / "residential-house.yaml"
    args = ["vary", str(spec), "--widths", "8,12", "--count", "3", "--seed", "7"]
    result = facade(*args, "-o", str(tmp_path / "a"), "-f", "json,svg")
    assert result.returncode == 0, result.stderr
    reports = sorted((tmp_path / "a").glob("*.layout.json"))
    names = [p.name for p in reports]
    assert "residential-house-8x3-0.layout.json" in names
    assert "residential-house-12x3-0.layout.json" in names
    counters = {json.dumps(json.loads(p.read_text())["counters"]) for p in reports}
    assert len(counters) >= 2  # different layouts, not copies
    sheet = (tmp_path / "a" / "contact-sheet.svg").read_text()
    assert sheet.count("<svg") == len(reports) + 1 and "12 x 3 m, seed 7, #0" in sheet
    again = facade(*args, "-o", str(tmp_path / "b"), "-f", "json,svg")
    assert again.returncode == 0
    for path in (tmp_path / "a").iterdir():
        assert path.read_bytes() == (tmp_path / "b" / path.name).read_bytes()


def test_vary_rejects_bad_sizes(tmp_path: Path) -> None:
    spec = ROOT / "specs" / "residential-house.yaml"
    result = facade("vary", str(spec), "--widths", "8,x", "-o", str(tmp_path))
    assert result.returncode == 2 and "metres" in result.stderr


def test_grammar_writes_text_json_svg_and_a_report(tmp_path: Path) -> None:
    layout = tmp_path / "floors.json"
    rects = [
        {"label": "window", "x0": x, "y0": y, "x1": x + 1, "y1": y + 1.5}
        for y in (0.5, 3.5, 6.5)
        for x in (1.0, 3.0, 5.0)
    ]
    layout.write_text(json.dumps({"canvas": {"width": 7, "height": 9.5}, "rects": rects}))
    result = facade("grammar", str(layout), "-o", str(tmp_path / "out"), "-n", "300")
    assert result.returncode == 0, result.stderr
    text = (tmp_path / "out" / "floors.grammar.txt").read_text()
    assert text.startswith("N1 --> split(y)") and "repeat(y)" in text
    grammar = json.loads((tmp_path / "out" / "floors.grammar.json").read_text())
    assert grammar["start"] == "N1" and grammar["terminals"] == ["facade", "window"]
    report = json.loads((tmp_path / "out" / "floors.grammar-report.json").read_text())
    assert report["method"] == "adp" and report["iterations"] == 300
    assert report["cost"] == grammar["cost"] <= 10.3 < report["greedy_cost"]
    assert report["rederives_exactly"] and report["time_ms"] is None
    assert (tmp_path / "out" / "floors.tiling.svg").read_text().startswith("<?xml")
    assert facade("grammar", str(tmp_path / "missing.xml")).returncode == 2


HEAVY = ("cvxpy", "numpy", "trimesh", "scipy", "dask", "distributed", "shapely", "pyproj")
SOLVER = ("facadecli.solver", "facadecli.layout", "facadecli.solve", "facadecli.geometry")


def _imported_by(args: list[str], watched: tuple[str, ...]) -> list[str]:
    """Which watched modules (a module or any of its submodules) a ``facade`` command has
    imported by the time it exits."""
    code = (
        "import json, sys\n"
        "from facadecli.cli import main\n"
        f"sys.argv = ['facade', *{args!r}]\n"
        "try:\n    main()\nexcept SystemExit as stop:\n    assert not stop.code, stop.code\n"
        f"watched = {watched!r}\n"
        "print(json.dumps([w for w in watched if any(m == w or m.startswith(w + '.')"
        " for m in sys.modules)]))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return list(json.loads(result.stdout.strip().splitlines()[-1]))


@pytest.mark.parametrize("args", [["--version"], ["validate", "specs/townhouse.yaml"]])
def test_start_up_imports_neither_the_solver_nor_numpy_nor_cvxpy_nor_trimesh(
    args: list[str],
) -> None:
    """``--version`` and ``validate`` load only what they use (the spec: pydantic, yaml)."""
    assert _imported_by(args, HEAVY + SOLVER) == []


def test_version_imports_no_pydantic_and_solving_no_cvxpy_nor_trimesh(tmp_path: Path) -> None:
    assert _imported_by(["--version"], ("pydantic", "yaml", "facadecli.spec")) == []
    solved = ["solve", "specs/residential-house.yaml", "-o", str(tmp_path), "--format", "json"]
    assert _imported_by(solved, ("cvxpy", "trimesh", "dask", "scipy")) == []


def test_a_sizing_with_active_bounds_reaches_clarabel_without_scipy(tmp_path: Path) -> None:
    """Clarabel takes its matrices as the arrays it reads (sizing._Csc), not SciPy's class:
    importing scipy.sparse costs more CPU than solving a small façade."""
    code = (
        "import sys\n"
        "from facadecli.cli import main\n"
        "from facadecli.solver import sizing\n"
        "calls = []\n"
        "real = sizing._clarabel\n"
        "sizing._clarabel = lambda program: calls.append(1) or real(program)\n"
        f"sys.argv = ['facade', 'solve', 'specs/townhouse.yaml', '-o', {str(tmp_path)!r},"
        " '--format', 'json']\n"
        "try:\n    main()\nexcept SystemExit as stop:\n    assert not stop.code, stop.code\n"
        "print(len(calls), any(m == 'scipy' or m.startswith('scipy.') for m in sys.modules))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    calls, scipy_loaded = result.stdout.split()[-2:]
    assert int(calls) > 0 and scipy_loaded == "False"


@pytest.mark.parametrize(("given", "expected"), [(None, "1"), ("3", "3")])
def test_numpy_runs_on_one_blas_thread_unless_the_user_says(
    given: str | None, expected: str
) -> None:
    """BLAS threads spin against each other on a loaded machine (20-40x slower least
    squares): facadecli asks for one before numpy loads, and keeps a value the user set."""
    environment = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    if given is not None:
        environment["OPENBLAS_NUM_THREADS"] = given
    code = (
        "import facadecli, numpy, os\n"
        "from facadecli.cli import main\n"
        "print(os.environ['OPENBLAS_NUM_THREADS'])\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        env=environment,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == expected
