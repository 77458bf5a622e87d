"""The reproducers of issue 37 at the spec, asset and grammar-layout doors, made small: each
ends in exit 2 with its place and the limit's name (or a correct exit 0), before the
expensive work, with nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.fuzz.spec_doors import (
    ASSET_SPEC,
    chain_glb,
    glb,
    instanced_glb,
    layout_cmp,
    layout_json,
    mesh_document,
    staggered_rects,
)
from tests.running import facade, files

# -- glTF assets: counted through the scene graph, before they are loaded -------------------


def _asset_spec(tmp_path: Path, data: bytes) -> Path:
    (tmp_path / "thing.glb").write_bytes(data)
    spec = tmp_path / "assets.yaml"
    spec.write_text(ASSET_SPEC.format(mesh="thing.glb"))
    return spec


@pytest.mark.parametrize("command", ["validate", "solve"])
def test_instances_of_one_mesh_count_against_the_triangle_limit(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    command: str,
) -> None:
    """400 nodes showing one 81,920-triangle mesh were flattened into 32,768,000 triangles."""
    from facadecli.spec import assets

    monkeypatch.setattr(assets, "MESH_FACES_MAX", 1000)  # the same shape, 1/200 of the size
    spec = _asset_spec(tmp_path, instanced_glb(triangles=500, instances=4))
    out = tmp_path / "out"
    code, _, err = facade(capsys, command, spec, *(["-o", out] if command == "solve" else []))
    assert code == 2, err
    assert "assets.yaml:8:" in err and "thing.glb" in err
    assert "has 2,000 triangles (each instance in its scene counted)" in err
    assert "limit of triangles of one mesh file (1,000)" in err
    assert files(out) == []


def test_instances_within_the_limit_solve(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    spec = _asset_spec(tmp_path, instanced_glb(triangles=5, instances=4))
    code, _, err = facade(capsys, "solve", spec, "-o", tmp_path / "out", "-f", "glb")
    assert code == 0, err
    assert files(tmp_path / "out") == ["assets.glb"]


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (chain_glb(40), "nests its nodes 40 levels deep, more than the limit of node depth"),
        (instanced_glb(1, 2049), "has 2,049 nodes, more than the limit of nodes of one mesh"),
    ],
)
def test_node_graphs_are_bounded_before_loading(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, data: bytes, expected: str
) -> None:
    spec = _asset_spec(tmp_path, data)
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and expected in err and "assets.yaml:8:" in err, err


def _glb_with_nodes(nodes: list[dict[str, object]], roots: list[int]) -> bytes:
    document, binary = mesh_document(1, nodes)
    document["scenes"] = [{"nodes": roots}]
    return glb(document, binary)


@pytest.mark.parametrize(
    ("nodes", "roots", "expected"),
    [
        ([{"children": [1]}, {"children": [0], "mesh": 0}], [0], "a cycle"),
        ([{"children": [0], "mesh": 0}], [0], "a cycle"),
        ([{"children": [5]}], [0], "not valid glTF"),
        ([{"children": [-1]}], [0], "not valid glTF"),
        ([{"mesh": -1}], [0], "not valid glTF"),
        ([{"mesh": 0}], [True], "not valid glTF"),
    ],
)
def test_broken_node_graphs_are_refused(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    nodes: list[dict[str, object]],
    roots: list[int],
    expected: str,
) -> None:
    spec = _asset_spec(tmp_path, _glb_with_nodes(nodes, roots))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and expected in err and "thing.glb" in err, err


def test_a_shared_subtree_counts_once_per_path(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each level of 30 points twice at the next: 2^30 paths to the mesh, counted, not walked."""
    from facadecli.spec import assets

    nodes: list[dict[str, object]] = [{"children": [i + 1, i + 1]} for i in range(30)]
    nodes.append({"mesh": 0})
    spec = _asset_spec(tmp_path, _glb_with_nodes(nodes, [0]))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and f"has {2**30:,} triangles" in err, err
    monkeypatch.setattr(assets, "MESH_FACES_MAX", 2**31)
    monkeypatch.setattr(assets, "GLTF_DEPTH_MAX", 2)
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and "31 levels deep" in err, err


# -- facade grammar on rectangles whose regions all differ -------------------------------------


