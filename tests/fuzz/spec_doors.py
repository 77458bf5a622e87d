"""Hostile inputs at the spec, asset and grammar-layout doors of ``facade``, generated from a
seed: each ``<door>_case(seed, workdir)`` writes one input under ``workdir`` and returns the
``facade`` arguments (without the program name) that read it.

The builders (``glb``, ``instanced_glb``, ``staggered_rects``, ...) are shared with the
tests of each reproducer (``tests/test_hostile_inputs.py``). Run this module to try many
cases as subprocesses: ``python -m tests.fuzz.spec_doors [cases per door]``.
"""

from __future__ import annotations

import json
import random
import re
import struct
from pathlib import Path
from typing import Any

from tests.test_fuzz import mutate, mutate_json

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))

# -- glTF --------------------------------------------------------------------------------


def glb(document: Any, binary: bytes = b"") -> bytes:
    """A binary glTF file of a JSON document and an optional binary chunk."""
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text
    if binary:
        chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def mesh_document(triangles: int, nodes: list[dict[str, Any]]) -> tuple[dict[str, Any], bytes]:
    """A glTF document with one mesh of ``triangles`` (indexed, all on one triangle) shown by
    ``nodes`` (every node a root of the scene), and its binary chunk."""
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    indices = bytes([0, 1, 2]) * triangles
    indices += b"\0" * (-len(indices) % 4)
    document = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(indices) + len(positions)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 3 * triangles},
            {"buffer": 0, "byteOffset": len(indices), "byteLength": len(positions)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5121, "count": 3 * triangles, "type": "SCALAR"},
            {
                "bufferView": 1,
                "componentType": 5126,
                "count": 3,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 0],
            },
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
        "nodes": nodes,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "scene": 0,
    }
    return document, indices + positions


def instanced_glb(triangles: int, instances: int) -> bytes:
    """One mesh shown by ``instances`` nodes side by side."""
    nodes = [{"mesh": 0, "translation": [i, 0, 0]} for i in range(instances)]
    return glb(*mesh_document(triangles, nodes))


def chain_glb(depth: int) -> bytes:
    """A mesh at the end of a chain of ``depth`` nodes, each the child of the one before."""
    nodes: list[dict[str, Any]] = [
        {"children": [i + 1], "translation": [0.001, 0, 0]} for i in range(depth - 1)
    ]
    nodes.append({"mesh": 0})
    document, binary = mesh_document(1, nodes)
    document["scenes"] = [{"nodes": [0]}]
    return glb(document, binary)


ASSET_SPEC = """\
version: 1
name: assets
canvas: {{width: 4.0, height: 3.0}}
symbol_defaults: {{opaque: true}}
symbols: {{A: 1.0, F: 3.0}}
patterns: {{x: "A^+", y: F}}
layers:
  - {{name: wall, x: x, y: y, shapes: [{{match: {{x: A, y: F}}, mesh: {mesh}}}]}}
"""

# -- layouts -----------------------------------------------------------------------------


def staggered_rects(count: int, side: float = 0.5) -> list[tuple[float, float, float, float]]:
    """``count`` squares on a slanted line, each edge a little off the others' edges."""
    return [(i * 1.0001, i * 1.0003, i * 1.0001 + side, i * 1.0003 + side) for i in range(count)]


def layout_json(rects: list[tuple[float, float, float, float]], label: str = "window") -> str:
    entries = [{"label": label, "x0": x0, "y0": y0, "x1": x1, "y1": y1} for x0, y0, x1, y1 in rects]
    return json.dumps(entries)


def cmp_object(top: float, bottom: float, left: float, right: float, label: str) -> str:
    return (
        f"<object><points><x>{top!r}</x><x>{bottom!r}</x><y>{left!r}</y><y>{right!r}</y>"
        f"</points><label>3</label><labelname>{label}</labelname><flag>1</flag></object>"
    )


def layout_cmp(rects: list[tuple[float, float, float, float]], label: str = "window") -> str:
    """The rectangles as a CMP annotation (x down, y across, in 0..1 of the extent)."""
    width = max(r[2] for r in rects)
    height = max(r[3] for r in rects)
    objects = [cmp_object(0.0, 1.0, 0.0, 1.0, "facade")]
    for x0, y0, x1, y1 in rects:
        top, bottom = 1 - y1 / height, 1 - y0 / height
        objects.append(cmp_object(top, bottom, x0 / width, x1 / width, label))
    return "\n".join(objects) + "\n"


