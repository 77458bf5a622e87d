"""The example specs and samples that ship with facadecli, and ``facade examples DIR``.

One copy of them lives in git, at the repository's root (``specs/``, ``samples/``: the
docs and tests run them from there). A built wheel carries them as package data in
``facadecli/_examples/``, copied there by setup.py's ``build_py`` step; a source checkout
(an editable install) has no such folder and uses the root's.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from facadecli.errors import FacadeError, SpecError

FOLDERS = ("specs", "samples")  # what ``facade examples`` copies, as laid out in the repo


def examples_folder() -> Path:
    """The folder holding ``specs/`` and ``samples/``: the installed copy, else the
    repository's root of a source checkout."""
    here = Path(__file__).resolve().parent
    for folder in (here / "_examples", here.parent):
        if all((folder / name).is_dir() for name in FOLDERS):
            return folder
    raise FacadeError(
        "the example specs are not installed with facadecli: reinstall it from a wheel or "
        "from the repository (pip install facadecli)"
    )


def example_spec(name: str) -> Path:
    """The path of a shipped example spec, e.g. ``townhouse``."""
    return examples_folder() / "specs" / f"{name}.yaml"


def example_files() -> list[Path]:
    """Every shipped file, relative to :func:`examples_folder`, in order."""
    root = examples_folder()
    return sorted(
        path.relative_to(root)
        for name in FOLDERS
        for path in (root / name).rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    )


def copy_examples(target: Path, option: str = "DIR") -> list[Path]:
    """Copy the example specs and samples into ``target`` (made if missing), keeping
    their layout (the samples' manifest names ``../specs/...``); returns the files
    written. Nothing is overwritten: a file already there is a SpecError (exit 2), before
    anything is copied."""
    root = examples_folder()
    files = example_files()
    if target.exists() and not target.is_dir():
        raise SpecError.at(option, None, None, f"'{target}' is not a folder", "give a folder")
    there = [target / file for file in files if (target / file).exists()]
    if there:
        more = f" and {len(there) - 1} more" if len(there) > 1 else ""
        raise SpecError.at(
            option,
            None,
            None,
            f"'{there[0]}'{more} already exist",
            "choose a new folder, or remove the files to copy them again",
        )
    written = []
    for file in files:
        (target / file).parent.mkdir(parents=True, exist_ok=True)
        written.append(Path(shutil.copy2(root / file, target / file)))
    return written
