"""``facade city --resume``: which buildings of the last run into a folder may be kept.

A building's outputs are decided by its task (:class:`facadecli.city.run.Task`: its
footprint and tags after inheritance, heights, roof, colours, party walls, the parts
standing on it, its façade rules...), by the bytes of the spec files it uses and of
the files they name (meshes, textures), and by this version of facadecli. Its *hash*
(:func:`building_hash`, the one place it is computed) digests all of them and is
written in its report entry. On ``--resume`` a building is kept only when its outputs
exist and the hash the last run recorded for it (:func:`recorded`) is the one it has
now; its report entry is then kept whole, figures and all. Any other building is built
again: an edited spec rebuilds the buildings that use it, an edited footprint or tag
the buildings it changes (its neighbours too when their party walls move).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import shapely
from pydantic import BaseModel
from shapely.geometry.base import BaseGeometry

from facadecli import __version__
from facadecli.city.packed import Positional
from facadecli.export.texture_store import pictures_missing

if TYPE_CHECKING:
    from facadecli.city.manifest import City
    from facadecli.city.run import Task

HASH = "hash"  # a building's report entry: the hash of what decided its outputs
DIGEST = hashlib.sha256().digest_size  # bytes of a hash

# A task's fields the hash leaves out, and why: paths where this run happens to be (the
# spec's and the output's folders; the files' bytes and the output's name are hashed
# instead), and what is hashed through another field.
UNHASHED = {
    "target": "its name is hashed, not the folder the run writes in",
    "spec_dir": "the spec's bytes and the files it names are hashed",
    "spec": "the bytes of its file are hashed (spec_key names it)",
    "cache_key": "a worker's cache key: the spec's absolute path and content",
    "walls": "its rules are hashed, and the bytes of their specs",
    "fallback": "the bytes of its spec are hashed",
    "level": "hashed below 3 only: a run with façades keeps the hashes it had",
}
NAMED = ("texture", "mesh")  # a spec's fields that may name a file beside it


def canonical(value: Any) -> Any:
    """``value`` as plain JSON data, the same for equal values on every run: geometry as
    its WKB (exact coordinates), dataclasses and models as their fields."""
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, BaseGeometry):
        return shapely.to_wkb(value, hex=True)
    if isinstance(value, BaseModel):
        return value.model_dump(mode="json")
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: canonical(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(key): canonical(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [canonical(item) for item in value]
    raise TypeError(f"no canonical form for {type(value).__name__}")


def _named(data: Any) -> Iterator[str]:
    """The file names a spec's fields hold (:data:`NAMED`), anywhere in it."""
    if isinstance(data, dict):
        for key, item in data.items():
            if key in NAMED and isinstance(item, str):
                yield item
            else:
                yield from _named(item)
    elif isinstance(data, list):
        for item in data:
            yield from _named(item)


def spec_digests(city: City) -> Callable[[str], str]:
    """A spec's digest by the path the manifest gives: its file's bytes and those of the
    files it names, each read once a run."""
    found: dict[str, str] = {}

    def digest(path: str) -> str:
        if path not in found:
            file = (city.folder / path).resolve()
            spec = city.specs[path]
            sha = hashlib.sha256()
            try:
                sha.update(file.read_bytes())
            except OSError:  # gone since it was loaded: its content as loaded
                sha.update(spec.model_dump_json().encode("utf-8"))
            for name in sorted(set(_named(spec.model_dump(mode="json")))):
                named = file.parent / name
                if named.is_file():  # else a built-in mesh's name
                    sha.update(b"\0" + name.encode("utf-8") + b"\0" + named.read_bytes())
            found[path] = sha.hexdigest()
        return found[path]

    return digest


