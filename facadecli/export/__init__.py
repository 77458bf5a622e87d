"""Writers: the only modules that write files, one per format, behind a registry."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from facadecli.export.atomic import write_atomic
from facadecli.layout import Layout

Writer = Callable[[Layout, Path, bool], list[Path]]


def _write_json(layout: Layout, outdir: Path, timings: bool) -> list[Path]:
    from facadecli.export.report import report_text

    path = outdir / f"{layout.spec.name}.layout.json"
    write_atomic(path, report_text(layout, timings=timings))
    return [path]


#: format name -> writer(layout, outdir, timings) returning the files it wrote
WRITERS: dict[str, Writer] = {"json": _write_json}


def write_outputs(layout: Layout, outdir: Path, formats: list[str], timings: bool) -> list[Path]:
    written: list[Path] = []
    for name in formats:
        written.extend(WRITERS[name](layout, outdir, timings))
    return written


__all__ = ["WRITERS", "write_atomic", "write_outputs"]
