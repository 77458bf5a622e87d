"""``facade view``: one self-contained HTML page of every model in an output folder (of
``facade solve``, ``vary`` or ``city``): a list of the models, each with its elevation as a
thumbnail, beside the shared three.js viewer; a click shows that model and its elevation.

The models are the folder's top-level ``*.glb`` files (a city's ``buildings/<shard>/*.glb``
only when there are none), each with the ``.svg`` of the same stem when there is one, in
natural order (``8x3`` before ``12x3``). What the page inlines is capped at
:data:`~facadecli.limits.GALLERY_BYTES_MAX`; the same folder gives the same bytes.

A page is made to be sent to others, so it inlines only regular files inside the folder
(a link to another file of the folder is fine, a link out of it is not: ``shadow.svg ->
/etc/shadow`` never reaches a page) that are what their names say (glTF binary, SVG with
no DTD); every file left out is listed with why."""

from __future__ import annotations

import base64
import errno
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from html import escape
from pathlib import Path
from urllib.parse import unquote

from facadecli.errors import OutputError, Problem, SpecError
from facadecli.export.atomic import atomic_output, check_output_file
from facadecli.export.texture_store import embedded
from facadecli.files import NotRegularFile, read_regular_at_most
from facadecli.limits import GALLERY_BYTES_MAX
from facadecli.viewer import document_parts, glb_element
from facadecli.viewer.kinds import kind_problem

PAGE_NAME = "index.html"
BUILDINGS = "buildings"  # where ``facade city`` writes one glb per building
GROUND = ".ground.geojson"  # a city's land cover, beside its merged glb
LAID_GROUND = ".ground.glb"  # a city's ground (--ground), beside its merged glb, in it too
HINT = (
    "run 'facade solve SPEC -o FOLDER' first, or facade vary or facade city: "
    "they write the .glb models this page shows"
)
SKIP_HINT = "a page shows only glTF (.glb) and SVG files that are inside the folder"


@dataclass(frozen=True)
class Model:
    """One model of a folder: its glb and the SVG elevation of the same stem, if any."""

    name: str
    glb: Path
    svg: Path | None
    ground: Path | None = None  # a city's land cover, <name>.ground.geojson


@dataclass(frozen=True)
class Loaded:
    """A model's bytes, read."""

    model: Model
    glb: bytes
    svg: bytes | None
    ground: bytes | None = None


def natural_key(name: str) -> tuple[tuple[str | int, ...], str]:
    """Sorts numbers by value: ``house-8x3-0`` before ``house-12x3-0``; ties by the name."""
    parts = re.split(r"(\d+)", name)
    return tuple(int(part) if i % 2 else part for i, part in enumerate(parts)), name


def _glbs(folder: Path, pattern: str = "*.glb") -> list[Path]:
    found = [
        path
        for path in folder.glob(pattern)
        if not path.name.startswith(".")  # not a run's temporary file
    ]
    return sorted(found, key=lambda path: natural_key(path.name))


def _buildings(folder: Path) -> list[Path]:
    """A city's buildings: ``buildings/<shard>/*.glb`` (and ``buildings/*.glb``, where
    runs before the shards wrote them), by name whatever their shard."""
    if not folder.is_dir():
        return []
    found = _glbs(folder) + _glbs(folder, "[0-9a-f][0-9a-f]/*.glb")
    return sorted(found, key=lambda path: natural_key(path.name))


def _laid_ground(glb: Path) -> bool:
    """Whether ``glb`` is a city's ground (``<name>.ground.glb``, ``facade city --ground``)
    beside its merged model ``<name>.glb``, which holds it: not a model of its own."""
    name = glb.name.removesuffix(LAID_GROUND)
    return name != glb.name and os.path.lexists(glb.with_name(f"{name}.glb"))


def find_models(folder: Path) -> list[Model]:
    """The models of ``folder``, in order; a SpecError (exit 2) when there are none or the
    folder cannot be read. Every ``*.glb`` name is listed here, whatever it names:
    :func:`read_models` skips those that are not glTF files inside the folder."""
    where = str(folder)
    if not folder.exists():
        raise SpecError.at(where, None, None, "no such folder", HINT)
    if not folder.is_dir():
        raise SpecError.at(
            where, None, None, "is a file, not a folder", "give the folder the models are in"
        )
    try:
        glbs = [glb for glb in _glbs(folder) if not _laid_ground(glb)]
        glbs = glbs or _buildings(folder / BUILDINGS)
    except OSError as error:
        raise SpecError.at(
            where, None, None, f"cannot read: {error.strerror}", "check its permissions"
        ) from None
    if not glbs:
        raise SpecError.at(where, None, None, "no models (.glb files) in this folder", HINT)
    models = []
    for glb in glbs:
        svg = glb.with_suffix(".svg")
        ground = glb.with_suffix(GROUND)
        models.append(
            Model(
                glb.stem,
                glb,
                svg if os.path.lexists(svg) else None,
                ground if os.path.lexists(ground) else None,
            )
        )
    return models


