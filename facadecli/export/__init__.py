"""Writers: the only modules that write files, one per format, behind a registry."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

from facadecli.export.atomic import (
    atomic_output,
    check_output_file,
    check_output_folder,
    staged,
    write_atomic,
)

if TYPE_CHECKING:  # trimesh takes half a second to import: only the mesh writers need it
    import trimesh

    from facadecli.city.built import BuiltCity
    from facadecli.layout import Layout


@dataclass(frozen=True)
class OutputOptions:
    timings: bool = False  # record solve times in the report (they vary run to run)
    labels: bool = False  # symbol names and column lines over the SVG elevation
    base_dir: Path | None = None  # where the spec is: mesh asset paths are relative to it


Writer = Callable[["Layout", Path, OutputOptions], list[Path]]


def _write_json(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.report import report_text

    path = outdir / f"{layout.spec.name}.layout.json"
    write_atomic(path, report_text(layout, timings=options.timings))
    return [path]


def _write_svg(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.svg import svg_text

    path = outdir / f"{layout.spec.name}.svg"
    write_atomic(path, svg_text(layout, labels=options.labels))
    return [path]


_last_scene: list[tuple[Layout, Path | None, trimesh.Scene]] = []  # the latest scene built


def _scene(layout: Layout, options: OutputOptions) -> trimesh.Scene:
    """The layout's scene, built once for all the mesh formats of one layout."""
    from facadecli.geometry.facade import facade_scene

    for built, base_dir, scene in _last_scene:
        if built is layout and base_dir == options.base_dir:
            return scene
    scene = facade_scene(layout, options.base_dir)
    _last_scene[:] = [(layout, options.base_dir, scene)]
    return scene