@pytest.mark.parametrize("form", ["json", "xml"])
def test_staggered_squares_are_refused_by_the_search_budget(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, form: str
) -> None:
    """300 squares on a slant took 5 GB, then a RecursionError; 40 with a budget 1/100 of the
    real one are refused the same way, by the limit's name."""
    from facadecli.grammar import regions

    monkeypatch.setattr(regions, "WORK_MAX", 300_000)
    rects = staggered_rects(40)
    layout = tmp_path / f"slant.{form}"
    layout.write_text(layout_json(rects) if form == "json" else layout_cmp(rects))
    out = tmp_path / "out"
    code, _, err = facade(capsys, "grammar", layout, "-o", out)
    assert code == 2, err
    assert f"slant.{form}: error:" in err and "limit of work a grammar search does" in err
    assert "--snap" in err
    assert files(out) == []


def _tiling_of(tmp_path: Path, rects: list[tuple[float, float, float, float]]):  # type: ignore[no-untyped-def]
    from facadecli.grammar.deadline import Deadline
    from facadecli.grammar.model import Options
    from facadecli.grammar.tidy import tidy_layout
    from facadecli.grammar.tiling import tile

    layout = tmp_path / "slant.json"
    layout.write_text(layout_json(rects))
    deadline = Deadline()
    return tile(tidy_layout(layout, Options(), deadline).layout, tolerance=0.0)


@pytest.mark.parametrize("count", [6, 20])
def test_the_search_for_repeats_stops_at_its_share_of_the_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, count: int
) -> None:
    """600 squares on a slant spent 5 s of CPU growing repeated regions that the budget did
    not count: every step of that search now counts, and it stops before passing its share
    (at most one region's growing past it), the same on every machine."""
    from facadecli.grammar import regions, symmetry
    from facadecli.grammar.regions import Grid

    monkeypatch.setattr(regions, "WORK_MAX", 40_000)
    tiling = _tiling_of(tmp_path, staggered_rects(count))
    grid = Grid(tiling)
    found = symmetry.find_repeats(grid)
    share = symmetry.WORK_SHARE * regions.WORK_MAX
    one_growing = regions.STEP_UNITS * max(grid.rows, grid.columns) + grid.rows * grid.columns
    assert found.stopped == "work" and not found.complete
    assert share - one_growing < grid.work <= share + one_growing
    again = Grid(tiling)
    repeated = symmetry.find_repeats(again)  # the same work, the same repeats
    assert again.work == grid.work and repeated.kinds == found.kinds
    assert [a.tolist() for a in (repeated.r0, repeated.c0, repeated.r1, repeated.c1)] == [
        a.tolist() for a in (found.r0, found.c0, found.r1, found.c1)
    ]


