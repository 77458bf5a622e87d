"""The ``facade`` command: the only module that talks to the terminal.

Exit codes (SPEC section 4): 0 success, 1 some specs failed in a multi-spec run,
2 invalid input, 3 no layout exists, 4 the search stopped (work budget or safety time
limit) before it found a layout. No traceback reaches a user unless ``--debug``.
"""

from __future__ import annotations

import json
import math
import sys
import time
import traceback
import warnings
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import replace
from importlib.machinery import EXTENSION_SUFFIXES
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, NoReturn

import typer

from facadecli import __version__
from facadecli.errors import (
    FacadeError,
    FacadeWarning,
    InfeasibleError,
    SearchLimitError,
    SpecError,
)
from facadecli.export import (
    DEFAULT_FORMATS,
    SINGLE_FILE_FORMATS,
    WRITERS,
    OutputOptions,
    check_output_file,
    check_output_folder,
    staged,
    write_atomic,
    write_outputs,
    write_stream,
)
from facadecli.limits import CANVAS_MAX, SPEC_BYTES_MAX

if TYPE_CHECKING:  # the commands import the stages they use: start-up stays fast
    from facadecli.solver.axis import AxisLayout
    from facadecli.spec import Spec

app = typer.Typer(
    name="facade",
    help="Turn declarative YAML façade specs into layered, aligned building façades.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

# the global options of this run: set by the options, read by the printing functions
_state = {"debug": False, "quiet": False, "verbose": False}
STDIN = "-"  # a spec path or --output that means standard input or output
STDIN_NAME = "<stdin>"  # how errors name a spec read from standard input

SpecPaths = Annotated[
    list[Path],
    typer.Argument(
        help="Spec files (YAML); - reads one from standard input.",
        metavar="SPEC",
        show_default=False,
    ),
]


def _version(value: bool) -> None:
    if value:
        typer.echo(f"facade {__version__}")
        missing = _not_built()
        if missing:  # pip hides the build's own note
            searches = ", ".join(missing)
            typer.echo(f"pure-Python searches ({searches}): slower; no C compiler at install")
        raise typer.Exit(0)


def _not_built() -> list[str]:
    """The compiled searches this install lacks, from its files (``facadecli.native``
    would import them, and the solver with them)."""
    here = Path(__file__).parent
    return [
        what
        for what, stem in (("grammar", "grammar/adp"), ("alignment", "solver/network"))
        if not any((here / f"{stem}{suffix}").exists() for suffix in EXTENSION_SUFFIXES)
    ]


GLOBAL_FLAGS = {  # accepted before and after the command: main() moves them before it
    "quiet": (("-q", "--quiet"), "Errors only: no warnings, progress or summaries."),
    "verbose": (("-v", "--verbose"), "More detail on standard error (stage times, items)."),
    "debug": (("--debug",), "Show tracebacks of internal errors."),
}
EPILOG = "The global options -q, -v and --debug may come before or after the command."


@app.callback(epilog=EPILOG)
def _main(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version."),
    ] = False,
    quiet: Annotated[bool, typer.Option("-q", "--quiet", help=GLOBAL_FLAGS["quiet"][1])] = False,
    verbose: Annotated[
        bool, typer.Option("-v", "--verbose", help=GLOBAL_FLAGS["verbose"][1])
    ] = False,
    debug: Annotated[bool, typer.Option("--debug", help=GLOBAL_FLAGS["debug"][1])] = False,
) -> None:
    if quiet and verbose:
        raise typer.BadParameter("give -q/--quiet or -v/--verbose, not both", param_hint="-q")
    _state.update(quiet=quiet, verbose=verbose, debug=debug)


def _hoisted(args: list[str]) -> list[str]:
    """The command line with the global flags moved before the command, wherever they were
    given (up to a ``--``), so that ``facade solve x.yaml -q`` is ``facade -q solve
    x.yaml``."""
    names = {name for flags, _ in GLOBAL_FLAGS.values() for name in flags}
    flags: list[str] = []
    rest: list[str] = []
    for index, arg in enumerate(args):
        if arg == "--":
            rest += args[index:]
            break
        (flags if arg in names else rest).append(arg)
    return flags + rest


def _say(text: str) -> None:
    """A result line (what was written): standard output, unless --quiet."""
    if not _state["quiet"]:
        typer.echo(text)


def _warn(text: str) -> None:
    """A warning or a progress line: standard error, unless --quiet."""
    if not _state["quiet"]:
        typer.echo(text, err=True)


def _detail(text: str) -> None:
    """More detail: standard error, with --verbose only."""
    if _state["verbose"]:
        typer.echo(text, err=True)


def _report(error: FacadeError) -> None:
    typer.echo(str(error), err=True)


def _load(path: Path) -> Spec:
    """A spec from its file, or from standard input for ``-`` (named ``<stdin>`` in
    errors; the files it names are relative to the current folder)."""
    from facadecli.spec import load_spec, parse_spec

    if str(path) != STDIN:
        return load_spec(path)
    raw = sys.stdin.buffer.read(SPEC_BYTES_MAX + 1)
    if len(raw) > SPEC_BYTES_MAX:
        raise SpecError.at(
            STDIN_NAME,
            None,
            None,
            f"the input is longer than specs are limited to ({SPEC_BYTES_MAX:,} bytes)",
            "a spec is a page of YAML: generate repeated layers with patterns",
        )
    return parse_spec(raw, STDIN_NAME, base_dir=Path.cwd())