# -- the doors -------------------------------------------------------------------------------

# what a hostile hand puts where a spec's value belongs
SPEC_VALUES = [
    "1.0e+21",
    "-1.0e+300",
    "1e21",
    "10001",
    "18446744073709551616",
    "-1",
    "0",
    ".nan",
    ".inf",
    "!!set {a, b}",
    "!custom {x: 1}",
    "!!python/object/apply:os.system [ls]",
    "!!omap [{a: 1}]",
    "!!binary aGVsbG8=",
    "!!float 1e400",
    "[" * 80 + "]" * 80,
    "{a: {b: {c: {d: [[[[[]]]]]}}}}",
    "&x [1, 2]",
    "*x",
    '"' + "\\u0000" + '"',
    "~",
    "{}",
    "[]",
]


def _long_name(rng: random.Random) -> str:
    return rng.choice("WAFxyz") * rng.choice([150, 201, 1000, 20_000])


def mutate_spec(text: str, rng: random.Random) -> str:
    """A spec with hostile values put in place of some of its values, keys or names."""
    kind = rng.randrange(5)
    if kind == 0:
        return mutate(text, rng, edits=3)
    pieces = text.split(": ")
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(1, len(pieces))
        head, sep, rest = pieces[i].partition("\n")
        if kind == 1:
            value = rng.choice(SPEC_VALUES)
        elif kind == 2:
            value = _long_name(rng)
        else:
            number = rng.choice(["1.0e+21", "1001", "10001", "-1.0e+21", "1e-320", "2e9"])
            value = number if head.strip().replace(".", "", 1).isdigit() else head
        # keep a flow mapping's closing braces, so more of the spec still parses
        closing = head[len(head.rstrip("}],")) :] if kind > 1 else ""
        pieces[i] = value + closing + sep + rest
    text = ": ".join(pieces)
    if kind == 4:  # an alias bomb or deep nesting at the end
        if rng.random() < 0.5:
            text += "bomb: &a0 [x, x, x, x, x, x, x, x, x, x]\n"
            for level in range(1, rng.randint(2, 8)):
                text += f"bomb{level}: &a{level} [" + ", ".join([f"*a{level - 1}"] * 10) + "]\n"
        else:
            text += "deep: " + "[" * rng.randint(60, 300) + "\n"
    return text


def spec_case(seed: int, workdir: Path) -> list[str]:
    """A mutated example spec, validated (or solved, one case in four)."""
    rng = random.Random(seed)
    source = EXAMPLES[seed % len(EXAMPLES)].read_text()
    spec = workdir / "spec.yaml"
    spec.write_text(mutate_spec(source, rng), errors="surrogatepass")
    if seed % 4 == 0:
        return ["solve", str(spec), "-o", str(workdir / "out"), "-f", "json,svg,glb"]
    return ["validate", str(spec)]


# what a careless or hostile program puts where a glTF value belongs
GLTF_VALUES: list[Any] = [
    None,
    -1,
    0,
    1,
    2**31,
    2**64,
    1e308,
    -1e308,
    float("nan"),
    "x",
    "",
    [],
    {},
    True,
    [0, 0, 0],
    [-1],
    [10**9],
    {"uri": "/dev/zero"},
    "/dev/zero",
    "../../../../etc/passwd",
    "data:application/octet-stream;base64,AAAA",
]


def _places(node: Any) -> list[tuple[Any, Any]]:
    found: list[tuple[Any, Any]] = []
    if isinstance(node, dict):
        items: Any = node.items()
    elif isinstance(node, list):
        items = enumerate(node)
    else:
        return found
    for key, value in list(items):
        found.append((node, key))
        found.extend(_places(value))
    return found