def test_a_search_whose_repeats_ran_out_of_work_says_so(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.grammar import regions

    monkeypatch.setattr(regions, "WORK_MAX", 200_000)
    layout = tmp_path / "slant.json"
    layout.write_text(layout_json(staggered_rects(6)))
    out = tmp_path / "out"
    code, _, err = facade(capsys, "grammar", layout, "-o", out)
    assert code == 0, err
    assert "the search for repeated regions did the most work it may (100,000 of" in err
    assert len(files(out)) == 5


def test_seeds_are_the_rectangles_of_one_label_in_the_order_met() -> None:
    """The seeds (labelled compiled) against a flood fill, on random grids of 1-3 labels."""
    import numpy as np

    from facadecli.grammar import symmetry

    rng = np.random.default_rng(7)
    for _ in range(60):
        rows, cols = rng.integers(1, 12, size=2)
        labels = rng.integers(0, rng.integers(1, 4), size=(rows, cols))
        grid = type("G", (), {"labels": labels, "rows": int(rows), "columns": int(cols)})()
        assert symmetry._seeds(grid) == _flooded(labels)  # type: ignore[arg-type]


def _flooded(labels) -> list[tuple[int, int, int, int]]:  # type: ignore[no-untyped-def]
    rows, cols = labels.shape
    seen: set[tuple[int, int]] = set()
    found = []
    for r in range(rows):
        for c in range(cols):
            if (r, c) in seen:
                continue
            stack, cells = [(r, c)], []
            seen.add((r, c))
            while stack:
                i, j = stack.pop()
                cells.append((i, j))
                for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
                    inside = 0 <= a < rows and 0 <= b < cols
                    if inside and (a, b) not in seen and labels[a, b] == labels[r, c]:
                        seen.add((a, b))
                        stack.append((a, b))
            r0, r1 = min(i for i, _ in cells), max(i for i, _ in cells) + 1
            c0, c1 = min(j for _, j in cells), max(j for _, j in cells) + 1
            if len(cells) == (r1 - r0) * (c1 - c0):
                found.append((r0, r1, c0, c1))
    return found


def test_the_budget_stops_adp_with_the_best_grammar_so_far(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.grammar import regions

    monkeypatch.setattr(regions, "WORK_MAX", 300_000)  # the greedy grammar reads 140,033
    layout = tmp_path / "slant.json"
    layout.write_text(layout_json(staggered_rects(12)))
    out = tmp_path / "out"
    code, _, err = facade(capsys, "grammar", layout, "-o", out)
    assert code == 0, err
    assert "the search did the most work it may (300,000 units)" in err
    assert len(files(out)) == 5


def test_a_grammar_deeper_than_the_limit_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.grammar import search

    monkeypatch.setattr(search, "DEPTH_MAX", 3)
    layout = tmp_path / "slant.json"
    layout.write_text(layout_json(staggered_rects(8)))
    code, _, err = facade(capsys, "grammar", layout, "-o", tmp_path / "out", "--method", "greedy")
    assert code == 2 and "limit of rules nested in a grammar (3)" in err, err
    assert files(tmp_path / "out") == []


def test_the_search_reads_its_budget_of_cells_and_stops(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.grammar import regions
    from facadecli.grammar.deadline import Deadline
    from facadecli.grammar.model import Options
    from facadecli.grammar.search import Search
    from facadecli.grammar.tidy import tidy_layout
    from facadecli.grammar.tiling import tile

    layout = tmp_path / "slant.json"
    layout.write_text(layout_json(staggered_rects(8)))
    deadline = Deadline()
    tiling = tile(tidy_layout(layout, Options(), deadline).layout, tolerance=0.0)
    monkeypatch.setattr(regions, "WORK_MAX", 100_000)
    search = Search(tiling, deadline=deadline)
    search.greedy()
    greedy = search.grid.work
    _, _, done = search.adp(200, seed=1)
    assert greedy == 58_785 and search.grid.spent and done < 200  # ADP stopped


# -- "did you mean": bounded work ---------------------------------------------------------------

HINT_SPEC = """\
version: 1
name: hint
canvas: {{width: 4.0, height: 3.0}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1.0, F: 3.0}}
patterns: {{x: "A^+", y: F}}
shapes: [{{match: {{x: {name}, y: F}}}}]
layers:
  - {{name: wall, x: x, y: y}}
"""


@pytest.mark.parametrize(
    ("name", "hint"),
    [
        ("AF", "did you mean 'A F'? symbols are separated by spaces"),
        ("FF", "did you mean 'F F'?"),
        ("W" * 30_000, "declare it under symbols"),  # took 12 s of CPU: no hint is sought
        ("AF" * 15_000, "declare it under symbols"),
    ],
)
def test_an_unknown_name_gets_a_hint_within_bounded_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str, hint: str
) -> None:
    spec = tmp_path / "hint.yaml"
    spec.write_text(HINT_SPEC.format(name=name))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and "hint.yaml:7:" in err and hint in err, err[:500]


def test_hints_compare_only_names_that_could_be_close() -> None:
    from facadecli.hints import HINT_CHARS_MAX, closest, split_into

    assert closest("windw", ["window", "door"]) == "window"
    assert closest("w" * 40, ["w"]) is None  # too short to reach the cutoff: never compared
    assert closest("x" * (HINT_CHARS_MAX + 1), ["x" * (HINT_CHARS_MAX + 1)]) is None
    assert split_into("ABA", {"A", "B"}) == ["A", "B", "A"]
    assert split_into("ABBA", {"AB", "BA", "A"}) == ["AB", "BA"]
    assert split_into("A", {"A"}) is None


# -- YAML: tags on collections, the size limit's place ---------------------------------------


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("!!python/object/apply:os.system {args: [ls]}", "tag '!!python/object/apply:os.system'"),
        ("!!set {width, height}", "the mapping has the tag '!!set'"),
        ("!custom {width: 4, height: 3}", "the mapping has the tag '!custom'"),
        ("!!omap [{width: 4}, {height: 3}]", "the list has the tag '!!omap'"),
        ("!!python/tuple [4, 3]", "the list has the tag '!!python/tuple'"),
    ],
)
def test_tags_on_lists_and_mappings_are_refused_with_their_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, value: str, message: str
) -> None:
    spec = tmp_path / "tagged.yaml"
    spec.write_text(f"version: 1\nname: t\ncanvas: {value}\n")
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and "tagged.yaml:3:9: error:" in err and message in err, err
    assert "remove the '!' tag" in err