def _shown(path: Path) -> str:
    """How messages name a spec path: ``<stdin>`` for ``-``."""
    return STDIN_NAME if str(path) == STDIN else str(path)


def _check_stdin(paths: list[Path]) -> None:
    if sum(str(path) == STDIN for path in paths) > 1:
        raise typer.BadParameter("standard input (-) can be read once", param_hint="SPEC")


class _Run:
    """A multi-spec run: reports each failure, then exits with one code (SPEC 4): the
    spec's own code when there is one spec, 1 when some of several failed."""

    def __init__(self, paths: list[Path]):
        _check_stdin(paths)
        self.paths = paths
        self.codes: list[int] = []

    def specs(self) -> Iterator[tuple[Path, Spec]]:
        for path in self.paths:
            try:
                spec = _load(path)
            except SpecError as error:
                self.fail(path, error)
                continue
            yield path, spec

    def fail(self, path: Path, error: FacadeError) -> None:
        if isinstance(error, InfeasibleError):
            typer.echo(f"{_shown(path)}: error: no layout: {error}", err=True)
        elif isinstance(error, SearchLimitError):
            typer.echo(f"{_shown(path)}: error: search stopped: {error}", err=True)
        else:
            _report(error)
        self.codes.append(error.exit_code)

    def succeed(self) -> None:
        self.codes.append(0)

    def finish(self) -> None:
        failed = [code for code in self.codes if code]
        if failed:
            raise typer.Exit(failed[0] if len(self.paths) == 1 else 1)


@app.command(epilog=EPILOG)
def validate(specs: SpecPaths) -> None:
    """Check specs without solving them; print every problem with file:line:col."""
    run = _Run(specs)
    for path, spec in run.specs():
        _say(f"{_shown(path)}: ok ({spec.name}: {len(spec.layers)} layers)")
        run.succeed()
    failed = sum(1 for code in run.codes if code)
    if failed:
        typer.echo(f"{failed} of {len(specs)} specs invalid", err=True)
        raise typer.Exit(2)


def _formats(value: str | None) -> list[str]:
    if value is None:
        return list(DEFAULT_FORMATS)
    names = [name.strip() for name in value.split(",") if name.strip()]
    unknown = [name for name in names if name not in WRITERS]
    if unknown or not names:
        raise typer.BadParameter(
            f"unknown format {', '.join(unknown) or '(none)'}; available: {', '.join(WRITERS)}"
        )
    return names


@app.command("solve", epilog=EPILOG)
def solve_command(
    specs: SpecPaths,
    outdir: Annotated[
        Path,
        typer.Option(
            "--output",
            "-o",
            help="Folder for the outputs; - writes the one file of one spec and one "
            f"format ({','.join(SINGLE_FILE_FORMATS)}) to standard output.",
        ),
    ] = Path("out"),
    formats: Annotated[
        str | None,
        typer.Option(
            "--format",
            "-f",
            help=f"Comma-separated, of {','.join(WRITERS)} (default: {','.join(DEFAULT_FORMATS)}).",
        ),
    ] = None,
    width: Annotated[
        float | None, typer.Option("--width", min=0.001, help="Override the canvas width (m).")
    ] = None,
    height: Annotated[
        float | None, typer.Option("--height", min=0.001, help="Override the canvas height (m).")
    ] = None,
    seed: Annotated[int | None, typer.Option("--seed", min=0, help="Override solver.seed.")] = None,
    timings: Annotated[
        bool, typer.Option("--timings", help="Record solve times in the report (not reproducible).")
    ] = False,
    labels: Annotated[
        bool, typer.Option("--labels", help="Symbol names and column lines over the SVG.")
    ] = False,
) -> None:
    """Solve specs into layouts and write their outputs to OUTDIR."""
    from facadecli.solve import retarget, solve

    chosen = _formats(formats)
    width = _length(width, "--width")
    height = _length(height, "--height")
    to_stdout = str(outdir) == STDIN
    if to_stdout:
        _check_stdout(specs, chosen)
    else:
        check_output_folder(outdir)
    run = _Run(specs)
    for path, spec in run.specs():
        try:
            layout = solve(retarget(spec, width, height, seed))
        except (InfeasibleError, SearchLimitError) as error:
            run.fail(path, error)
            continue
        for warning in layout.warnings:
            _warn(f"{_shown(path)}: warning: {warning}")
        for axis in (layout.x, layout.y):
            _detail(f"{_shown(path)}: {_axis_detail(axis)}")
        options = OutputOptions(timings, labels, path.parent)
        counters = ", ".join(f"{k}={v}" for k, v in sorted(layout.counters.items()))
        solved = f"{_shown(path)}: solved in {layout.time_ms:.1f} ms" + (
            f" ({counters})" if counters else ""
        )
        if to_stdout:
            write_stream(layout, chosen[0], options, sys.stdout.buffer)
            sys.stdout.buffer.flush()
            _warn(f"{solved} -> standard output")  # standard output holds the file
        else:
            written = write_outputs(layout, outdir, chosen, options)
            _say(f"{solved} -> " + ", ".join(str(p) for p in written))
        run.succeed()
    run.finish()