def _node_graph(rng: random.Random) -> tuple[list[dict[str, Any]], list[int]]:
    """Nodes with random children: trees, shared subtrees, cycles, long chains, many."""
    count = rng.choice([1, 2, 5, 30, 100, 600, 2100])
    nodes: list[dict[str, Any]] = [{} for _ in range(count)]
    shape = rng.randrange(4)
    for i, node in enumerate(nodes):
        if rng.random() < 0.5:
            node["mesh"] = 0
        if shape == 0 and i + 1 < count:  # a chain
            node["children"] = [i + 1]
        elif shape == 1 and i:  # a random tree
            nodes[rng.randrange(i)].setdefault("children", []).append(i)
        elif shape == 2:  # any edges: shared subtrees and cycles
            node["children"] = [rng.randrange(count) for _ in range(rng.randint(0, 2))]
        if rng.random() < 0.2:
            node["translation"] = [rng.choice([0, 1e308, -1e308, 1e21]), 0, 0]
    roots = [0] if shape in (0, 1) else rng.sample(range(count), min(count, 3))
    return nodes, roots


def mutate_glb(rng: random.Random) -> bytes:
    """A glb with its JSON header, binary chunk, node graph or framing damaged."""
    triangles = rng.choice([1, 3, 50])
    document, binary = mesh_document(triangles, [{"mesh": 0}])
    kind = rng.randrange(5)
    if kind == 0:  # values of the header
        for _ in range(rng.randint(1, 3)):
            parent, key = rng.choice(_places(document))
            parent[key] = json.loads(json.dumps(rng.choice(GLTF_VALUES)))
    elif kind == 1:  # the node graph
        nodes, roots = _node_graph(rng)
        document["nodes"] = nodes
        document["scenes"] = [{"nodes": roots}]
    elif kind == 2:  # the binary chunk: cut, grown, NaN positions
        choice = rng.randrange(3)
        if choice == 0:
            binary = binary[: rng.randrange(len(binary))]
        elif choice == 1:
            binary = binary[:-36] + struct.pack("<9f", *[float("nan")] * 9)
        else:
            binary += bytes(rng.randrange(1, 4096))
    elif kind == 3:  # a buffer elsewhere
        document["buffers"][0]["uri"] = rng.choice(
            ["/dev/zero", "../outside.bin", "data:,", "http://example.com/x.bin", "x.bin"]
        )
    data = glb(document, binary)
    if kind == 4:  # the framing: magic, lengths, chunk types, or bytes cut off
        at = rng.randrange(min(len(data), 28))
        data = data[:at] + bytes([rng.randrange(256)]) + data[at + 1 :]
        if rng.random() < 0.3:
            data = data[: rng.randrange(len(data))]
    return data


def asset_case(seed: int, workdir: Path) -> list[str]:
    """A spec naming a damaged glb, validated (or solved, one case in three)."""
    rng = random.Random(seed)
    (workdir / "thing.glb").write_bytes(mutate_glb(rng))
    spec = workdir / "assets.yaml"
    spec.write_text(ASSET_SPEC.format(mesh="thing.glb"))
    if seed % 3 == 0:
        return ["solve", str(spec), "-o", str(workdir / "out"), "-f", "json,glb"]
    return ["validate", str(spec)]


LAYOUT_NUMBERS = [
    "nan",
    "NaN",
    "Infinity",
    "-Infinity",
    "1e308",
    "-1e308",
    "1e-320",
    "-0",
    "0",
    "1" * 400,
    "0." + "0" * 400 + "1",
    "2",
    "-1",
    "0.5",
]


def _small_layout(rng: random.Random) -> list[tuple[float, float, float, float]]:
    if rng.random() < 0.3:
        return staggered_rects(rng.randint(1, 30))
    rects = []
    for row in range(rng.randint(1, 4)):
        for column in range(rng.randint(1, 4)):
            x, y = 1 + 3 * column, 1 + 3 * row
            rects.append((x, y, x + 1.2, y + 1.5))
    return rects