@dataclass(frozen=True)
class Skipped:
    """A file the page leaves out, and why."""

    path: Path
    reason: str


class _Skip(Exception):
    pass


def _inside(path: Path, root: Path) -> Path:
    """The file ``path`` names, when it is a regular file inside ``root`` (a link to one is
    fine: a link between two files of the folder shows nothing new); _Skip otherwise."""
    try:
        target = path.resolve(strict=True)
    except (OSError, RuntimeError):  # a link to nothing, a loop of links
        raise _Skip("a link to nothing" if path.is_symlink() else "cannot be read") from None
    if not target.is_relative_to(root):
        raise _Skip(f"a link to {target}, outside the folder")
    if not target.is_file():
        raise _Skip("not a regular file (a folder, a device or a pipe)")
    return target


def read_models(
    models: list[Model], folder: Path, limit: int | None = None
) -> tuple[list[Loaded], list[Skipped]]:
    """Every model's bytes, never more than ``limit`` (:data:`GALLERY_BYTES_MAX`) in all:
    past it, a SpecError naming the limit, having read at most one byte more. Only regular
    files inside ``folder`` are read, and only what is of its name's kind
    (:mod:`facadecli.viewer.kinds`) is kept: a model whose glb is not is skipped, one whose
    svg is not is shown without its elevation; each is listed in the second list."""
    cap = GALLERY_BYTES_MAX if limit is None else limit
    root = folder.resolve()
    used = 0
    loaded: list[Loaded] = []
    skipped: list[Skipped] = []

    def read(path: Path) -> bytes:
        nonlocal used
        target = _inside(path, root)
        try:  # the file checked, not a link put in its place since
            data, _ = read_regular_at_most(target, cap - used, follow_links=False)
        except NotRegularFile:
            raise _Skip("not a regular file (a folder, a device or a pipe)") from None
        except OSError as error:
            if error.errno == errno.ELOOP:
                raise _Skip("replaced by a link while read") from None
            raise SpecError.at(
                str(path), None, None, f"cannot read: {error.strerror}", "check its permissions"
            ) from None
        if data is None:
            raise SpecError.at(
                str(folder),
                None,
                None,
                f"the models and elevations hold more than {cap:,} bytes, the most one "
                "page inlines (GALLERY_BYTES_MAX)",
                "view a folder with fewer models (move some out), or open the .glb files "
                "one at a time",
            )
        problem = kind_problem(path.suffix, data)
        if problem is not None:
            raise _Skip(problem)
        used += len(data)
        return data

    def picture(model: Model, uri: str) -> bytes:
        try:
            return read(model.glb.parent / unquote(uri))
        except _Skip as skip:
            raise _Skip(f"its texture picture {unquote(uri)}: {skip}") from None

    def optional(path: Path | None) -> bytes | None:
        """A file beside a model's glb (its SVG, its ground), if it has one and it reads;
        one that does not is skipped, the model kept."""
        if path is None:
            return None
        try:
            return read(path)
        except _Skip as skip:
            skipped.append(Skipped(path, str(skip)))
            return None

    for model in models:
        try:  # a city's glb names the pictures of its run's textures/: the page holds them
            glb = embedded(read(model.glb), partial(picture, model))
        except _Skip as skip:
            skipped.append(Skipped(model.glb, str(skip)))
            continue
        loaded.append(Loaded(model, glb, optional(model.svg), optional(model.ground)))
    return loaded, skipped


STYLE = (
    "#list{flex:none;width:220px;overflow:auto;padding:8px;box-sizing:border-box;"
    "background:#fff;border-right:1px solid #ccc}"
    "#count{margin:0 0 8px;font-size:12px;color:#555}"
    "#list button{display:block;width:100%;margin:0 0 6px;padding:4px;text-align:left;"
    "font:inherit;font-size:12px;background:#f8f8f8;border:2px solid transparent;"
    "cursor:pointer}"
    "#list button[aria-pressed=true]{border-color:#2a6fdb;background:#e8f0fd}"
    "#list img{display:block;width:100%;height:auto;max-height:120px;object-fit:contain;"
    "margin-bottom:3px}"
    "#list span{overflow-wrap:anywhere}"
)