def _check_stdout(specs: list[Path], formats: list[str]) -> None:
    if len(specs) != 1 or len(formats) != 1 or formats[0] not in SINGLE_FILE_FORMATS:
        raise typer.BadParameter(
            "- (standard output) takes one spec and one format that is one file: "
            f"-f {' or -f '.join(SINGLE_FILE_FORMATS)}",
            param_hint="--output",
        )


def _axis_detail(axis: AxisLayout) -> str:
    """One line on how an axis was solved: the objective and its proof, the time of each
    stage, the words chosen (long ones cut)."""
    proof = "proven" if axis.proven else f"unproven, bound {axis.bound:.6g} m2"
    stages = ", ".join(
        f"{stage.removesuffix('_ms')} {ms:.1f} ms" for stage, ms in axis.timings.items()
    )
    words = "; ".join(
        f"{key}: {word if len(word) <= 60 else word[:57] + '...'}"
        for key, word in sorted(axis.words.items())
    )
    return f"{axis.axis} axis: objective {axis.objective:.6g} m2 ({proof}); {stages}; {words}"


def _length(value: float | None, option: str) -> float | None:
    """A canvas length given on the command line: finite, positive, within the limit."""
    if value is not None and not (math.isfinite(value) and 0 < value <= CANVAS_MAX):
        raise typer.BadParameter(
            f"{value:g} is not a canvas length: give metres above 0 and at most {CANVAS_MAX:g}",
            param_hint=option,
        )
    return value