def cmp_case(seed: int, workdir: Path) -> list[str]:
    """A CMP annotation, its text or its numbers damaged, through ``facade grammar``."""
    rng = random.Random(seed)
    text = layout_cmp(_small_layout(rng))
    kind = rng.randrange(4)
    if kind == 0:
        text = mutate(text, rng, edits=3)
    elif kind == 1:
        numbers = re.findall(r"<([xy])>([^<]*)</\1>", text)
        for _ in range(rng.randint(1, 3)):
            old = rng.choice(numbers)[1]
            text = text.replace(f">{old}<", f">{rng.choice(LAYOUT_NUMBERS)}<", 1)
    elif kind == 2:
        hostile = [
            '<!DOCTYPE x [<!ENTITY a "aaaaaaaaaa">]>',
            "<object>" * rng.randint(50, 3000),
            "<labelname>" + "w" * rng.choice([101, 5000]) + "</labelname>",
            "<labelname>\x01</labelname>",
            "\ufeff",
            "<?xml version='1.0' encoding='latin-1'?>",
            "]]>",
            "&#0;",
        ]
        at = rng.randrange(len(text) + 1)
        text = text[:at] + rng.choice(hostile) + text[at:]
    else:
        text = text * rng.randint(2, 40)
    layout = workdir / "layout.xml"
    layout.write_text(text, errors="surrogatepass")
    return _grammar_argv(layout, workdir, rng)


def layout_case(seed: int, workdir: Path) -> list[str]:
    """A JSON layout (a list, or rectangles with a canvas), damaged, through ``grammar``."""
    rng = random.Random(seed)
    rects = _small_layout(rng)
    if rng.random() < 0.5:
        text = layout_json(rects)
    else:
        width, height = max(r[2] for r in rects) + 1, max(r[3] for r in rects) + 1
        entries = json.loads(layout_json(rects))
        text = json.dumps({"canvas": {"width": width, "height": height}, "rects": entries})
    kind = rng.randrange(4)
    if kind == 0:
        text = mutate(text, rng, edits=3)
    elif kind == 1:
        text = mutate_json(text, rng, edits=3)
    elif kind == 2:
        numbers = re.findall(r"(?<=: )-?[0-9][0-9.e+-]*", text)
        for _ in range(rng.randint(1, 3)):
            text = text.replace(rng.choice(numbers), rng.choice(LAYOUT_NUMBERS), 1)
    else:
        depth = rng.choice([10, 70, 5000])
        text = rng.choice(["[" * depth + "]" * depth, '{"rects": ' + text + ', "rects": []}'])
    layout = workdir / "layout.json"
    layout.write_text(text, errors="surrogatepass")
    return _grammar_argv(layout, workdir, rng)


def _grammar_argv(layout: Path, workdir: Path, rng: random.Random) -> list[str]:
    argv = ["grammar", str(layout), "-o", str(workdir / "out"), "-n", "20"]
    return argv + rng.choice([[], ["--method", "greedy"], ["--snap", "0"], ["--size", "20x15"]])


DOORS = {"spec": spec_case, "asset": asset_case, "cmp-xml": cmp_case, "json-layout": layout_case}

# -- judging one case ------------------------------------------------------------------------

EXPECTED_OUTPUTS = {"grammar": 5}


def judge(argv: list[str], code: int, stderr: str, workdir: Path) -> str | None:
    """What is wrong with how ``facade argv`` ended, or None: an exit code other than 0, 2
    or 3, a traceback or internal error, a staging folder or temporary file left, files
    written on failure, or files missing on success."""
    if code not in (0, 2, 3):
        return f"exit {code}"
    if "Traceback" in stderr or "internal error" in stderr:
        return "internal error"
    out = workdir / "out"
    written = sorted(p.name for p in out.iterdir()) if out.exists() else []
    leftovers = [name for name in written if name.startswith(".") or name.endswith(".tmp")]
    if leftovers:
        return f"left {leftovers}"
    if code != 0 and written:
        return f"exit {code} but wrote {written}"
    if code == 0 and "-o" in argv:
        expected = EXPECTED_OUTPUTS.get(argv[0])
        if expected is None:  # solve: one file a format
            expected = len(argv[argv.index("-f") + 1].split(","))
        if len(written) != expected:
            return f"wrote {written}, expected {expected} files"
    return None


