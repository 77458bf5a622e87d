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


def run_facade(command: str, out: Path) -> subprocess.CompletedProcess[str]:
    """Run a README command from the root, its out/... paths moved into ``out``."""
    words = [re.sub(r"^out(?=/|$)", str(out), w) for w in shlex.split(command)]
    assert words[0] == "facade"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
    }
    return subprocess.run(
        [sys.executable, "-m", "facadecli", *words[1:]],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.mark.parametrize("command", [c for c in COMMANDS if shlex.split(c)[1] in FAST])
def test_readme_fast_commands_run(command: str, tmp_path: Path) -> None:
    done = run_facade(command, tmp_path / "out")
    assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"


@pytest.mark.slow
def test_readme_commands_run_in_order(tmp_path: Path) -> None:
    """The README's other commands, in order: `facade view out/vary` needs the vary before
    it. Its solves and validate each run in a test of their own above, and no command after
    them reads what they write."""
    for command in (c for c in COMMANDS if shlex.split(c)[1] not in FAST):
        done = run_facade(command, tmp_path / "out")
        assert done.returncode == 0, f"{command}\n{done.stdout}\n{done.stderr}"
    assert (tmp_path / "out" / "vary" / "index.html").is_file()
    assert (tmp_path / "out" / "town" / "town.glb").is_file()


@pytest.mark.slow
def test_samples_run(tmp_path: Path) -> None:
    for command in (
        "facade grammar samples/five-bays.xml --size 15x12 -o out/grammar",
        "facade grammar samples/five-bays.json -o out/grammar-json --derive 21x12 -f svg",
        "facade infer samples/five-bays.xml --size 15x12 -o out/infer/five-bays.yaml",
        "facade city samples/town.yaml -o out/town -j 1",
    ):
        done = run_facade(command, tmp_path / "out")
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
def test_guides_commands_run_in_order(page: Path, tmp_path: Path) -> None:
    """Every ``facade`` command of a guide (or the CLI reference, or the home page) runs
    as written, in order, in a folder holding the repository's specs/ and samples/ and
    the files the page asks the reader to create."""
    for name in ("specs", "samples"):
        (tmp_path / name).symlink_to(ROOT / name)
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])),
    }
    for kind, text in guide_steps(page):
        if kind == "file":
            name, _, body = text.partition("\n")
            (tmp_path / name).write_text(body)
            continue
        words = []  # the shell's globbing, as a reader's shell does it
        for word in shlex.split(text)[1:]:
            matched = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.glob(word))
            words += matched if "*" in word and matched else [word]
        done = subprocess.run(
            [sys.executable, "-m", "facadecli", *words],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert done.returncode == 0, f"{page.name}: {text}\n{done.stdout}\n{done.stderr}"