def _sizes(text: str | None, option: str) -> list[float | None]:
    if text is None:
        return [None]
    try:
        sizes = [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise typer.BadParameter(
            "takes metres separated by commas, e.g. 8,10,12", param_hint=option
        ) from None
    if not sizes:
        raise typer.BadParameter(
            "takes metres separated by commas, e.g. 8,10,12", param_hint=option
        )
    return [_length(size, option) for size in sizes]


@app.command(epilog=EPILOG)
def vary(
    spec_path: Annotated[
        Path,
        typer.Argument(help="Spec file (YAML); - reads it from standard input.", metavar="SPEC"),
    ],
    widths: Annotated[
        str | None, typer.Option("--widths", help="Canvas widths, e.g. 8,10,12 (metres).")
    ] = None,
    heights: Annotated[
        str | None, typer.Option("--heights", help="Canvas heights, e.g. 6,9 (metres).")
    ] = None,
    count: Annotated[
        int, typer.Option("--count", "-n", min=1, max=64, help="Layouts per size.")
    ] = 1,
    seed: Annotated[int | None, typer.Option("--seed", min=0, help="Override solver.seed.")] = None,
    outdir: Annotated[Path, typer.Option("--output", "-o", help="Folder for the outputs.")] = Path(
        "out"
    ),
    formats: Annotated[
        str | None, typer.Option("--format", "-f", help="Formats of each variant (as solve).")
    ] = None,
) -> None:
    """Retarget a spec to several sizes and sample different layouts at each; writes every
    variant and contact-sheet.svg, a grid of their elevations."""
    chosen = _formats(formats)
    width_list = _sizes(widths, "--widths")
    height_list = _sizes(heights, "--heights")
    check_output_folder(outdir)
    from facadecli.export.contact import Variant, contact_sheet  # only vary draws sheets
    from facadecli.solve import retarget, solve_variants

    spec = _load(spec_path)
    shown = _shown(spec_path)

    rows: list[list[Variant]] = []
    failed = 0
    lines: list[str] = []  # printed once every file is in place
    with staged(outdir) as stage:  # the whole run's files appear together or not at all
        for width in width_list:
            for height in height_list:
                sized = retarget(spec, width, height, seed)
                size = (sized.canvas.width, sized.canvas.height)
                stem = f"{spec.name}-{size[0]:g}x{size[1]:g}"
                at = f"{size[0]:g} x {size[1]:g} m"
                if len(width_list) * len(height_list) > 1:  # progress: a line per size
                    _warn(f"{shown}: {at}: drawing {count} layout{'s' * (count > 1)}...")
                try:
                    layouts = solve_variants(sized, count)
                except (InfeasibleError, SearchLimitError) as error:
                    typer.echo(f"{shown}: {at}: no layout: {error}", err=True)
                    rows.append([Variant(None, size, sized.solver.seed, 0, "no layout")])
                    failed += 1
                    continue
                row = []
                _detail(f"{shown}: {at}: {len(layouts)} different layouts")
                for index, layout in enumerate(layouts):
                    named = replace(layout, spec=retarget(layout.spec, name=f"{stem}-{index}"))
                    options = OutputOptions(base_dir=spec_path.parent)
                    written = write_outputs(named, stage, chosen, options)
                    row.append(Variant(named, size, sized.solver.seed, index))
                    lines.append(
                        f"{size[0]:g} x {size[1]:g} m #{index}: "
                        + ", ".join(str(outdir / path.name) for path in written)
                    )
                rows.append(row)
        write_atomic(stage / "contact-sheet.svg", contact_sheet(rows, spec.name))
    _say("\n".join([*lines, f"contact sheet: {outdir / 'contact-sheet.svg'}"]))
    if failed:
        raise typer.Exit(1)


@app.command(epilog=EPILOG)
def city(
    source: Annotated[
        Path,
        typer.Argument(
            help="A city manifest (YAML), or a footprints file to build with the defaults: "
            "OSM (.osm, .osm.pbf), GeoJSON, GeoPackage (.gpkg), Shapefile, FlatGeobuf.",
            metavar="MANIFEST|FOOTPRINTS",
        ),
    ],
    outdir: Annotated[Path, typer.Option("--output", "-o", help="Folder for the outputs.")] = Path(
        "out/city"
    ),
    spec: Annotated[
        Path | None,
        typer.Option(
            "--spec",
            metavar="SPEC",
            help="Without a manifest: the façade spec of every building [default: the "
            "examples by OSM building tag].",
            show_default=False,
        ),
    ] = None,
    jobs: Annotated[
        int | None, typer.Option("--jobs", "-j", min=1, help="Worker processes.")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", help="A Dask scheduler, tcp://HOST:PORT.")
    ] = None,
    resume: Annotated[
        bool,
        typer.Option(
            "--resume",
            help="Keep the buildings built before whose inputs are unchanged (their "
            "figures too); rebuild the rest.",
        ),
    ] = False,
    limit: Annotated[int | None, typer.Option("--limit", min=1, help="Only the first N.")] = None,
    usd: Annotated[
        bool,
        typer.Option(
            "--usd", help="Also a USD stage: one per building, and the city's of their payloads."
        ),
    ] = False,
    bbox: Annotated[
        str | None,
        typer.Option(
            "--bbox",
            metavar="W,S,E,N",
            help="Only footprints with a point in this box, in the footprints' CRS (lon/lat "
            "for OSM extracts).",
            show_default=False,
        ),
    ] = None,
    tiles3d: Annotated[
        bool, typer.Option("--3dtiles", help="Also OGC 3D Tiles: 3dtiles/tileset.json.")
    ] = False,
    lod: Annotated[
        str | None,
        typer.Option(
            "--lod",
            metavar="1,2,3",
            help="Levels of detail: 1 blocks, 2 roofs, 3 façades. The merged glb takes the "
            "finest; --3dtiles makes each [default: 3, and 1,2,3 with --3dtiles].",
            show_default=False,
        ),
    ] = None,
    instance: Annotated[
        bool,
        typer.Option(
            "--instance",
            help="Parts façades repeat (frames, sills, doors) as GPU instances "
            "(EXT_mesh_gpu_instancing): a mesh stored once, drawn once for all.",
        ),
    ] = False,
    timings: Annotated[
        bool,
        typer.Option("--timings", help="Record the times in the report (not reproducible)."),
    ] = False,
    embed_textures: Annotated[
        bool,
        typer.Option(
            "--embed-textures",
            help="Each glb holds its own texture pictures (self-contained, ~1.6 MiB a "
            "building), instead of naming the run's textures/, where each is stored once.",
        ),
    ] = False,
) -> None:
    """Build every footprint of a city manifest, or of a footprints file with sensible
    defaults, into whole buildings (SPEC 5)."""
    import os

    from facadecli.extras import require

    require("city", "facade city")
    if scheduler is not None:
        if not scheduler.startswith(("tcp://", "tls://", "inproc://")):
            raise SpecError.at(
                "--scheduler",
                None,
                None,
                f"'{scheduler}' is not a scheduler address",
                "write tcp://HOST:PORT",
            )
        require("dask", "facade city --scheduler")
    from functools import partial

    from facadecli.city.default import default_city
    from facadecli.city.manifest import load_city
    from facadecli.city.run import run_city
    from facadecli.city.tileset import chosen_lods

    box = _bbox(bbox) if bbox is not None else None
    lods, finest = chosen_lods(lod, tiles3d)
    is_manifest = source.suffix.lower() in (".yaml", ".yml")
    if is_manifest and spec is not None:
        raise typer.BadParameter(
            "is for a footprints file given without a manifest: the manifest names its specs",
            param_hint="--spec",
        )
    loaded = load_city(source) if is_manifest else default_city(source, spec)
    workers = jobs or os.cpu_count() or 1
    run = partial(  # the run's options; the calls below differ in their progress
        run_city,
        scheduler=scheduler,
        bbox=box,
        usd=usd,
        lods=lods,
        merged_lod=finest,
        instanced=instance,
        timings=timings,
        shared_textures=not embed_textures,
    )
    if _state["quiet"]:
        report = run(loaded, outdir, workers, limit, resume, None)
    elif sys.stderr.isatty():  # a progress bar for a person; plain lines for CI logs
        from rich.progress import Progress

        with Progress(transient=True) as bar:
            task = bar.add_task("buildings", total=None)

            def progress(done: int, total: int) -> None:
                bar.update(task, completed=done, total=total)

            report = run(loaded, outdir, workers, limit, resume, progress)
    else:
        step = max(1, (limit or 1000) // 20)

        def progress(done: int, total: int) -> None:
            if done == total or done % step == 0:
                typer.echo(f"{done}/{total} buildings", err=True)

        report = run(loaded, outdir, workers, limit, resume, progress)
    summary = report["summary"]

    def place(entry: dict[str, object]) -> str:  # a feature's place in the footprints
        if entry["line"] is None:
            return f"{loaded.footprints}: features[{entry['feature']}]"
        return f"{loaded.footprints}:{entry['line']}:{entry['column']}"

    for entry in report["rejected"]:  # rejected by design: reported, not a failure
        _warn(f"{place(entry)}: rejected: feature '{entry['id']}': {entry['error']}")
    alike = Counter(entry["warning"] for entry in report["warnings"])
    for entry in report["warnings"]:  # tags ignored: each warned once, all in the report
        where = place(entry)
        more = alike.pop(entry["warning"], 0) - 1
        if more >= 0:
            also = f" (and {more} more features: see the report)" if more else ""
            _warn(f"{where}: warning: feature '{entry['id']}': {entry['warning']}{also}")
    for entry in report["buildings"]:
        if entry["status"] != "ok":
            typer.echo(f"{source}: building {entry['id']}: {entry['error']}", err=True)
        else:
            _detail(
                f"{source}: building {entry['id']}: {entry.get('facades')} façades, "
                f"{entry.get('height')} m -> {outdir}/{entry.get('file')} "
                f"({entry.get('time_ms')} ms)"
            )
    rejected = f", {summary['rejected']} footprints rejected" if summary["rejected"] else ""
    models = report["models"]
    if models.get("merged_left_out"):
        _warn(f"{outdir}: no merged {report['name']}.glb: {models['merged_left_out']}")
    merged = [models["merged"] or models["tiles"]] if models["merged"] or models["tiles"] else []
    tileset = [models["3dtiles"]["tileset"]] if "3dtiles" in models else []
    beside = [models[key] for key in ("usd", "ground") if models.get(key)]  # when written
    names = [
        *merged,
        f"{report['name']}.city.json",
        f"{report['name']}.report.json",
        *tileset,
        *beside,
    ]
    _say(
        f"{summary['ok']} of {summary['buildings']} buildings built{rejected} in "
        f"{summary['seconds']} s -> " + ", ".join(f"{outdir}/{name}" for name in names)
    )
    if summary["failed"]:  # exit 1 only when a building that should build did not
        raise typer.Exit(1)


def _bbox(text: str) -> tuple[float, float, float, float]:
    try:
        west, south, east, north = (float(v) for v in text.split(","))
    except ValueError:
        west = south = east = north = math.nan
    box = (west, south, east, north)
    if not all(math.isfinite(v) for v in box) or west >= east or south >= north:
        raise typer.BadParameter(
            f"{text!r} is not WEST,SOUTH,EAST,NORTH with west < east and south < north, "
            "e.g. 24.93,60.16,24.96,60.18",
            param_hint="--bbox",
        )
    return box


def _size(text: str, option: str = "--derive") -> tuple[float, float]:
    try:
        width, height = (float(v) for v in text.lower().split("x"))
    except ValueError:
        width = height = -1.0
    if not all(math.isfinite(v) and 0 < v <= CANVAS_MAX for v in (width, height)):
        raise typer.BadParameter(
            f"{text!r} is not WIDTHxHEIGHT in metres (each above 0 and at most "
            f"{CANVAS_MAX:g}), e.g. 12x9",
            param_hint=option,
        )
    return width, height


# options of the commands that read a labelled layout (grammar, infer)
LayoutArgument = Annotated[
    Path,
    typer.Argument(
        help="A labelled layout: CMP .xml, a facadecli .layout.json, or a JSON list of rectangles.",
        metavar="LAYOUT",
    ),
]
SnapOption = Annotated[
    float | None,
    typer.Option(
        "--snap",
        min=0,
        max=0.1,
        help="Join edges closer than this fraction of the façade [default: 0.005 for CMP, "
        "0.001 for JSON lists, 0 for .layout.json].",
        show_default=False,
    ),
]
ToleranceOption = Annotated[
    float | None,
    typer.Option(
        "--tolerance",
        min=0,
        max=0.1,
        help="Regularise: give repeated elements one size when they differ by less than "
        "this fraction of the façade [default: 0.01 for CMP, 0.005 for JSON lists, 0 for "
        ".layout.json].",
        show_default=False,
    ),
]
SizeOption = Annotated[
    str | None,
    typer.Option(
        "--size",
        metavar="WxH",
        help="The façade's real size WxH (CMP annotations are a unit square): the "
        "layout is stretched to it.",
        show_default=False,
    ),
]


@app.command(epilog=EPILOG)
def infer(
    layout: LayoutArgument,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="The spec to write [default: out/<name>.yaml]; the report goes beside it "
            "as <name>.infer.json.",
            show_default=False,
        ),
    ] = None,
    size: SizeOption = None,
    snap: SnapOption = None,
    tolerance: ToleranceOption = None,
    check: Annotated[
        bool,
        typer.Option(
            "--check/--no-check",
            help="Solve the spec at the input's size (intersection over union per label "
            "against the annotation, elements lost or fused; and against the tidied layout) "
            "and at 0.7 and 1.5 times its width, and report it.",
        ),
    ] = True,
) -> None:
    """Infer a layered spec from a labelled façade: a wall and a layer per grid of each
    label's elements, back to front, with the sizes measured."""
    from facadecli.grammar.model import Options
    from facadecli.grammar.read import stem
    from facadecli.infer.run import check as check_spec
    from facadecli.infer.run import infer as infer_spec
    from facadecli.spec import parse_spec

    name = stem(layout)
    target = output or Path("out") / f"{name}.yaml"
    report_path = target.with_name(f"{target.name.removesuffix('.yaml')}.infer.json")
    check_output_file(target)
    check_output_file(report_path)
    options = Options(snap=snap, tolerance=tolerance, size=_size(size, "--size") if size else None)
    progress = _progress(str(layout))
    inferred = infer_spec(layout, name, options, progress)
    spec = parse_spec(inferred.text, str(target))  # a bug if it fails: never the user's input
    if check:
        inferred.checks = check_spec(inferred, spec, progress)
    report = inferred.report()
    target.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(target, inferred.text)
    write_atomic(report_path, json.dumps(report, indent=2) + "\n")
    for warning in inferred.warnings:
        _warn(f"{layout}: warning: {warning}")
    if inferred.unshared:
        _warn(f"{layout}: warning: bays {inferred.bays}; each layer has its own x word")
    summary = (
        f"{report['layers']} layers, {report['spec_lines']} lines for "
        f"{report['rectangles']} rectangles"
    )
    if check and not report.get("solves"):
        _warn(f"{layout}: warning: the spec does not solve: {report.get('error')}")
    elif check:
        faithful = report["fidelity"]
        summary += (
            f", IoU at least {report['iou_min']:.3f} against the tidied layout; against the "
            f"annotation mean IoU {faithful['iou_mean']:.3f}, "  # type: ignore[index]
            f"{faithful['lost']} lost, {faithful['fused']} fused"  # type: ignore[index]
        )
        if inferred.fidelity is not None:
            for warning in inferred.fidelity.warnings("the spec solved at the input's size"):
                _warn(f"{layout}: warning: {warning}")
        for entry in report["retargets"]:  # type: ignore[attr-defined]
            if not entry["solves"]:
                _warn(f"{layout}: warning: at {entry['width']:g} m wide: {entry['error']}")
        for label, iou in sorted(report.get("iou", {}).items()):  # type: ignore[attr-defined]
            _detail(f"{layout}: IoU of {label}: {iou:.4f} against the tidied layout")
        for label, iou in sorted(faithful["iou_per_label"].items()):  # type: ignore[index]
            _detail(f"{layout}: IoU of {label}: {iou:.4f} against the annotation")
    _say(f"{layout}: {summary} -> {target}, {report_path}")