def test_the_plain_tags_of_lists_and_mappings_are_kept(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    spec = tmp_path / "plain.yaml"
    spec.write_text(HINT_SPEC.format(name="A").replace("canvas: {", "canvas: !!map {"))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 0, err


@pytest.mark.parametrize(
    ("line", "col", "tag"),
    [
        ("name: !!binary aGVsbG8=", 7, "!!binary"),
        ("name: !!python/name:os.system", 7, "!!python/name:os.system"),
        ("name: &n !custom hint", 7, "!custom"),
        ("name: !!timestamp 'x'", 7, "!!timestamp"),  # a bare date is one, tag or not
        ('name: !!binary "aGVsbG8="', 7, "!!binary"),
        ("canvas: {width: !!python/object:x 4.0, height: 3.0}", 17, "!!python/object:x"),
        ("canvas: {!!binary d2lkdGg=: 4.0, height: 3.0}", 10, "!!binary"),
    ],
)
def test_tags_on_values_and_keys_are_refused_with_their_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, line: str, col: int, tag: str
) -> None:
    """A tag on a scalar built bytes or dates (!!binary, !!timestamp) or was "invalid
    YAML" (!custom); now each is refused by name, at its key or value."""
    spec = tmp_path / "tagged.yaml"
    key = line.split(":")[0]
    text = HINT_SPEC.format(name="A")
    spec.write_text(
        "\n".join(line if row.startswith(f"{key}:") else row for row in text.split("\n"))
    )
    code, _, err = facade(capsys, "validate", spec)
    row = 2 if key == "name" else 3
    assert code == 2 and f"tagged.yaml:{row}:{col}: error:" in err, err
    assert f"has the tag '{tag}'" in err and "remove the '!' tag" in err


def test_the_core_tags_of_values_are_kept(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    spec = tmp_path / "plain.yaml"
    text = HINT_SPEC.format(name="A").replace("name: hint", "name: !!str 3")
    spec.write_text(text.replace("{width: 4.0, height: 3.0}", "{width: !!float 4, height: ! 3}"))
    code, out, err = facade(capsys, "validate", spec)
    assert code == 0 and "plain.yaml: ok (3: 1 layers)" in out, err


def test_a_spec_past_the_size_limit_is_refused_at_the_byte_past_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.spec import load, source

    monkeypatch.setattr(load, "SPEC_BYTES_MAX", 100)
    monkeypatch.setattr(source, "MAX_BYTES", 100)
    spec = tmp_path / "big.yaml"
    spec.write_text("version: 1\n" + "# é\n" * 30)
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2, err
    assert "big.yaml:19:4: error: the file is longer than specs are limited to (100 bytes" in err
    assert "the limit of a spec file" in err


# -- numbers within the limits ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "place", "message"),
    [
        ("counters: {n: 10001}", "7:15", "counters.n: Input should be less than or equal to 10000"),
        ("counters: {n: 18446744073709551616}", "7:15", "counters.n: Input should be less"),
        ("counters: {n: {min: 1, max: 10001}}", "7:29", "counters.n.max: Input should be less"),
        ("shapes: [{depth: 1.0e+21}]", "7:18", "shapes[0].depth: Input should be less"),
        ("defaults: {depth: -1.0e+300}", "7:19", "defaults.depth: Input should be greater"),
        ("defaults: {thickness: 1001}", "7:23", "defaults.thickness: Input should be less"),
        ("solver: {tolerance: 1.0e+200}", "7:21", "solver.tolerance: Input should be less"),
    ],
)
def test_numbers_past_the_limits_are_refused_with_their_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, line: str, place: str, message: str
) -> None:
    text = HINT_SPEC.format(name="A").replace("shapes: [{match: {x: A, y: F}}]\n", line + "\n")
    text = text.replace('x: "A^+"', 'x: "A^n"' if "counters" in line else 'x: "A^+"')
    spec = tmp_path / "numbers.yaml"
    spec.write_text(text)
    out = tmp_path / "out"
    for command in (["validate"], ["solve", "-o", str(out)]):
        code, _, err = facade(capsys, *command, spec)
        assert code == 2 and f"numbers.yaml:{place}: error: {message}" in err, err
        assert "the limit of a" in err
    assert files(out) == []


