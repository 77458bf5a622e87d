"""The documentation holds: its links lead somewhere, the README's commands run, the site builds.

- every relative link and image of README.md and docs/**/*.md points to a file that exists
  (and, for a link into a Markdown page with ``#anchor``, to one of its headings);
- the ``facade ...`` commands of the README's shell blocks exit 0, run from the repository's
  root with their outputs (``out/...``) moved into a temporary folder; solve and validate
  each on its own, always; the others (vary, view, city), in order, under
  ``@pytest.mark.slow``;
- every ``facade`` command of the tutorials and how-to guides runs as written, in order,
  with the files the guide asks the reader to create (slow);
- ``mkdocs build --strict`` succeeds, where mkdocs is installed (the ``docs`` extra);
- the shipped samples (samples/) go through grammar, infer and city.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PAGES = sorted((ROOT / "docs").rglob("*.md"))
FAST = {"solve", "validate"}  # commands quick enough for every run of the suite

FENCE = re.compile(r"^(```|~~~)")
LINK = re.compile(r"!?\[[^\]]*\]\(([^()\s]+)(?:\s+\"[^\"]*\")?\)")
INLINE_CODE = re.compile(r"`[^`]*`")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")


def prose_lines(text: str) -> list[str]:
    """The lines of a Markdown text outside fenced code blocks, inline code removed."""
    lines, fenced = [], False
    for line in text.splitlines():
        if FENCE.match(line.strip()):
            fenced = not fenced
            continue
        if not fenced:
            lines.append(INLINE_CODE.sub("", line))
    return lines


def slug(heading: str) -> str:
    """The anchor MkDocs (Python-Markdown's toc) gives a heading."""
    text = re.sub(r"[`*_\[\]()]", "", heading).strip().lower()
    text = re.sub(r"[^\w\s-]", "", text)
    return re.sub(r"[\s-]+", "-", text).strip("-")


def anchors(page: Path) -> set[str]:
    return {
        slug(m.group(1)) for line in prose_lines(page.read_text()) if (m := HEADING.match(line))
    }


def relative_links(page: Path) -> list[str]:
    targets = []
    for line in prose_lines(page.read_text()):
        for target in LINK.findall(line):
            if not re.match(r"^[a-z][a-z0-9+.-]*:", target) and not target.startswith("#"):
                targets.append(target)
    return targets


@pytest.mark.parametrize("page", [README, *PAGES], ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_point_to_files(page: Path) -> None:
    broken = []
    for target in relative_links(page):
        path, _, anchor = target.partition("#")
        resolved = (page.parent / path).resolve()
        if not resolved.exists():
            broken.append(f"{target}: no file {os.path.relpath(resolved, ROOT)}")
        elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
            broken.append(f"{target}: no heading '#{anchor}' in {resolved.name}")
    assert not broken, f"{page.relative_to(ROOT)}: " + "; ".join(broken)


def test_docs_pages_are_linked_from_the_site() -> None:
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [str(p.relative_to(ROOT / "docs")) for p in PAGES]
    missing = [p for p in missing if p not in nav]
    assert not missing, f"pages missing from mkdocs.yml's nav: {missing}"


def test_readme_is_a_short_door() -> None:
    lines = README.read_text().splitlines()
    assert len(lines) < 150, f"README.md has {len(lines)} lines: move reference text to docs/"


def readme_commands() -> list[str]:
    """The lines of the README's shell blocks that run facade, in order."""
    commands, block = [], None
    for line in README.read_text().splitlines():
        fence = FENCE.match(line.strip())
        if fence:
            block = line.strip()[3:].strip() if block is None else None
            continue
        if block in ("sh", "bash", "shell", "console") and line.startswith("facade "):
            commands.append(line.split(" #")[0].strip())
    return commands


COMMANDS = readme_commands()


def test_readme_has_a_tour() -> None:
    verbs = {shlex.split(c)[1] for c in COMMANDS}
    assert {"validate", "solve", "vary", "city"} <= verbs, verbs


FACADE_ENV = {
    **os.environ,
    "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
}
SHARED = ("samples/", "specs/")  # the repository's inputs, the same for every page
OUTPUT = ("-o", "--output")


def shared_key(words: list[str], cwd: Path) -> tuple[str, ...] | None:
    """``facade WORDS`` run in ``cwd`` as a key its outputs can be shared under: the words
    with the output's replaced by ``-o``'s marker, when the command reads only the
    repository's samples/ and specs/ (every word naming a file or folder in ``cwd``
    starts with one of them) and writes one ``-o`` target not there yet. None for any
    other command (one reading what a guide created or wrote before, or writing into an
    earlier run's folder, which ``facade city`` would resume)."""
    targets = [k + 1 for k, word in enumerate(words[:-1]) if word in OUTPUT]
    if len(targets) != 1 or (cwd / words[targets[0]]).exists():
        return None
    read = [w for k, w in enumerate(words) if k != targets[0] and not w.startswith("-")]
    if any((cwd / w).exists() and not w.startswith(SHARED) for w in read):
        return None
    return tuple("<output>" if k == targets[0] else w for k, w in enumerate(words))


class SharedRuns:
    """``facade`` commands run in a fresh process each, the outputs of those that read only
    the repository's samples and specs kept (in ``store``): the README and the guides run
    the same ``facade city samples/...`` commands (6-8 CPU-s each), so a command seen
    before gets the files its first run wrote, and answers with its first run's exit code
    and output. A folder target is copied whole (under any name); a file target with the
    files its run wrote beside it (``facade infer``'s report), under the same name. Same
    command, same inputs, same bytes (the project's rule; ``facade city`` into another
    folder writes the same files, the report's timings aside), so each page is still
    checked in order, step by step."""

    def __init__(self, store: Path) -> None:
        self.store = store
        self.runs: dict[tuple[str, ...], tuple[subprocess.CompletedProcess[str], str, Path]] = {}

    def run(self, words: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
        """``facade WORDS`` run in ``cwd`` (or its first run's outputs copied)."""
        key = shared_key(words, cwd)
        if key is None:
            return self._run(words, cwd)
        output = words[key.index("<output>")]
        target = cwd / output
        if key in self.runs:
            first, said_as, kept = self.runs[key]
            whole = kept.name == "folder"
            if whole or target.name == Path(said_as).name:
                if whole:
                    _copy(kept, target)
                else:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    for made in kept.iterdir():
                        _copy(made, target.parent / made.name)
                said, err = (t.replace(said_as, output) for t in (first.stdout, first.stderr))
                return subprocess.CompletedProcess(words, first.returncode, said, err)
        there = {p.name for p in target.parent.iterdir()} if target.parent.is_dir() else set()
        done = self._run(words, cwd)
        if done.returncode != 0 or not target.exists():
            return done
        kept = self.store / str(len(self.runs)) / ("folder" if target.is_dir() else "beside")
        if target.is_dir():
            _copy(target, kept)
        else:  # the file and what its run wrote beside it
            kept.mkdir(parents=True)
            for made in target.parent.iterdir():
                if made.name not in there:
                    _copy(made, kept / made.name)
        self.runs[key] = (done, output, kept)
        return done

    @staticmethod
    def _run(words: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "facadecli", *words],
            cwd=cwd,
            env=FACADE_ENV,
            capture_output=True,
            text=True,
            timeout=600,
        )


def _copy(made: Path, to: Path) -> None:
    """A file or a folder copied to ``to``."""
    if made.is_dir():
        shutil.copytree(made, to)
    else:
        shutil.copy2(made, to)


@pytest.fixture(scope="module")
def facade_runs(tmp_path_factory: pytest.TempPathFactory) -> SharedRuns:
    """The module's commands, the outputs of the shared ones kept (:class:`SharedRuns`)."""
    return SharedRuns(tmp_path_factory.mktemp("shared-runs"))


def test_a_command_run_before_copies_its_first_runs_outputs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A command of the repository's specs run again into another folder gets the files of
    its first run, its exit code and its output (the folder's name changed), and starts
    no process; one reading a file of the guide's or writing into an existing folder is
    never shared."""
    for name in ("specs", "samples"):
        (tmp_path / name).symlink_to(ROOT / name)
    (tmp_path / "store").mkdir()
    runs = SharedRuns(tmp_path / "store")
    solve = ["solve", "specs/townhouse.yaml", "-f", "svg,json", "-o"]
    first = runs.run([*solve, "out/first"], tmp_path)
    assert first.returncode == 0, first.stderr
    assert "out/first/townhouse.svg" in first.stdout
    infer = ["infer", "samples/five-bays.xml", "--size", "15x12", "-o"]
    assert runs.run([*infer, "a/five-bays.yaml"], tmp_path).returncode == 0

    def no_process(*args: object, **kwargs: object) -> None:
        raise AssertionError("a command run again started a process")

    monkeypatch.setattr(subprocess, "run", no_process)
    again = runs.run([*solve, "again"], tmp_path)
    assert again.returncode == 0 and again.stdout == first.stdout.replace("out/first", "again")
    written = sorted(p.name for p in (tmp_path / "out" / "first").iterdir())
    assert written == sorted(p.name for p in (tmp_path / "again").iterdir())
    assert written and all(
        (tmp_path / "again" / name).read_bytes() == (tmp_path / "out/first" / name).read_bytes()
        for name in written
    )
    # a file target: the files its run wrote beside it too (infer's report), same name
    assert runs.run([*infer, "b/five-bays.yaml"], tmp_path).returncode == 0
    beside = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert beside == sorted(p.name for p in (tmp_path / "b").iterdir()) and len(beside) == 2
    (tmp_path / "house.yaml").write_text("")
    assert shared_key(["solve", "house.yaml", "-o", "mine"], tmp_path) is None
    assert shared_key([*solve, "again"], tmp_path) is None  # there: a city would resume
    assert shared_key(["city", "specs/x.yaml", "-o", "a", "-o", "b"], tmp_path) is None
    assert shared_key([*solve, "new"], tmp_path) == (*solve, "<output>")


def run_facade(command: str, out: Path, runs: SharedRuns) -> subprocess.CompletedProcess[str]:
    """Run a README command from the root, its out/... paths moved into ``out``."""
    words = [re.sub(r"^out(?=/|$)", str(out), w) for w in shlex.split(command)]
    assert words[0] == "facade"
    return runs.run(words[1:], ROOT)


@pytest.mark.parametrize("command", [c for c in COMMANDS if shlex.split(c)[1] in FAST])
def test_readme_fast_commands_run(command: str, tmp_path: Path, facade_runs: SharedRuns) -> None:
    done = run_facade(command, tmp_path / "out", facade_runs)
    assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"


@pytest.mark.slow
def test_readme_commands_run_in_order(tmp_path: Path, facade_runs: SharedRuns) -> None:
    """The README's other commands, in order: `facade view out/vary` needs the vary before
    it. Its solves and validate each run in a test of their own above, and no command after
    them reads what they write."""
    for command in (c for c in COMMANDS if shlex.split(c)[1] not in FAST):
        done = run_facade(command, tmp_path / "out", facade_runs)
        assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"
    assert (tmp_path / "out" / "vary" / "index.html").is_file()
    assert (tmp_path / "out" / "town" / "town.glb").is_file()


@pytest.mark.slow
def test_samples_run(tmp_path: Path, facade_runs: SharedRuns) -> None:
    for command in (
        "facade grammar samples/five-bays.xml --size 15x12 -o out/grammar",
        "facade grammar samples/five-bays.json -o out/grammar-json --derive 21x12 -f svg",
        "facade infer samples/five-bays.xml --size 15x12 -o out/infer/five-bays.yaml",
        "facade city samples/town.yaml -o out/town -j 1",
    ):
        done = run_facade(command, tmp_path / "out", facade_runs)
        assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"
    assert (tmp_path / "out" / "grammar" / "five-bays.grammar.txt").is_file()
    assert (tmp_path / "out" / "infer" / "five-bays.yaml").is_file()
    assert "4 of 4 buildings built" in done.stdout


@pytest.mark.skipif(
    importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("material") is None,
    reason="mkdocs and mkdocs-material are not installed: pip install '.[docs]' (make docs does)",
)
def test_site_builds_strictly(tmp_path: Path) -> None:
    config, site = str(ROOT / "mkdocs.yml"), str(tmp_path / "site")
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "-f", config, "-d", site],
        cwd=ROOT,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "reference" / "spec" / "index.html").is_file()


# -- the commands of the tutorials, how-to guides, CLI reference and home page -------------
GUIDES = sorted(
    [
        *(ROOT / "docs/tutorials").glob("*.md"),
        *(ROOT / "docs/how-to").glob("*.md"),
        ROOT / "docs/reference/cli.md",
        ROOT / "docs/index.md",
    ]
)
# commands a guide shows that cannot run here: a server that runs until stopped, a cluster,
# a manifest of the reader's own (the guide says so), a change to the reader's shell
NOT_HERE = re.compile(r"\bwatch\b|--scheduler|district\.yaml|/shared/|--install-completion")
CREATE = re.compile(r"[Cc]reate `([^`/]+)`")


def guide_steps(page: Path) -> list[tuple[str, str]]:
    """A guide's steps in order: ("file", NAME + "\\n" + text) for a fenced block right after
    "Create `NAME`", ("run", command) for each ``facade`` line of its shell blocks."""
    steps: list[tuple[str, str]] = []
    lines = page.read_text().splitlines()
    creating, block, kind = None, [], None
    for line in lines:
        if kind is None:
            fence = re.match(r"^```(\w*)", line)
            if fence:
                kind, block = fence.group(1) or "text", []
                continue
            found = CREATE.search(line)
            if found:
                creating = found.group(1)
            elif line.strip():
                creating = None if not line.startswith("Create") else creating
            continue
        if line.startswith("```"):
            if creating is not None and kind not in ("sh", "bash", "shell", "console"):
                steps.append(("file", creating + "\n" + "\n".join(block) + "\n"))
            if kind in ("sh", "bash", "shell"):
                for command in block:
                    command = command.split("&&")[0].strip()
                    if command.startswith("facade ") and not NOT_HERE.search(command):
                        steps.append(("run", " ".join(shlex.split(command, comments=True))))
            creating, kind = None, None
            continue
        block.append(line)
    return steps


@pytest.mark.slow
@pytest.mark.parametrize("page", GUIDES, ids=lambda p: str(p.relative_to(ROOT)))
def test_guides_commands_run_in_order(page: Path, tmp_path: Path, facade_runs: SharedRuns) -> None:
    """Every ``facade`` command of a guide (or the CLI reference, or the home page) runs
    as written, in order, in a folder holding the repository's specs/ and samples/ and
    the files the page asks the reader to create."""
    for name in ("specs", "samples"):
        (tmp_path / name).symlink_to(ROOT / name)
    for kind, text in guide_steps(page):
        if kind == "file":
            name, _, body = text.partition("\n")
            (tmp_path / name).write_text(body)
            continue
        words = []  # the shell's globbing, as a reader's shell does it
        for word in shlex.split(text)[1:]:
            matched = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.glob(word))
            words += matched if "*" in word and matched else [word]
        done = facade_runs.run(words, tmp_path)
        assert done.returncode == 0, f"{page.name}: {text}\n{done.stdout}\n{done.stderr}"