@app.command(epilog=EPILOG)
def grammar(
    layout: LayoutArgument,
    outdir: Annotated[Path, typer.Option("--output", "-o", help="Folder for the outputs.")] = Path(
        "out/grammar"
    ),
    method: Annotated[
        str, typer.Option("--method", help="adp (the search) or greedy (the baseline).")
    ] = "adp",
    iterations: Annotated[
        int, typer.Option("--iterations", "-n", min=1, help="ADP iterations.")
    ] = 2000,
    seed: Annotated[
        int, typer.Option("--seed", min=0, help="ADP's random seed, and --variations'.")
    ] = 0,
    extensions: Annotated[
        str,
        typer.Option(
            "--extensions", help="Extra rules, comma-separated: repeatABA,symsplit,gridsplit."
        ),
    ] = "",
    split_cost: Annotated[
        float, typer.Option("--split-cost", min=0, help="Cost of a split rule (Eq. 2).")
    ] = 0.1,
    repeat_cost: Annotated[
        float, typer.Option("--repeat-cost", min=0, help="Cost of a repeat rule (Eq. 2).")
    ] = 0.5,
    snap: SnapOption = None,
    tolerance: ToleranceOption = None,
    size: SizeOption = None,
    derive: Annotated[
        list[str] | None,
        typer.Option(
            "--derive",
            metavar="WxH",
            help="Also apply the grammar at a new size WxH (repeatable): writes "
            "<name>-<W>x<H>.* through the layout writers.",
            show_default=False,
        ),
    ] = None,
    variations: Annotated[
        int,
        typer.Option(
            "--variations",
            min=1,
            max=64,
            help="Layouts per --derive size: the best fit and others with repeat counts "
            "within 1 of it, shuffled parts or proportions drawn near the input's, by --seed "
            "(Bao et al. 2013); writes <name>-<W>x<H>-v<K>.* and <name>.variations.svg when "
            "above 1.",
        ),
    ] = 1,
    formats: Annotated[
        str | None,
        typer.Option(
            "--format", "-f", help=f"Formats of derived layouts [{','.join(DEFAULT_FORMATS)}]."
        ),
    ] = None,
    time_limit: Annotated[
        float,
        typer.Option(
            "--time-limit",
            min=0.1,
            help="CPU seconds for the whole run, reading included; the search keeps the best "
            "grammar so far (reached, the result depends on the machine's speed).",
        ),
    ] = 120.0,
    timings: Annotated[
        bool, typer.Option("--timings", help="Record the time in the report (not reproducible).")
    ] = False,
) -> None:
    """Derive a split grammar from a labelled façade (Wu et al. 2014): writes it as text,
    JSON and CityEngine CGA, the tiling as SVG and a report; with --derive, the grammar at
    new sizes."""
    from facadecli.grammar.derive import TooLarge
    from facadecli.grammar.extract import extract_grammar
    from facadecli.grammar.model import Options
    from facadecli.grammar.outputs import grammar_files, variations_sheet
    from facadecli.grammar.read import stem
    from facadecli.grammar.split import EXTENSIONS, Costs
    from facadecli.grammar.variations import derive_sizes

    if method not in ("adp", "greedy"):
        raise typer.BadParameter(f"{method!r}: use adp or greedy", param_hint="--method")
    chosen = tuple(e.strip() for e in extensions.split(",") if e.strip())
    for name in chosen:
        if name not in EXTENSIONS:
            raise typer.BadParameter(
                f"{name!r}: use {', '.join(EXTENSIONS)}", param_hint="--extensions"
            )
    sizes = [_size(text) for text in derive or []]
    kinds = _formats(formats)
    check_output_folder(outdir)
    options = Options(
        method,
        iterations,
        seed,
        chosen,
        Costs(split_cost, repeat_cost),
        snap=snap,
        tolerance=tolerance,
        time_limit=time_limit,
        size=_size(size, "--size") if size else None,
    )
    progress = _progress(str(layout))
    extraction = extract_grammar(layout, options, progress)
    if extraction.problems:  # a bug, never a user's error
        raise RuntimeError(
            "the grammar does not derive its layout: " + "; ".join(extraction.problems)
        )
    found = extraction.grammar
    name = stem(layout)
    for warning in extraction.warnings:
        _warn(f"{layout}: warning: {warning}")
    if extraction.fidelity is not None:
        faithful = extraction.fidelity
        for warning in faithful.warnings("the grammar at the input's size"):
            _warn(f"{layout}: warning: {warning}")
        _detail(
            f"{layout}: against the annotation: mean IoU {faithful.iou_mean:.3f}, "
            f"{faithful.lost} lost, {faithful.fused} fused of {faithful.elements} elements"
        )
    _detail(
        f"{layout}: {len(extraction.tiling.xs) - 1} x {len(extraction.tiling.ys) - 1} tiling, "
        f"search {extraction.time_ms:.0f} ms"
    )
    try:  # every size is derived before anything is written
        derived = derive_sizes(extraction, name, sizes, variations, seed, progress)
    except TooLarge as error:
        raise typer.BadParameter(str(error), param_hint="--derive") from None
    outputs = grammar_files(extraction, name, timings, derived)
    for new in derived:
        at = f"{layout}: warning: {new.width:g}x{new.height:g}"
        for note in new.notes:
            _warn(f"{at}: {note}")
        for k, (result, keeps) in enumerate(zip(new.layouts, new.kept, strict=True)):
            which = f" v{k}" if variations > 1 else ""
            for warning in [*result.warnings, *keeps.warnings()]:
                _warn(f"{at}{which}: {warning}")
    if variations > 1 and derived:
        outputs[f"{name}.variations.svg"] = variations_sheet(derived, name, seed)
    written = [outdir / file for file in outputs]
    with staged(outdir) as stage:  # the grammar and every derived size together, or nothing
        for file, text in outputs.items():
            write_atomic(stage / file, text)
        for result in (built for new in derived for built in new.layouts):
            written += [
                outdir / path.name for path in write_outputs(result, stage, kinds, OutputOptions())
            ]
    _say(
        f"{layout}: {len(found.rules)} rules, cost {found.cost:.1f} "
        f"(greedy {extraction.found.greedy_cost:.1f}) -> " + ", ".join(str(p) for p in written)
    )


