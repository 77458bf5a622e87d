"""The ``facade`` command: the only module that talks to the terminal.

Exit codes (SPEC section 4): 0 success, 1 some specs failed in a multi-spec run,
2 invalid input, 3 no layout exists. No traceback reaches a user unless ``--debug``.
"""

from __future__ import annotations

import sys
import traceback
from pathlib import Path
from typing import Annotated

import typer

from facadecli import __version__
from facadecli.errors import FacadeError, SpecError
from facadecli.export import write_atomic
from facadecli.preview import preview_words
from facadecli.spec import load_spec, spec_schema_text

app = typer.Typer(
    name="facade",
    help="Turn declarative YAML façade specs into layered, aligned building façades.",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)

_state = {"debug": False}

SpecPaths = Annotated[
    list[Path], typer.Argument(help="Spec files (YAML).", metavar="SPEC", show_default=False)
]


def _version(value: bool) -> None:
    if value:
        typer.echo(f"facade {__version__}")
        raise typer.Exit(0)


@app.callback()
def _main(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version."),
    ] = False,
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks of errors.")] = False,
) -> None:
    _state["debug"] = debug


def _report(error: FacadeError) -> None:
    typer.echo(str(error), err=True)


@app.command()
def validate(specs: SpecPaths) -> None:
    """Check specs without solving them; print every problem with file:line:col."""
    failed = 0
    for path in specs:
        try:
            spec = load_spec(path)
        except SpecError as error:
            _report(error)
            failed += 1
            continue
        typer.echo(f"{path}: ok ({spec.name}: {len(spec.layers)} layers)")
    if failed:
        typer.echo(f"{failed} of {len(specs)} specs invalid", err=True)
        raise typer.Exit(2)


@app.command()
def schema(
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", help="Write to this file instead of standard output."),
    ] = None,
) -> None:
    """Print the JSON Schema of the spec format (point your editor's YAML plugin at it)."""
    text = spec_schema_text()
    if output is None:
        sys.stdout.write(text)
    else:
        write_atomic(output, text)


@app.command()
def words(
    specs: SpecPaths,
    limit: Annotated[int, typer.Option("--limit", "-n", min=1, help="Words per layer axis.")] = 5,
) -> None:
    """List the words each layer's patterns make that fit the canvas, nearest first."""
    failed = 0
    for path in specs:
        try:
            spec = load_spec(path)
        except SpecError as error:
            _report(error)
            failed += 1
            continue
        typer.echo(f"# {path} ({spec.name})")
        for preview in preview_words(spec, limit):
            typer.echo("\n".join(preview.lines()))
    if failed:
        raise typer.Exit(2 if failed == len(specs) else 1)


def main() -> None:
    """Entry point: run the app, turning every error into a message and an exit code."""
    try:
        app()  # typer reports usage errors itself (exit 2) and exits
    except FacadeError as error:
        _report(error)
        sys.exit(error.exit_code)
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        sys.exit(130)
    except Exception as error:  # the last line of defence: no traceback for users
        if _state["debug"]:
            traceback.print_exc()
        else:
            typer.echo(
                f"facade: internal error: {type(error).__name__}: {error} "
                "(run with --debug for a traceback, and please report it)",
                err=True,
            )
        sys.exit(1)
