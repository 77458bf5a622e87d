"""Seeded mutations of real inputs at every door of ``facade``: no internal error, no
traceback, no partial output, whatever the input (issue: every bad input ends in exit 2).

Each test mutates small inputs a few hundred times with a fixed seed (the same cases on
every run) and runs the command in this process."""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path

import pytest

from tests.running import facade, files

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))

# what a hostile or careless hand puts into a file
TOKENS = [
    "",
    " ",
    "\t",
    "\n",
    ":",
    "- ",
    "{",
    "}",
    "[",
    "]",
    ",",
    '"',
    "'",
    "#",
    "&a ",
    "*a",
    "!!python/object:os.system ",
    "\x00",
    "\x1b",
    "~",
    "null",
    "true",
    ".inf",
    "-.inf",
    ".nan",
    "nan",
    "inf",
    "1e308",
    "-1",
    "0",
    "-0",
    "1e-320",
    "99999999999999999999",
    "\u202e",
    "é",
    "A^-1",
    "^",
    "(",
    ")",
    "|",
    "*",
    "?",
    "+",
    "x",
    "y",
    "<",
    ">",
    "&amp;",
    "&foo;",
    "Infinity",
    "NaN",
    "{}",
    "[]",
    "[[[[[[[[",
    "]]]]",
    '"x": ',
    "0x10",
]


def mutate(text: str, rng: random.Random, edits: int = 3) -> str:
    """``text`` with a few random edits: spans deleted, lines duplicated or swapped,
    tokens inserted or put in place of a character, the end cut off."""
    for _ in range(rng.randint(1, edits)):
        if not text:
            return rng.choice(TOKENS)
        kind = rng.randrange(6)
        at = rng.randrange(len(text))
        if kind == 0:
            text = text[:at] + text[at + rng.randint(1, 20) :]
        elif kind == 1:
            text = text[:at] + rng.choice(TOKENS) + text[at + 1 :]
        elif kind == 2:
            text = text[:at] + rng.choice(TOKENS) + text[at:]
        elif kind == 3:
            lines = text.split("\n")
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            text = "\n".join(lines)
        elif kind == 4:
            lines = text.split("\n")
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
        else:
            text = text[:at]
    return text


# what a careless program puts where a JSON value belongs
VALUES: list[object] = [
    None,
    [],
    {},
    "x",
    "",
    1e308,
    -1e308,
    -1,
    0,
    True,
    [[1, 2]],
    [[[0, 0]]],
    {"type": "Point", "coordinates": [0, 0]},
    {"type": "Nonsense"},
    [None],
    "EPSG:0",
    {"type": "name", "properties": {"name": "EPSG:99999"}},
    10**30,
]


def places(node: object) -> list[tuple[object, object]]:
    """Every (container, key) of a JSON document, depth first."""
    found: list[tuple[object, object]] = []
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    for key, value in items:
        found.append((node, key))
        found.extend(places(value))
    return found


def mutate_json(text: str, rng: random.Random, edits: int = 2) -> str:
    """A JSON document with a few values replaced by values of the wrong kind or range."""
    document = json.loads(text)
    for _ in range(rng.randint(1, edits)):
        parent, key = rng.choice(places(document))
        parent[key] = copy.deepcopy(rng.choice(VALUES))  # type: ignore[index]
    return json.dumps(document)


def test_mutated_specs_validate_or_fail_with_their_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    rng = random.Random(20261129)
    codes: dict[int, int] = {}
    for case in range(300):
        source = EXAMPLES[case % len(EXAMPLES)]
        path = tmp_path / f"case{case}.yaml"
        path.write_text(mutate(source.read_text(), rng), errors="surrogatepass")
        code, _, err = facade(capsys, "validate", str(path))
        codes[code] = codes.get(code, 0) + 1
        assert code in (0, 2), err
        if code == 2:
            assert f"case{case}.yaml" in err, err
    assert codes.get(2, 0) > 100  # the mutations do break specs


