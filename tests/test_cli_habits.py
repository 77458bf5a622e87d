"""The command line's habits: shell completion, -q/-v/--debug anywhere, ``-`` for standard
input and output, progress on standard error, ``facade city`` without a manifest,
``facade examples DIR``, and a missing extra named at the door."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from facadecli.examples import example_files, examples_folder
from facadecli.extras import EXTRAS, extra_of

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


@pytest.mark.parametrize("where", ["before", "after"])
def test_quiet_keeps_errors_only(where: str, tmp_path: Path) -> None:
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "json", "--width", "4"]
    loud = facade(*args)
    assert loud.returncode == 0 and "warning: x: symbol 'A'" in loud.stderr
    assert "solved in" in loud.stdout
    quiet = facade(*(["-q", *args] if where == "before" else [*args, "--quiet"]))
    assert quiet.returncode == 0
    assert quiet.stdout == "" and quiet.stderr == ""
    assert (tmp_path / "residential-house.layout.json").is_file()  # the work is done
    failed = facade("solve", str(UNKNOWN_SYMBOL), "-o", str(tmp_path), "-q")
    assert failed.returncode == 2 and "error:" in failed.stderr  # errors stay


@pytest.mark.parametrize("where", ["before", "after"])
def test_verbose_adds_each_axis_on_standard_error(where: str, tmp_path: Path) -> None:
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "json"]
    plain = facade(*args)
    assert "axis:" not in plain.stderr
    verbose = facade(*(["-v", *args] if where == "before" else [*args, "-v"]))
    assert verbose.returncode == 0, verbose.stderr
    lines = verbose.stderr.splitlines()
    assert [line.split(": ")[1].split(" axis")[0] for line in lines if " axis:" in line] == [
        "x",
        "y",
    ]
    assert "objective" in verbose.stderr and "(proven)" in verbose.stderr
    untimed = re.compile(r"in [0-9.]+ ms")
    assert untimed.sub("", verbose.stdout) == untimed.sub("", plain.stdout)  # stdout the same


def test_quiet_and_verbose_together_are_a_usage_error() -> None:
    both = facade("validate", str(HOUSE), "-q", "-v")
    assert both.returncode == 2 and "not both" in both.stderr


def test_debug_after_the_command_and_flags_after_double_dash(tmp_path: Path) -> None:
    assert facade("validate", str(HOUSE), "--debug").returncode == 0
    # after --, -q is a file name (a missing spec), not the flag
    result = facade("validate", "--", "-q")
    assert result.returncode == 2 and "-q: error: no such file" in result.stderr


# - for standard input and standard output


def test_validate_reads_standard_input_and_names_it_in_errors() -> None:
    good = facade("validate", "-", stdin=HOUSE.read_text())
    assert good.returncode == 0 and good.stdout.startswith("<stdin>: ok (residential-house")
    bad = facade("validate", "-", stdin=UNKNOWN_SYMBOL.read_text())
    line, col = UNKNOWN_SYMBOL.read_text().split()[2].split(":")
    assert bad.returncode == 2
    assert f"<stdin>:{line}:{col}: error: " in bad.stderr
    assert facade("validate", "-", "-", stdin="").returncode == 2  # read once only


def test_solve_from_standard_input_to_a_folder_and_to_standard_output(tmp_path: Path) -> None:
    spec = HOUSE.read_text()
    to_folder = facade("solve", "-", "-o", str(tmp_path), "-f", "json", stdin=spec)
    assert to_folder.returncode == 0, to_folder.stderr
    assert to_folder.stdout.startswith("<stdin>: solved in")
    written = (tmp_path / "residential-house.layout.json").read_text()
    to_stdout = facade("solve", "-", "-o", "-", "-f", "json", stdin=spec)
    assert to_stdout.returncode == 0, to_stdout.stderr
    assert to_stdout.stdout == written  # the file itself, nothing else
    assert "-> standard output" in to_stdout.stderr
    assert json.loads(to_stdout.stdout)["name"] == "residential-house"
    svg = facade("solve", str(HOUSE), "-o", "-", "-f", "svg")
    assert svg.returncode == 0 and svg.stdout.startswith("<?xml")


@pytest.mark.parametrize(
    "args",
    [
        ["-f", "obj"],  # two files
        ["-f", "json,svg"],  # two formats
        [str(HOUSE), "-f", "json"],  # two specs
    ],
)
def test_standard_output_takes_one_file(args: list[str], tmp_path: Path) -> None:
    result = facade("solve", str(HOUSE), "-o", "-", *args)
    assert result.returncode == 2 and "standard output" in result.stderr
    assert result.stdout == ""


def test_schema_to_standard_output_with_dash() -> None:
    assert facade("schema", "-o", "-").stdout == facade("schema").stdout


# progress


def test_grammar_and_infer_tell_their_stages_on_standard_error(tmp_path: Path) -> None:
    sample = ROOT / "samples" / "five-bays.json"
    args = ["grammar", str(sample), "-o", str(tmp_path / "g"), "-n", "50"]
    result = facade(*args)
    assert result.returncode == 0, result.stderr
    stages = [line for line in result.stderr.splitlines() if line.endswith("...")]
    assert [line.split(": ")[1] for line in stages][:2] == [
        "reading...",
        "snapping 37 rectangles...",
    ]
    assert any("searching (adp, 50 iterations)" in line for line in stages)
    assert facade(*args[:-4], "-o", str(tmp_path / "q"), "-n", "50", "-q").stderr == ""
    inferred = facade("infer", str(sample), "-o", str(tmp_path / "i" / "s.yaml"), "-v")
    assert inferred.returncode == 0, inferred.stderr
    assert "finding the grids of each label (at " in inferred.stderr
    assert "IoU of window: 1.0000" in inferred.stderr


def test_vary_tells_each_size_on_standard_error(tmp_path: Path) -> None:
    args = ["vary", str(HOUSE), "--widths", "8,12", "-o", str(tmp_path), "-f", "json"]
    result = facade(*args)
    assert result.returncode == 0, result.stderr
    assert result.stderr.splitlines() == [
        f"{HOUSE}: 8 x 3 m: drawing 1 layout...",
        f"{HOUSE}: 12 x 3 m: drawing 1 layout...",
    ]
    assert facade(*args, "-q").stderr == ""


# facade examples DIR


def test_examples_copies_the_specs_and_samples_once(tmp_path: Path) -> None:
    target = tmp_path / "start"
    result = facade("examples", str(target))
    assert result.returncode == 0, result.stderr
    copied = sorted(p.relative_to(target) for p in target.rglob("*") if p.is_file())
    assert copied == example_files()
    assert Path("specs/townhouse.yaml") in copied and Path("samples/town.osm") in copied
    for path in copied:
        assert (target / path).read_bytes() == (examples_folder() / path).read_bytes()
    assert facade("validate", *map(str, sorted((target / "specs").glob("*.yaml")))).returncode == 0
    again = facade("examples", str(target))
    assert again.returncode == 2 and "already exist" in again.stderr


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


def test_city_checks_its_input_before_any_work(tmp_path: Path) -> None:
    town = str(ROOT / "samples" / "town.osm")
    bad_spec = facade("city", town, "-o", str(tmp_path / "a"), "--spec", str(UNKNOWN_SYMBOL))
    assert bad_spec.returncode == 2 and f"{UNKNOWN_SYMBOL}:" in bad_spec.stderr
    with_manifest = facade(
        "city", str(ROOT / "samples" / "town.yaml"), "-o", str(tmp_path / "b"), "--spec", town
    )
    assert with_manifest.returncode == 2 and "--spec" in with_manifest.stderr
    missing = facade("city", str(tmp_path / "none.osm"), "-o", str(tmp_path / "c"))
    assert missing.returncode == 2 and "no such file" in missing.stderr
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
    modules: list[str], args: list[str], tmp_path: Path
) -> subprocess.CompletedProcess[str]:
    """``facade ARGS`` in a Python where ``modules`` cannot be imported, as after a
    ``pip install facadecli`` without the extra."""
    code = (
        "import sys\n"
        f"for name in {modules!r}:\n    sys.modules[name] = None\n"
        "from facadecli.cli import main\n"
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
    modules: list[str], args: list[str], message: str, tmp_path: Path
) -> None:
    result = _without(modules, [*args, "-o", str(tmp_path / "out")], tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines() == [message] or result.stderr.startswith(message)
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_the_core_commands_need_no_extra(tmp_path: Path) -> None:
    every = [name for names in EXTRAS.values() for name in names]
    args = ["solve", str(HOUSE), "-o", str(tmp_path), "-f", "glb,obj,json,svg,html,usd", "-q"]
    result = _without(every, args, tmp_path)
    assert result.returncode == 0, result.stderr
    assert len(list(tmp_path.iterdir())) == 7


def test_an_import_past_the_door_names_its_extra() -> None:
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