def test_a_layer_offset_past_the_limit_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    spec = tmp_path / "offset.yaml"
    spec.write_text(HINT_SPEC.format(name="A").replace("y: y}", "y: y, offset: 1.0e+21}"))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and "offset.yaml:9:38: error: layers[0].offset" in err, err
    assert "the limit of a length: at most 1,000 m either way" in err


# -- staging left by a killed run ---------------------------------------------------------------


def test_staging_of_runs_that_are_gone_is_removed_and_no_other(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import os
    import subprocess
    import sys

    from facadecli.export.atomic import _host, _started

    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    dead = int(gone.stdout)
    me, host = os.getpid(), _host()
    out = tmp_path / "out"
    out.mkdir()
    stale = [
        f".facade-{host}-{dead}-12345-abc_123",  # its process is gone
        f".facade-{host}-{me}-1-xyz",  # this process id, but another start: a reused id
    ]
    kept = [
        f".facade-{host}-{me}-{_started(me)}-live",  # a run still going
        f".facade-other.host-{dead}-12345-abc",  # another machine's (a shared folder)
        ".facade-abcd1234",  # named some other way (an older version's)
        f".facade-{host}-notapid-1-abc",
    ]
    for name in stale + kept:
        (out / name).mkdir()
        (out / name / "half.glb").write_bytes(b"glTF\x02")
    (out / f".facade-{host}-{dead}-1-file").write_text("a file, not a folder")
    (out / "mine.txt").write_text("the user's")
    spec = _asset_spec(tmp_path, instanced_glb(triangles=5, instances=2))
    code, _, err = facade(capsys, "solve", spec, "-o", out, "-f", "json,glb")
    assert code == 0, err
    names = sorted(p.name for p in out.iterdir())
    assert not any(name in names for name in stale)
    assert all(name in names for name in kept)
    assert f".facade-{host}-{dead}-1-file" in names and "mine.txt" in names
    assert "assets.glb" in names and "assets.layout.json" in names
    assert all((out / name / "half.glb").exists() for name in kept)


def test_staging_of_an_older_version_is_kept_and_told_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """facadecli 0.1.0 named its staging ``.facade-XXXXXXXX``: no owner to prove it is gone,
    so such folders stay, and a run (two specs into the folder: two stagings) says so once."""
    out = tmp_path / "out"
    out.mkdir()
    older = [".facade-abcd1234", ".facade-x_9z0qwe"]
    for name in older:
        (out / name).mkdir()
        (out / name / "half.glb").write_bytes(b"glTF\x02")
    (out / ".facade-file0001").write_text("a file, not a staging folder")
    spec = _asset_spec(tmp_path, instanced_glb(triangles=5, instances=2))
    other = tmp_path / "other.yaml"
    other.write_text(spec.read_text().replace("name: assets", "name: other"))
    code, _, err = facade(capsys, "solve", spec, other, "-o", out, "-f", "json")
    assert code == 0, err
    told = [line for line in err.splitlines() if "staging folder" in line]
    assert told == [
        f"{out}: warning: 2 staging folders of facadecli 0.1.0 left as they are "
        f"({', '.join(older)}): they name no owner, so they may be a run's still writing "
        "here; remove them when no facade run writes into this folder"
    ], err
    assert all((out / name / "half.glb").exists() for name in older)
    assert (out / ".facade-file0001").is_file()
    assert {"assets.layout.json", "other.layout.json"} <= {p.name for p in out.iterdir()}
    code, _, err = facade(capsys, "-q", "solve", spec, "-o", out, "-f", "json")
    assert code == 0 and err == "", err  # --quiet: errors only


def test_a_run_killed_while_staging_is_cleaned_up_by_the_next(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """kill -9 in the middle of writing: the half-written glb stays out of sight, in the
    staging folder, which the next run into the folder removes."""
    import signal
    import subprocess
    import sys

    out = tmp_path / "out"
    killed = (
        "import os, signal, sys\n"
        "from pathlib import Path\n"
        "from facadecli.export.atomic import staged\n"
        "with staged(sys.argv[1]) as stage:\n"
        "    (stage / 'assets.glb').write_bytes(b'glTF half')\n"
        "    os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    run = subprocess.run([sys.executable, "-c", killed, str(out)], check=False)
    assert run.returncode == -signal.SIGKILL
    left = [p.name for p in out.iterdir()]
    assert len(left) == 1 and left[0].startswith(".facade-"), left  # nothing visible
    spec = _asset_spec(tmp_path, instanced_glb(triangles=5, instances=2))
    code, _, err = facade(capsys, "solve", spec, "-o", out, "-f", "glb")
    assert code == 0, err
    assert files(out) == ["assets.glb"]
    assert (out / "assets.glb").read_bytes() != b"glTF half"


@pytest.mark.parametrize("uri", ["/dev/zero", "../outside.bin", "thing.bin", "http://x/y.bin"])
def test_a_glb_reads_no_file_but_itself(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, uri: str
) -> None:
    document, binary = mesh_document(1, [{"mesh": 0}])
    document["buffers"][0]["uri"] = uri
    spec = _asset_spec(tmp_path, glb(document, binary))
    code, _, err = facade(capsys, "validate", spec)
    assert code == 2 and "a .glb holds its own" in err, err


def test_a_gltf_reads_regular_files_in_its_folder_only(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import base64
    import json

    document, binary = mesh_document(1, [{"mesh": 0}])
    (tmp_path / "thing.bin").write_bytes(binary)
    (tmp_path / "zero.bin").symlink_to("/dev/zero")
    spec = tmp_path / "assets.yaml"
    spec.write_text(ASSET_SPEC.format(mesh="thing.gltf"))
    for uri, expected in [
        ("thing.bin", None),
        ("data:application/octet-stream;base64," + base64.b64encode(binary).decode(), None),
        ("zero.bin", "not a file in its folder"),
        ("../thing.bin", "not a file in its folder"),
        ("missing.bin", "not a file in its folder"),
    ]:
        document["buffers"][0]["uri"] = uri
        (tmp_path / "thing.gltf").write_text(json.dumps(document))
        code, _, err = facade(capsys, "validate", spec)
        if expected is None:
            assert code == 0, err
        else:
            assert code == 2 and expected in err and "assets.yaml:8:" in err, err


# -- seeded fuzz, a few cases a door (``python -m tests.fuzz.spec_doors`` runs thousands) ------

FUZZ_CASES = {"spec": 24, "asset": 30, "cmp-xml": 10, "json-layout": 10}


@pytest.mark.parametrize("door", list(FUZZ_CASES))
def test_hostile_inputs_at_each_door_end_cleanly(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, door: str
) -> None:
    """Exit 0, 2 or 3; no traceback; nothing left half-written or staged; all or nothing."""
    from tests.fuzz.spec_doors import DOORS, judge

    codes: dict[int, int] = {}
    for seed in range(FUZZ_CASES[door]):
        workdir = tmp_path / f"case{seed}"
        workdir.mkdir()
        argv = DOORS[door](seed, workdir)
        code, _, err = facade(capsys, *argv)
        codes[code] = codes.get(code, 0) + 1
        assert judge(argv, code, err, workdir) is None, (seed, argv, err[-2000:])
    assert codes.get(2, 0) >= FUZZ_CASES[door] // 4, codes  # the inputs are hostile


def test_a_grammar_at_the_depth_limit_is_written_derived_and_varied() -> None:
    """The limit keeps every stage that goes down a grammar one rule at a time within
    Python's recursion limit."""
    from facadecli.grammar import derive
    from facadecli.grammar.cga import grammar_cga
    from facadecli.grammar.outputs import grammar_json
    from facadecli.grammar.search import DEPTH_MAX
    from facadecli.grammar.split import Grammar, Part, Rule, derive_tree, inlined

    grammar = Grammar(start="N0", terminals={"a", "b"})
    width = height = 1000.0
    for level in range(DEPTH_MAX):  # each rule halves the region, across the last one's
        axis = "x" if level % 2 == 0 else "y"
        extent = width if axis == "x" else height
        below = f"N{level + 1}" if level + 1 < DEPTH_MAX else "b"
        grammar.rules[f"N{level}"] = Rule(
            "split", axis, (Part(extent / 2, "a"), Part(extent / 2, below))
        )
        width, height = (width / 2, height) if axis == "x" else (width, height / 2)
    assert len(derive_tree(grammar, 1000.0, 1000.0)) == 2 * DEPTH_MAX + 1
    assert len(inlined(grammar).rules) == DEPTH_MAX
    assert grammar_cga(grammar, 1000.0, 1000.0) and grammar_json(grammar) and grammar.text()
    assert derive.derive_at(grammar, (1000.0, 1000.0), 1200.0, 900.0)
    assert derive.with_runs(grammar, (1000.0, 1000.0)).rules