def building_hash(task: Task, spec_digest: Callable[[str], str]) -> str:
    """The hash of everything that decides a building's outputs (the module's docstring)."""
    hashed: dict[str, Any] = {"version": __version__}
    for field in dataclasses.fields(task):
        if field.name not in UNHASHED:
            hashed[field.name] = canonical(getattr(task, field.name))
    hashed["file"] = task.target.name
    hashed["spec_file"] = spec_digest(task.spec_key)
    hashed["walls"] = [[canonical(rule), spec_digest(rule.facade)] for rule, _ in task.walls]
    if task.fallback is not None:  # absent before: a run without one keeps its hashes
        hashed["fallback"] = spec_digest(task.fallback[0])
    if task.level < 3:  # a coarser building's files are another building's
        hashed["level"] = task.level
    text = json.dumps(hashed, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


class Hashes(Positional[str]):
    """The buildings' hashes (:func:`building_hash`) by their position in the manifest's
    order, kept as their 32 bytes in one buffer: 32 bytes a building in memory, where a
    dict of hex strings by id takes 195, in small objects that stay for the whole run
    (and keep the memory around them from being given back, :mod:`.heap`)."""

    def __init__(self) -> None:
        self._digests = bytearray()

    def append(self, digest: str) -> None:
        self._digests += bytes.fromhex(digest)

    def __len__(self) -> int:
        return len(self._digests) // DIGEST

    def _at(self, index: int) -> str:
        return self._digests[index * DIGEST : (index + 1) * DIGEST].hex()


def building_hashes(city: City, tasks: Iterable[Task]) -> Hashes:
    """Every task's :func:`building_hash`, in the tasks' order."""
    digest = spec_digests(city)
    hashes = Hashes()
    for task in tasks:
        hashes.append(building_hash(task, digest))
    return hashes


def recorded(outdir: Path, name: str) -> dict[str, bytes]:
    """The report entries of the buildings the last run into ``outdir`` built, with their
    hashes, by id, each as its JSON line (a few hundred bytes, where a parsed entry takes
    kilobytes: a city of 100,000 is resumed in little memory): from
    ``<name>.report.jsonl`` (a line a building as it ended, so a killed run's too; a line
    cut short is skipped), or, without it, the report."""
    log = outdir / f"{name}.report.jsonl"
    found: dict[str, bytes] = {}

    def keep(entry: Any) -> None:
        if (
            isinstance(entry, dict)
            and entry.get("status") == "ok"
            and isinstance(entry.get("id"), str)
            and isinstance(entry.get(HASH), str)
        ):
            found[entry["id"]] = json.dumps(entry).encode("utf-8")

    try:
        with open(log, encoding="utf-8", errors="replace") as lines:
            for line in lines:
                try:
                    keep(json.loads(line))
                except ValueError:
                    continue
    except FileNotFoundError:
        try:
            report = json.loads((outdir / f"{name}.report.json").read_bytes())
        except (OSError, ValueError):
            return {}
        entries = report.get("buildings") if isinstance(report, dict) else None
        for entry in entries if isinstance(entries, list) else []:
            keep(entry)
    return found


def reusable(
    task: Task, digest: str, previous: dict[str, bytes], usd: bool
) -> dict[str, Any] | None:
    """The last run's report entry of a building, marked ``resumed``, when it may be kept:
    its outputs exist and its hash is the one it has now; else None (build it)."""
    line = previous.get(task.footprint.id)
    if line is None:
        return None
    entry: dict[str, Any] = json.loads(line)
    if entry[HASH] != digest:
        return None
    if entry.get("file") != task.file or not task.target.is_file():
        return None
    if usd and not task.target.with_suffix(".usda").is_file():
        return None
    if task.shared_textures and pictures_missing(task.target):  # textures/ emptied since
        return None
    return {**entry, "resumed": True}


def stamped(
    results: Iterable[tuple[int, dict[str, Any]]], hashes: Sequence[str]
) -> Iterator[tuple[int, dict[str, Any]]]:
    """Report entries as they come, each at its building's position, with its building's
    hash (``hashes`` at that position)."""
    for position, result in results:
        yield position, {**result, HASH: hashes[position]}