# the page's own code: a click (or the arrow keys) shows an entry's model and elevation;
# the address ends #NAME of the model shown, and a page opened at #NAME shows that model
SCRIPT = """
const entries = [...document.querySelectorAll('#list button')];
const heading = document.getElementById('name');
const elevation = document.getElementById('elevation');
function pick(entry) {
  for (const other of entries) other.setAttribute('aria-pressed', String(other === entry));
  heading.textContent = entry.dataset.name;
  const thumbnail = entry.querySelector('img');
  elevation.replaceChildren();
  if (thumbnail) {
    const image = new Image();
    image.src = thumbnail.src;
    image.alt = 'front elevation of ' + entry.dataset.name;
    elevation.append(image);
  } else elevation.textContent = 'no elevation (.svg) beside this model';
  show(entry.dataset.glb);
  history.replaceState(null, '', '#' + encodeURIComponent(entry.dataset.name));
}
for (const entry of entries) entry.addEventListener('click', () => pick(entry));
document.addEventListener('keydown', event => {
  const step = {ArrowDown: 1, ArrowUp: -1}[event.key];
  if (!step) return;
  const now = entries.findIndex(entry => entry.getAttribute('aria-pressed') === 'true');
  const next = entries[Math.min(Math.max(now + step, 0), entries.length - 1)];
  event.preventDefault();
  if (next === entries[now]) return;
  pick(next); next.focus(); next.scrollIntoView({block: 'nearest'});
});
const wanted = decodeURIComponent(location.hash.slice(1));
pick(entries.find(entry => entry.dataset.name === wanted) || entries[0]);
"""


def _entry(index: int, loaded: Loaded) -> str:
    name = escape(loaded.model.name)
    thumbnail = ""
    if loaded.svg is not None:
        data = base64.b64encode(loaded.svg).decode()
        thumbnail = f'<img src="data:image/svg+xml;base64,{data}" alt="">'
    return (
        f'<button type="button" data-glb="glb-{index}" data-name="{name}" '
        f'aria-pressed="false" title="{name}">{thumbnail}<span>{name}</span></button>'
    )


def gallery_parts(title: str, models: list[Loaded], note: str = "") -> Iterator[str]:
    """The gallery page, piece by piece (one model's base64 at a time)."""
    count = f"{len(models)} model{'s' if len(models) != 1 else ''}{note}"

    def body() -> Iterator[str]:
        yield f'<nav id="list"><p id="count">{escape(count)}</p>'
        yield from (_entry(index, loaded) for index, loaded in enumerate(models))
        yield (
            '</nav><div id="model"></div><div id="side"><h3 id="name"></h3>'
            '<p id="status">loading the model</p><div id="elevation"></div></div>'
        )
        for index, loaded in enumerate(models):
            yield glb_element(f"glb-{index}", loaded.glb)
            if loaded.ground is not None:  # drawn by show() (facadecli.viewer.landcover)
                yield glb_element(f"glb-{index}-ground", loaded.ground)

    return document_parts(title, STYLE, body(), SCRIPT)


@dataclass(frozen=True)
class Written:
    """What ``facade view`` wrote: the page, the models it shows and the files it left out."""

    page: Path
    models: list[Model]
    skipped: list[Skipped]


def write_gallery(folder: Path, page: Path | None = None) -> Written:
    """``facade view``: the gallery of ``folder``'s models, written atomically to ``page``
    (default ``FOLDER/index.html``). A SpecError when no model is left to show."""
    target = folder / PAGE_NAME if page is None else page
    models = find_models(folder)
    check_output_file(target)
    loaded, skipped = read_models(models, folder)
    if not loaded:
        where = str(models[0].glb.parent)
        raise SpecError(
            [Problem(where, None, None, "no model to show: every .glb file here is left out")]
            + [
                Problem(str(file.path), None, None, f"left out: {file.reason}", SKIP_HINT)
                for file in skipped
            ]
        )
    title = folder.resolve().name or str(folder)
    note = f" in {BUILDINGS}/" if models[0].glb.parent != folder else ""
    try:
        with atomic_output(target) as handle:
            for part in gallery_parts(title, loaded, note):
                handle.write(part.encode("utf-8"))
    except OSError as error:
        raise OutputError(f"{target}: cannot write the page: {error.strerror}") from None
    return Written(target, [item.model for item in loaded], skipped)