def run_case(
    door: str, seed: int, root: Path, timeout: float, memory: int, fork: bool = True
) -> tuple[int | None, str | None]:
    """Run one case in a process of its own, in a fresh folder: its exit code (None when
    it did not end in time) and what went wrong, or None.
    The folder is kept when something did. ``fork``: the process is forked from this one,
    with facadecli already imported (some ten times faster); else a new interpreter."""
    import shutil

    workdir = root / f"{door}-{seed}"
    workdir.mkdir(parents=True)
    argv = DOORS[door](seed, workdir)
    code, stderr = (_forked if fork else _executed)(argv, workdir, timeout, memory)
    problem = f"no end within {timeout:g} s" if code is None else judge(argv, code, stderr, workdir)
    if problem is None:
        shutil.rmtree(workdir, ignore_errors=True)
    else:
        (workdir / "argv.txt").write_text(" ".join(argv) + "\n")
        (workdir / "stderr.txt").write_text(stderr)
    return code, problem


def _bound(memory: int) -> None:
    """A memory bomb fails the case instead of the machine."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))


def _executed(
    argv: list[str], workdir: Path, timeout: float, memory: int
) -> tuple[int | None, str]:
    import subprocess
    import sys

    try:
        done = subprocess.run(
            [sys.executable, "-m", "facadecli", *argv],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=timeout,
            preexec_fn=lambda: _bound(memory),
            cwd=workdir,
        )
    except subprocess.TimeoutExpired:
        return None, ""
    return done.returncode, done.stderr


def _forked(argv: list[str], workdir: Path, timeout: float, memory: int) -> tuple[int | None, str]:
    import os
    import signal
    import sys
    import time

    from facadecli.cli import main as facade_main

    log = workdir / "stderr.log"
    pid = os.fork()
    if pid == 0:  # the case: its own process, output to the log, exit with the code
        code = 1
        try:
            fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(fd, 1)
            os.dup2(fd, 2)
            os.chdir(workdir)
            _bound(memory)
            sys.argv = ["facade", *argv]
            facade_main()
            code = 0
        except SystemExit as stop:
            code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
        except BaseException:
            import traceback

            traceback.print_exc()
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
    deadline = time.monotonic() + timeout
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return None, log.read_text(errors="replace") if log.exists() else ""
        time.sleep(0.01)
    stderr = log.read_text(errors="replace")
    log.unlink()
    return os.waitstatus_to_exitcode(status), stderr


def main() -> None:
    """``python -m tests.fuzz.spec_doors [--cases N] [--doors a,b] [--workers W]``: N cases
    per door as subprocesses, judged by ``judge``; prints the tally per door and keeps the
    folders of failed cases."""
    import argparse
    import tempfile
    import time
    from collections import Counter
    from concurrent.futures import ThreadPoolExecutor
    from functools import partial

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("--cases", type=int, default=1000)
    parser.add_argument("--doors", default=",".join(DOORS))
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--memory", type=int, default=3 << 30, help="bytes of address space")
    parser.add_argument("--exec", action="store_true", help="a new interpreter a case")
    options = parser.parse_args()
    if not options.exec:  # imported once, before the forks
        import importlib

        for module in (
            "facadecli.cli",
            "facadecli.grammar.extract",
            "facadecli.spec.load",
            "trimesh",
        ):
            importlib.import_module(module)
    root = Path(tempfile.mkdtemp(prefix="facade-fuzz-"))
    failed = 0
    for door in options.doors.split(","):
        started = time.perf_counter()
        seeds = range(options.first_seed, options.first_seed + options.cases)
        with ThreadPoolExecutor(options.workers) as pool:
            case = partial(
                run_case, door, root=root, timeout=options.timeout, memory=options.memory
            )
            results = list(pool.map(case, seeds))
        problems = [problem for _, problem in results]
        tally = Counter("ok" if p is None else p.split(" ")[0] for p in problems)
        codes = Counter(f"exit {code}" if code is not None else "hang" for code, _ in results)
        bad = [(seed, p) for seed, p in zip(seeds, problems, strict=True) if p is not None]
        failed += len(bad)
        seconds = time.perf_counter() - started
        print(
            f"{door}: {options.cases} cases in {seconds:.0f} s: {dict(tally)}, "
            f"{dict(sorted(codes.items()))}",
            flush=True,
        )
        for seed, problem in bad[:20]:
            print(f"  seed {seed}: {problem} ({root / f'{door}-{seed}'})", flush=True)
    print(f"{failed} failed; kept in {root}" if failed else "no failure")
    raise SystemExit(1 if failed else 0)


if __name__ == "__main__":
    main()