@app.command(epilog=EPILOG)
def schema(
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Write to this file instead of standard output (-)."),
    ] = None,
) -> None:
    """Print the JSON Schema of the spec format (point your editor's YAML plugin at it)."""
    from facadecli.spec import spec_schema_text

    if output is None or str(output) == STDIN:
        sys.stdout.write(spec_schema_text())
        return
    check_output_file(output)
    write_atomic(output, spec_schema_text())


@app.command(epilog=EPILOG)
def watch(
    spec: Annotated[Path, typer.Argument(help="The spec to preview.", metavar="SPEC")],
    port: Annotated[
        int,
        typer.Option("--port", min=0, max=65535, help="Port on 127.0.0.1 (0: any free one)."),
    ] = 8765,
    poll: Annotated[
        bool,
        typer.Option(
            "--poll",
            help="Look at the file 20 times a second instead of waiting for the system's "
            "file events (for network drives and mounts that send none).",
        ),
    ] = False,
) -> None:
    """Preview a spec live: solve it again on every save and serve its page (the 3D model
    and the elevation) on 127.0.0.1, which the server updates; errors show on the page."""
    from facadecli.viewer.watch import serve

    if not spec.is_file():
        what = "not a regular file" if spec.exists() else "no such file"
        raise SpecError.at(str(spec), None, None, what, "check the path")
    try:
        serve(spec, port, _watch_log(), poll)
    except OSError as error:
        raise typer.BadParameter(
            f"cannot serve on port {port}: {error.strerror}", param_hint="--port"
        ) from None
    except KeyboardInterrupt:
        raise typer.Exit(0) from None


