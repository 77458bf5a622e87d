"""Writers: the only modules that write files, one per format, behind a registry."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from facadecli.export.atomic import write_atomic
from facadecli.layout import Layout


@dataclass(frozen=True)
class OutputOptions:
    timings: bool = False  # record solve times in the report (they vary run to run)
    labels: bool = False  # symbol names and column lines over the SVG elevation


Writer = Callable[[Layout, Path, OutputOptions], list[Path]]


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


#: format name -> writer(layout, outdir, options) returning the files it wrote
WRITERS: dict[str, Writer] = {"json": _write_json, "svg": _write_svg}


def write_outputs(
    layout: Layout, outdir: Path, formats: list[str], options: OutputOptions
) -> list[Path]:
    written: list[Path] = []
    for name in formats:
        written.extend(WRITERS[name](layout, outdir, options))
    return written


__all__ = ["WRITERS", "OutputOptions", "write_atomic", "write_outputs"]
