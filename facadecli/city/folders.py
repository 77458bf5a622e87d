"""Where ``facade city`` puts a building's files: ``buildings/<shard>/<name>.glb``.

A city of 100,000 buildings must not put 100,000 files (300,000 with their CityJSON
features and USD stages) in one folder: listing, globbing and deleting such a folder is
slow on every file system, and some tools give up. So the buildings' files are spread
over :data:`SHARDS` sub-folders of ``buildings/``, named by the first two hexadecimal
digits of a hash of the building's id: the same folder on every run and machine,
whatever the other buildings, the run's size or its ``--limit`` (so ``--resume`` finds
them), about 400 buildings a folder at 100,000, 4,000 at a million. Small runs use the
same rule (one rule, so a script finds a building of any run the same way); the report's
``file`` gives each building's path, and the merged ``<name>.glb`` stays the one file
to open for a small run.

A building's file name is its id when the id is short, lower-case and plain, else a
readable prefix and a hash (:func:`safe_name`).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path, PurePosixPath

BUILDINGS = "buildings"  # the folder of the buildings' files, in the output folder
SHARD_DIGITS = 2  # hexadecimal digits of a shard's name
SHARDS = 16**SHARD_DIGITS  # sub-folders of buildings/, at most
SHARD = re.compile(rf"[0-9a-f]{{{SHARD_DIGITS}}}")  # a shard folder's name
PLAIN_NAME = re.compile(r"[a-z0-9][a-z0-9._-]{0,119}")  # ids used as file names as they are
READABLE = 100  # characters of any other id kept, made safe, in front of its hash


def id_digest(building_id: str) -> str:
    """The SHA-256 of a building's id (or a file name), in hex: its hashed names' part."""
    return hashlib.sha256(building_id.encode("utf-8", "surrogatepass")).hexdigest()


def safe_name(building_id: str) -> str:
    """A file name for an id, never the same for two ids, on case-insensitive file systems
    too. A short, lower-case, plain id is its own name; any other id (OSM ids hold '/')
    gives its first READABLE characters with unsafe ones replaced, then '~' and a hash of
    the whole id. No plain name holds '~', so the two kinds never meet."""
    if PLAIN_NAME.fullmatch(building_id):
        return building_id
    readable = re.sub(r"[^A-Za-z0-9._-]", "_", building_id[:READABLE]).strip("._") or "building"
    return f"{readable}~{id_digest(building_id)[:16]}"


def shard(building_id: str) -> str:
    """The sub-folder of ``buildings/`` a building's files go in: a hash of its id."""
    return id_digest(building_id)[:SHARD_DIGITS]


def building_file(building_id: str, suffix: str = ".glb") -> PurePosixPath:
    """A building's file, relative to the output folder: ``buildings/<shard>/<name><suffix>``
    (the report's ``file``; ``.city.jsonl`` and ``.usda`` sit beside the ``.glb``)."""
    return PurePosixPath(BUILDINGS, shard(building_id), safe_name(building_id) + suffix)


def run_folder(glb: Path) -> Path:
    """The output folder of a run, from a building's glb in it (:func:`building_file`)."""
    return glb.parents[2]