def _write_glb(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.gltf import write_glb
    from facadecli.geometry.facade import material_extensions

    path = outdir / f"{layout.spec.name}.glb"
    return write_glb(_scene(layout, options), path, material_extensions(layout.spec))


def _write_gltf(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.gltf import write_gltf
    from facadecli.geometry.facade import material_extensions

    path = outdir / f"{layout.spec.name}.gltf"
    return write_gltf(_scene(layout, options), path, material_extensions(layout.spec))


def _write_obj(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.obj import write_obj

    return write_obj(_scene(layout, options), outdir / f"{layout.spec.name}.obj")


def _write_usd(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.usd import write_usd

    return write_usd(_scene(layout, options), outdir / f"{layout.spec.name}.usda")


def _write_html(layout: Layout, outdir: Path, options: OutputOptions) -> list[Path]:
    from facadecli.export.gltf import glb_bytes
    from facadecli.export.svg import svg_text
    from facadecli.geometry.facade import material_extensions
    from facadecli.viewer import page

    path = outdir / f"{layout.spec.name}.html"
    glb = glb_bytes(_scene(layout, options), material_extensions(layout.spec))
    write_atomic(path, page(layout.spec.name, glb, svg_text(layout, labels=options.labels)))
    return [path]


#: format name -> writer(layout, outdir, options) returning the files it wrote; the
#: default set of ``facade solve`` is SPEC 4's: glb, obj, json, svg
WRITERS: dict[str, Writer] = {
    "glb": _write_glb,
    "obj": _write_obj,
    "json": _write_json,
    "svg": _write_svg,
    "gltf": _write_gltf,
    "html": _write_html,
    "usd": _write_usd,
}
DEFAULT_FORMATS = ("glb", "obj", "json", "svg")
#: the formats that are one file, which can go to a stream (``facade solve -o -``)
SINGLE_FILE_FORMATS = ("json", "svg", "glb", "html", "usd")


@dataclass(frozen=True)
class CityWriter:
    """A writer of a whole city's output, once its buildings have ended: ``write`` returns
    what the report's ``models`` says of it; ``what`` names the output in messages."""

    what: str
    write: Callable[[BuiltCity], dict[str, Any]]


def _write_city_models(built: BuiltCity) -> dict[str, Any]:
    from facadecli.city.tiles import merge_city

    streamed = built.tileset is not None  # 3D Tiles: no square tiles unless asked for
    ground = _write_city_ground_model(built)
    written = merge_city(
        built.placed,
        built.outdir,
        built.name,
        built.tile_size,
        built.georef,
        streamed,
        built.merged_lod,
        built.instanced,
        built.outdir / ground["file"] if ground else None,
    )
    return {**written, "ground_model": ground} if ground else written


def _write_city_ground_model(built: BuiltCity) -> dict[str, Any]:
    """With ``--ground``, the district's ground (city/ground.py) as ``<name>.ground.glb``:
    its file and triangles a kind, for the report; without, none (one an earlier run
    left is removed)."""
    from facadecli.city.ground import write_ground_glb

    path = _ground_model(built)
    parts = [part for task in built.ok() for part in task.footprint.parts]
    if not (built.ground and parts):
        path.unlink(missing_ok=True)
        return {}
    store = next((task.pictures for task in built.ok()), None)
    triangles = write_ground_glb(path, parts, built.found.ground, store)
    return {"file": path.name, "triangles": triangles}


def _write_city_3dtiles(built: BuiltCity) -> dict[str, Any]:
    if built.tileset is None:
        raise ValueError("a city without --3dtiles has no tileset to write")
    ground = _ground_model(built)  # written by the models' writer, before this one
    laid = ground if built.ground and ground.is_file() else None
    return {"3dtiles": built.tileset.close(built.name, laid)}


def _ground_model(built: BuiltCity) -> Path:
    """Where the district's ground goes (``--ground``): ``<name>.ground.glb``."""
    return built.outdir / f"{built.name}.ground.glb"


def _write_city_usd(built: BuiltCity) -> dict[str, Any]:
    from facadecli.export.usd import city_usda_lines

    stage = built.outdir / f"{built.name}.usda"
    with atomic_output(stage) as out:
        buildings = (task.target for task in built.ok())
        for line in city_usda_lines(built.name, buildings, built.outdir):
            out.write(line.encode("utf-8"))
    return {"usd": stage.name}


def _write_cityjson(built: BuiltCity) -> dict[str, Any]:
    from facadecli.city.cityjson import CityJSONWriter

    path = built.outdir / f"{built.name}.city.json"
    with CityJSONWriter(path, built.found.crs, built.found.origin, built.name) as writer:
        for feature in built.features():
            writer.add(feature)
    return {}


def _write_city_ground(built: BuiltCity) -> dict[str, Any]:
    """The district's land cover, ``<name>.ground.geojson`` (city/landcover.py), when its
    input maps any; else no such file (one an earlier run left is removed)."""
    from facadecli.city.landcover import ordered, write_ground

    path = built.outdir / f"{built.name}.ground.geojson"
    found = built.found
    if not found.ground:
        path.unlink(missing_ok=True)
        return {}
    write_ground(path, ordered(found.ground), found.crs, found.origin, found.unit)
    return {"ground": path.name}


#: format name -> the writer of a city's output of that format (``facade city``), each
#: reading the buildings' own files again in the manifest's order, never all at once:
#: ``glb`` the merged model or its square tiles and ``<name>.georef.json``, ``3dtiles``
#: the tileset (with ``--3dtiles``), ``usd`` the city's stage (with ``--usd``),
#: ``cityjson`` the CityJSON, ``ground`` the land cover (``<name>.ground.geojson``)
CITY_WRITERS: dict[str, CityWriter] = {
    "glb": CityWriter("merged model", _write_city_models),
    "3dtiles": CityWriter("3D Tiles", _write_city_3dtiles),
    "usd": CityWriter("USD stage", _write_city_usd),
    "cityjson": CityWriter("CityJSON", _write_cityjson),
    "ground": CityWriter("land cover", _write_city_ground),
}


def write_outputs(
    layout: Layout, outdir: Path, formats: list[str], options: OutputOptions
) -> list[Path]:
    """Write a layout in every format into ``outdir``: all the files or none."""
    written: list[Path] = []
    with staged(outdir) as stage:
        for name in formats:
            written.extend(outdir / path.name for path in WRITERS[name](layout, stage, options))
    return written


def write_stream(layout: Layout, name: str, options: OutputOptions, stream: BinaryIO) -> None:
    """Write a layout in one of ``SINGLE_FILE_FORMATS`` to a binary stream (standard
    output): the writer writes into a temporary folder, and its one file is copied."""
    if name not in SINGLE_FILE_FORMATS:
        raise ValueError(f"{name} is not one file: use one of {', '.join(SINGLE_FILE_FORMATS)}")
    with tempfile.TemporaryDirectory(prefix="facade-") as folder:
        path, *pictures = WRITERS[name](layout, Path(folder), options)
        if pictures:  # a USD stage with its library materials' pictures beside it
            from facadecli.errors import SpecError

            raise SpecError.at(
                layout.spec.name,
                None,
                None,
                f"the {name} output of this spec is {1 + len(pictures)} files: the model and "
                "the texture pictures of its library materials",
                "write it to a folder (-o DIR), or use glb, which embeds the pictures",
            )
        stream.write(path.read_bytes())


__all__ = [
    "CITY_WRITERS",
    "DEFAULT_FORMATS",
    "SINGLE_FILE_FORMATS",
    "WRITERS",
    "CityWriter",
    "OutputOptions",
    "check_output_file",
    "check_output_folder",
    "staged",
    "write_atomic",
    "write_outputs",
    "write_stream",
]
