"""The optional parts of facadecli: which extra installs which modules, and the check a
command makes at its door, before any work, so that a missing extra is one line naming
it rather than a traceback from deep inside a pipeline.

The core (``pip install facadecli``) solves, validates, varies, previews and infers;
``facade city`` needs ``[city]``, ``facade city --scheduler`` also ``[dask]``, Shapefile
and FlatGeobuf footprints ``[gdal]``.
"""

from __future__ import annotations

import importlib.util

from facadecli.errors import MissingExtraError

#: extra -> the modules it installs that facadecli imports
EXTRAS: dict[str, tuple[str, ...]] = {
    "city": ("shapely", "pyproj", "osmium"),
    "dask": ("distributed",),
    "gdal": ("pyogrio",),
}


def missing_message(extra: str, needed_by: str, module: str) -> str:
    return (
        f"{needed_by} needs the [{extra}] extra ({module} is not installed): "
        f"pip install 'facadecli[{extra}]'"
    )


def require(extra: str, needed_by: str) -> None:
    """Raise :class:`MissingExtraError` unless every module of ``extra`` can be imported;
    ``needed_by`` says what needs it (``facade city``). Looks the modules up without
    importing them."""
    for module in EXTRAS[extra]:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):  # a broken install, or a module set to None
            found = False
        if not found:
            raise MissingExtraError(missing_message(extra, needed_by, module))


def extra_of(module: str | None) -> str | None:
    """The extra that installs a module (or its package), if one does."""
    top = (module or "").split(".")[0]
    return next((extra for extra, names in EXTRAS.items() if top in names), None)
