"""The command line's habits: shell completion, -q/-v/--debug anywhere, ``-`` for standard
input and output, progress on standard error, ``facade city`` without a manifest,
``facade examples DIR``, and a missing extra named at the door."""

from __future__ import annotations

import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli.examples import example_files, examples_folder
from facadecli.extras import EXTRAS, extra_of
from tests.running import facade as run

ROOT = Path(__file__).resolve().parent.parent
HOUSE = ROOT / "specs" / "residential-house.yaml"
UNKNOWN_SYMBOL = ROOT / "tests" / "cases" / "invalid" / "unknown-symbol.yaml"


def facade(
    *args: str, stdin: str | None = None, env: dict[str, str] | None = None, cwd: Path = ROOT
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "facadecli", *args],
        input=stdin,
        capture_output=True,
        text=True,
        cwd=cwd,
        env={**os.environ, "COLUMNS": "200", "NO_COLOR": "1", **(env or {})},
    )


# completion


def test_completion_script_is_shown_for_the_facade_command() -> None:
    shown = facade(
        "--show-completion", "bash", env={"_TYPER_COMPLETE_TEST_DISABLE_SHELL_DETECTION": "1"}
    )
    assert shown.returncode == 0, shown.stderr
    assert "_FACADE_COMPLETE" in shown.stdout and "complete" in shown.stdout


def test_completion_completes_commands_and_options() -> None:
    commands = facade(
        env={"_FACADE_COMPLETE": "complete_bash", "COMP_WORDS": "facade so", "COMP_CWORD": "1"}
    )
    assert commands.returncode == 0, commands.stderr
    assert "solve" in commands.stdout.split()
    options = facade(
        env={
            "_FACADE_COMPLETE": "complete_bash",
            "COMP_WORDS": "facade solve --lab",
            "COMP_CWORD": "2",
        }
    )
    assert "--labels" in options.stdout.split()


# -q, -v, --debug: before or after the command


def test_quiet_keeps_errors_only(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "json", "--width", "4"]
    code, out, err = run(capsys, *args)
    assert code == 0 and "warning: x: symbol 'A'" in err and "solved in" in out
    for quiet in (["-q", *args], [*args, "--quiet"]):  # before or after the command
        assert run(capsys, *quiet) == (0, "", "")
    assert (tmp_path / "residential-house.layout.json").is_file()  # the work is done
    code, out, err = run(capsys, "solve", str(UNKNOWN_SYMBOL), "-o", str(tmp_path), "-q")
    assert code == 2 and "error:" in err  # errors stay


def test_verbose_adds_each_axis_on_standard_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "json"]
    _, plain, plain_err = run(capsys, *args)
    assert "axis:" not in plain_err
    untimed = re.compile(r"in [0-9.]+ ms")
    for verbose in (["-v", *args], [*args, "--verbose"]):  # before or after the command
        code, out, err = run(capsys, *verbose)
        assert code == 0, err
        axes = [line.split(": ")[1].split(" axis")[0] for line in err.splitlines()]
        assert axes == ["x", "y"] and "objective" in err and "(proven)" in err
        assert untimed.sub("", out) == untimed.sub("", plain)  # standard output the same


def test_quiet_and_verbose_together_are_a_usage_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = run(capsys, "validate", str(HOUSE), "-q", "-v")
    assert code == 2 and "not both" in err


def test_debug_after_the_command_and_flags_after_double_dash(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert run(capsys, "validate", str(HOUSE), "--debug")[0] == 0
    # after --, -q is a file name (a missing spec), not the flag
    code, _, err = run(capsys, "validate", "--", "-q")
    assert code == 2 and "-q: error: no such file" in err


# - for standard input and standard output


def _stdin(monkeypatch: pytest.MonkeyPatch, text: str) -> None:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text.encode())))