def _watch_log() -> Callable[[str, bool], None]:
    """The log of ``facade watch``: its first line, the page's address, and errors always
    (a quiet preview still needs its address), the other lines unless --quiet."""
    told = {"address": False}

    def log(line: str, error: bool) -> None:
        if error:
            typer.echo(line, err=True)
        elif not told["address"]:
            told["address"] = True
            typer.echo(line)
        else:
            _say(line)

    return log


@app.command(epilog=EPILOG)
def view(
    folder: Annotated[
        Path,
        typer.Argument(
            help="A folder of models (the output of facade solve, vary or city).",
            metavar="FOLDER",
        ),
    ],
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", metavar="PAGE", help="The page to write [default: FOLDER/index.html]."
        ),
    ] = None,
) -> None:
    """Write one self-contained HTML page of every model in FOLDER: a list of them with
    their elevations beside a 3D viewer; click one to see it."""
    from facadecli.viewer.gallery import write_gallery

    written = write_gallery(folder, output)
    for file in written.skipped:
        _warn(f"{file.path}: warning: left out: {file.reason}")
    count, left = len(written.models), len(written.skipped)
    note = f" ({left} file{'' if left == 1 else 's'} left out)" if left else ""
    _say(f"{count} model{'' if count == 1 else 's'} -> {written.page}{note}")