def test_mutated_specs_that_validate_solve_whole_or_not_at_all(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Mutations of the numbers only (sizes, counts, canvas): every outcome is a layout
    with all its files, or an exit code with its reason and no file."""
    rng = random.Random(7)
    numbers = ["0", "-1", "1e308", "0.0001", "999", ".inf", ".nan", "3", "1e-9", "1000"]
    solved = 0
    for case in range(16):
        source = EXAMPLES[case % len(EXAMPLES)].read_text()
        pieces = source.split(": ")
        for _ in range(2):
            i = rng.randrange(1, len(pieces))
            head, _, rest = pieces[i].partition(",")
            if head.replace(".", "", 1).isdigit():
                pieces[i] = rng.choice(numbers) + ("," + rest if rest or "," in pieces[i] else "")
        spec = tmp_path / f"case{case}.yaml"
        spec.write_text(": ".join(pieces))
        out = tmp_path / f"out{case}"
        code, _, err = facade(capsys, "solve", str(spec), "-o", str(out), "-f", "json,svg")
        assert code in (0, 2, 3, 4), err
        if code == 0:
            solved += 1
            assert len(files(out)) == 2
            report = json.loads(next(out.glob("*.layout.json")).read_text())
            assert "Infinity" not in json.dumps(report) and "NaN" not in json.dumps(report)
        else:
            assert files(out) == [], err
    assert solved > 0


def test_mutated_geojson_builds_rejects_or_fails_with_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from tests.test_city_inputs import MANIFEST, SPEC, square

    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "m.yaml").write_text(MANIFEST)
    features = ",\n".join(square(f"b{i}", x=12.0 * i) for i in range(2))
    crs = '{"type": "name", "properties": {"name": "EPSG:28992"}}'
    text = f'{{"type": "FeatureCollection", "crs": {crs},\n"features": [\n{features}\n]}}\n'
    rng = random.Random(5)
    codes: dict[int, int] = {}
    for case in range(100):
        mutated = mutate(text, rng, edits=2) if case % 2 else mutate_json(text, rng)
        (tmp_path / "f.geojson").write_text(mutated, errors="surrogatepass")
        out = tmp_path / f"out{case}"
        code, _, err = facade(capsys, "city", str(tmp_path / "m.yaml"), "-o", str(out), "-j", "1")
        codes[code] = codes.get(code, 0) + 1
        assert code in (0, 1, 2), err
        if code == 2:
            assert "f.geojson" in err and files(out) == [], err
    assert codes.get(2, 0) > 20 and codes.get(0, 0) > 10, codes  # both kinds met


def _cmp_facade() -> str:
    from tests.test_grammar_inputs import cmp_object

    objects = [cmp_object("0.0", "1.0", "0.0", "1.0", "facade")]
    for row in range(3):
        for column in range(3):
            top, left = 0.1 + 0.3 * row, 0.1 + 0.3 * column
            objects.append(
                cmp_object(f"{top:.2f}", f"{top + 0.15:.2f}", f"{left:.2f}", f"{left + 0.12:.2f}")
            )
    return "\n".join(objects) + "\n"


def _rectangles() -> str:
    rects = [{"label": "wall", "x0": 0, "y0": 0, "x1": 12, "y1": 9}]
    for row in range(3):
        for column in range(4):
            x, y = 1 + 3 * column, 1 + 3 * row
            rects.append({"label": "window", "x0": x, "y0": y, "x1": x + 1.2, "y1": y + 1.5})
    return json.dumps({"canvas": {"width": 12, "height": 9}, "rects": rects}, indent=1)


@pytest.mark.parametrize(("name", "make"), [("f.xml", _cmp_facade), ("f.json", _rectangles)])
def test_mutated_layouts_give_a_grammar_or_fail_with_their_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str, make: object
) -> None:
    text = make()  # type: ignore[operator]
    rng = random.Random(11)
    codes: dict[int, int] = {}
    for case in range(60):
        if name.endswith(".json") and case % 2:
            mutated = mutate_json(text, rng)
        else:
            mutated = mutate(text, rng, edits=2)
        path = tmp_path / name
        path.write_text(mutated, errors="surrogatepass")
        out = tmp_path / f"out{case}"
        code, _, err = facade(capsys, "grammar", str(path), "-o", str(out), "-n", "20")
        codes[code] = codes.get(code, 0) + 1
        assert code in (0, 2), err
        if code == 2:
            assert name in err and files(out) == [], err
        else:
            assert len(files(out)) == 5  # text, JSON, CGA, tiling, report
    assert codes.get(2, 0) > 10 and codes.get(0, 0) > 2, codes