def test_validate_reads_standard_input_and_names_it_in_errors(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    _stdin(monkeypatch, HOUSE.read_text())
    code, out, _ = run(capsys, "validate", "-")
    assert code == 0 and out.startswith("<stdin>: ok (residential-house")
    _stdin(monkeypatch, UNKNOWN_SYMBOL.read_text())
    code, _, err = run(capsys, "validate", "-")
    line, col = UNKNOWN_SYMBOL.read_text().split()[2].split(":")
    assert code == 2 and f"<stdin>:{line}:{col}: error: " in err
    code, _, err = run(capsys, "validate", "-", "-")
    assert code == 2 and "read once" in err


def test_solve_from_standard_input_to_a_folder_and_to_standard_output(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    _stdin(monkeypatch, HOUSE.read_text())
    code, out, err = run(capsys, "solve", "-", "-o", str(tmp_path), "-f", "json")
    assert code == 0 and out.startswith("<stdin>: solved in"), err
    written = (tmp_path / "residential-house.layout.json").read_text()
    _stdin(monkeypatch, HOUSE.read_text())
    code, out, err = run(capsys, "solve", "-", "-o", "-", "-f", "json")
    assert code == 0, err
    assert out == written  # the file itself, nothing else
    assert "-> standard output" in err
    code, out, _ = run(capsys, "solve", str(HOUSE), "-o", "-", "-f", "svg")
    assert code == 0 and out.startswith("<?xml")


@pytest.mark.parametrize(
    "args",
    [
        ["-f", "obj"],  # two files
        ["-f", "json,svg"],  # two formats
        [str(HOUSE), "-f", "json"],  # two specs
    ],
)
def test_standard_output_takes_one_file(
    capsys: pytest.CaptureFixture[str], args: list[str]
) -> None:
    code, out, err = run(capsys, "solve", str(HOUSE), "-o", "-", *args)
    assert code == 2 and "standard output" in err and out == ""


def test_schema_to_standard_output_with_dash(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "schema", "-o", "-")[1] == run(capsys, "schema")[1]


# progress


def test_grammar_and_infer_tell_their_stages_on_standard_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    sample = ROOT / "samples" / "five-bays.json"
    args = ["grammar", str(sample), "-n", "50", "--method", "greedy"]
    code, _, err = run(capsys, *args, "-o", str(tmp_path / "g"))
    assert code == 0, err
    stages = [line.split(": ")[1] for line in err.splitlines() if line.endswith("...")]
    assert stages[:2] == ["reading...", "snapping 37 rectangles..."]
    assert "searching (greedy)..." in stages
    assert run(capsys, *args, "-o", str(tmp_path / "q"), "-q") == (0, "", "")
    target = str(tmp_path / "i" / "s.yaml")
    code, _, err = run(capsys, "infer", str(sample), "-o", target, "--no-check", "-v")
    assert code == 0, err
    assert "finding the bays and the grids of each label (at " in err


def test_vary_tells_each_size_on_standard_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    args = ["vary", str(HOUSE), "--widths", "8,12", "-o", str(tmp_path), "-f", "json"]
    code, _, err = run(capsys, *args)
    assert code == 0, err
    assert err.splitlines() == [
        f"{HOUSE}: 8 x 3 m: drawing 1 layout...",
        f"{HOUSE}: 12 x 3 m: drawing 1 layout...",
    ]
    assert run(capsys, *args, "-q")[2] == ""


# facade examples DIR


def test_examples_copies_the_specs_and_samples_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    target = tmp_path / "start"
    code, _, err = run(capsys, "examples", str(target))
    assert code == 0, err
    copied = sorted(p.relative_to(target) for p in target.rglob("*") if p.is_file())
    assert copied == example_files()
    assert Path("specs/townhouse.yaml") in copied and Path("samples/town.osm") in copied
    for path in copied:
        assert (target / path).read_bytes() == (examples_folder() / path).read_bytes()
    assert run(capsys, "validate", *map(str, sorted((target / "specs").glob("*.yaml"))))[0] == 0
    code, _, err = run(capsys, "examples", str(target))
    assert code == 2 and "already exist" in err


def test_the_examples_are_the_repository_s_own() -> None:
    """In a checkout the examples are the root's specs/ and samples/ (a wheel carries a
    copy made by setup.py's build_py)."""
    files = example_files()
    assert Path("specs/residential-house.yaml") in files
    assert Path("samples/five-bays.xml") in files
    assert all(not str(path).endswith((".pyc", "~")) for path in files)


# facade city without a manifest


def test_city_name_and_default_rules() -> None:
    from facadecli.city.default import city_name, default_city

    assert city_name(Path("helsinki.osm.pbf")) == "helsinki"
    assert city_name(Path("my town.geojson")) == "my_town"
    city = default_city(ROOT / "samples" / "town.osm")
    assert city.manifest.name == "town"
    assert Path(city.choose({"building": "retail"}).facade).name == "shop-front.yaml"
    assert Path(city.choose({"building": "apartments"}).facade).name == "terraced-house.yaml"
    assert Path(city.choose({"building": "yes"}).facade).name == "townhouse.yaml"
    chosen = default_city(ROOT / "samples" / "town.osm", HOUSE)
    assert {chosen.choose({"building": kind}).facade for kind in ("retail", "yes")} == {str(HOUSE)}


def test_city_checks_its_input_before_any_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    town = str(ROOT / "samples" / "town.osm")
    code, _, err = run(
        capsys, "city", town, "-o", str(tmp_path / "a"), "--spec", str(UNKNOWN_SYMBOL)
    )
    assert code == 2 and f"{UNKNOWN_SYMBOL}:" in err
    manifest = str(ROOT / "samples" / "town.yaml")
    code, _, err = run(capsys, "city", manifest, "-o", str(tmp_path / "b"), "--spec", town)
    assert code == 2 and "--spec" in err
    code, _, err = run(capsys, "city", str(tmp_path / "none.osm"), "-o", str(tmp_path / "c"))
    assert code == 2 and "no such file" in err
    assert not any((tmp_path / name).exists() for name in "abc")


@pytest.mark.slow
def test_city_from_an_osm_extract_without_a_manifest(tmp_path: Path) -> None:
    result = facade("city", "samples/town.osm", "-o", str(tmp_path), "-j", "1", "-v")
    assert result.returncode == 0, result.stderr
    assert "4 of 4 buildings built" in result.stdout
    assert result.stderr.count(": building way/") == 4  # -v: a line per building
    report = json.loads((tmp_path / "town.report.json").read_text())
    assert report["summary"]["ok"] == 4
    assert (tmp_path / "town.glb").is_file()


# a missing extra


def _without(
    modules: list[str], args: list[str], tmp_path: Path, doors: bool = True
) -> subprocess.CompletedProcess[str]:
    """``facade ARGS`` in a Python where ``modules`` cannot be imported, as after a
    ``pip install facadecli`` without the extra; without the checks at the commands'
    doors unless ``doors``."""
    code = (
        "import sys\n"
        f"for name in {modules!r}:\n    sys.modules[name] = None\n"
        "import facadecli.extras\n"
        + ("" if doors else "facadecli.extras.require = lambda extra, needed_by: None\n")
        + "from facadecli.cli import main\n"
        f"sys.argv = ['facade', *{args!r}]\n"
        "main()\n"
    )
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)


@pytest.mark.parametrize(
    ("modules", "args", "message"),
    [
        (
            ["shapely"],
            ["city", "samples/town.osm"],
            "facade city needs the [city] extra (shapely is not installed): "
            "pip install 'facadecli[city]'",
        ),
        (
            ["osmium"],
            ["city", "samples/town.yaml"],
            "facade city needs the [city] extra (osmium is not installed)",
        ),
        (
            ["distributed"],
            ["city", "samples/town.yaml", "--scheduler", "tcp://127.0.0.1:1"],
            "facade city --scheduler needs the [dask] extra (distributed is not installed): "
            "pip install 'facadecli[dask]'",
        ),
    ],
)
def test_a_missing_extra_is_one_line_naming_it(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    modules: list[str],
    args: list[str],
    message: str,
    tmp_path: Path,
) -> None:
    for name in modules:  # as after a pip install without the extra
        monkeypatch.setitem(sys.modules, name, None)
    code, out, err = run(capsys, *args, "-o", str(tmp_path / "out"))
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and err.startswith(message), err
    assert not (tmp_path / "out").exists()


def test_the_core_commands_need_no_extra(tmp_path: Path) -> None:
    every = [name for names in EXTRAS.values() for name in names]
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "glb,obj,json,svg,html,usd", "-q"]
    result = _without(every, args, tmp_path)
    assert result.returncode == 0, result.stderr
    written = [p for p in tmp_path.iterdir() if p.suffix != ".png"]  # and the library's PNGs
    assert len(written) == 7
    assert any(p.suffix == ".png" for p in tmp_path.iterdir())  # drawn without an extra