@app.command(epilog=EPILOG)
def words(
    specs: SpecPaths,
    limit: Annotated[int, typer.Option("--limit", "-n", min=1, help="Words per layer axis.")] = 5,
) -> None:
    """List the words each layer's patterns make that fit the canvas, nearest first."""
    from facadecli.preview import preview_words

    run = _Run(specs)
    for path, spec in run.specs():
        _say(f"# {_shown(path)} ({spec.name})")
        for preview in preview_words(spec, limit):
            _say("\n".join(preview.lines()))
        run.succeed()
    run.finish()


@app.command(epilog=EPILOG)
def examples(
    folder: Annotated[
        Path,
        typer.Argument(help="The folder to copy them into (made if missing).", metavar="DIR"),
    ],
) -> None:
    """Copy the example specs (specs/) and the samples for grammar, infer and city
    (samples/) into DIR, to start from; nothing already there is overwritten."""
    from facadecli.examples import copy_examples

    written = copy_examples(folder)
    for path in written:
        _detail(str(path))
    _say(
        f"{len(written)} files -> {folder / 'specs'}, {folder / 'samples'} "
        f"(try: facade solve {folder / 'specs' / 'townhouse.yaml'} -o out)"
    )


def _progress(subject: str) -> Callable[[str], None]:
    """Progress lines on standard error for a run that may take seconds: each stage as it
    starts (plain lines, safe in logs); with --verbose, the seconds since the start."""
    started = time.perf_counter()

    def progress(stage: str) -> None:
        if _state["verbose"]:
            _warn(f"{subject}: {stage} (at {time.perf_counter() - started:.1f} s)")
        else:
            _warn(f"{subject}: {stage}...")

    return progress


def main() -> None:
    """Entry point: run the app, turning every error into a message and an exit code."""
    from facadecli.extras import extra_of, missing_message

    _state.update(debug=False, quiet=False, verbose=False)  # a fresh run (tests call main)
    try:
        args = _hoisted(sys.argv[1:])
        _state["debug"] = "--debug" in args  # for an error before the options are read
        with warnings.catch_warnings():  # a stage's FacadeWarning: a warning line, once
            warnings.simplefilter("always", FacadeWarning)  # told once by ``_shown_warning``
            warnings.showwarning = _shown_warning(warnings.showwarning)
            app(args=args, prog_name="facade")  # typer reports usage errors itself (exit 2)
    except FacadeError as error:
        _report(error)
        sys.exit(error.exit_code)
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        sys.exit(130)
    except ImportError as error:  # an extra's module that went missing past the door
        extra = extra_of(error.name)
        if extra is None or _state["debug"]:
            _internal(error)
        else:
            named = next((f"facade {arg}" for arg in sys.argv[1:] if arg in COMMANDS), "facade")
            typer.echo(missing_message(extra, named, str(error.name)), err=True)
            sys.exit(2)
    except Exception as error:  # the last line of defence: no traceback for users
        _internal(error)


def _shown_warning(other: Callable[..., None]) -> Callable[..., None]:
    """``warnings.showwarning`` for a run: each FacadeWarning a warning line, once."""
    told: set[str] = set()

    def show(message: Warning | str, category: type[Warning], *rest: object) -> None:
        if issubclass(category, FacadeWarning):
            if str(message) not in told:
                told.add(str(message))
                _warn(str(message))
        else:
            other(message, category, *rest)

    return show


COMMANDS = {  # the commands' names, for messages (a command is named after its function)
    info.name or getattr(info.callback, "__name__", "") for info in app.registered_commands
}


def _internal(error: Exception) -> NoReturn:
    if _state["debug"]:
        traceback.print_exc()
    else:
        typer.echo(
            f"facade: internal error: {type(error).__name__}: {error} "
            "(run with --debug for a traceback, and please report it)",
            err=True,
        )
    sys.exit(1)