def test_an_import_past_the_door_names_its_extra(tmp_path: Path) -> None:
    """A module of an extra that a command imports without checking it first (a bug) is
    still one line naming the extra, not an internal error."""
    result = _without(
        ["pyproj"], ["city", "samples/town.osm", "-o", str(tmp_path)], tmp_path, False
    )
    assert result.returncode == 2
    assert result.stderr == (
        "facade city needs the [city] extra (pyproj is not installed): "
        "pip install 'facadecli[city]'\n"
    )
    assert extra_of("shapely.geometry") == "city"
    assert extra_of("distributed") == "dask"
    assert extra_of("pyogrio.raw") == "gdal"
    assert extra_of("numpy") is None and extra_of(None) is None


def test_a_quiet_watch_still_gives_its_address(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli import cli

    monkeypatch.setitem(cli._state, "quiet", True)
    log = cli._watch_log()
    log("x.yaml: serving http://127.0.0.1:8765/ (Ctrl-C to stop)", False)
    log("x.yaml: solved in 3 ms", False)
    log("x.yaml:1:1: error: bad", True)
    out, err = capsys.readouterr()
    assert out == "x.yaml: serving http://127.0.0.1:8765/ (Ctrl-C to stop)\n"
    assert err == "x.yaml:1:1: error: bad\n"


@pytest.mark.parametrize("command", ["grammar", "infer"])
def test_a_cmp_annotation_without_its_size_is_read_as_one_metre_and_says_so(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, command: str
) -> None:
    """A CMP annotation is a unit square: read without ``--size`` it is a 1 x 1 m façade,
    which a user is told on stderr (and ``infer`` in its report); with it, nothing."""
    sample = ROOT / "samples" / "five-bays.xml"
    options = ["-n", "50", "--method", "greedy"] if command == "grammar" else ["--no-check"]
    for sized, folder in ((False, "unsized"), (True, "sized")):
        target = tmp_path / folder / "s.yaml"
        output = ["-o", str(target if command == "infer" else target.parent)]
        size = ["--size", "15x12"] if sized else []
        code, _, err = run(capsys, command, str(sample), *options, *output, *size)
        assert code == 0, err
        told = [line for line in err.splitlines() if "a CMP annotation has no size" in line]
        assert len(told) == (0 if sized else 1), err
        assert all(
            line.startswith(f"{sample}: warning: ") and "read as a 1 x 1 m façade" in line
            for line in told
        )
        if command == "infer":
            report = json.loads(target.with_name("s.infer.json").read_text())
            assert bool(report["warnings"]) is not sized
