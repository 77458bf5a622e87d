"""facadecli: layered procedural façades from declarative YAML specs.

The public API; everything else is internal and may change. Its names are loaded when
first used (``facade --version`` needs none of them, and they bring numpy and pydantic).
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING

import facadecli._blas  # noqa: F401  (first: before anything loads numpy)

if TYPE_CHECKING:
    from facadecli.errors import FacadeError, InfeasibleError, Problem, SpecError
    from facadecli.layout import Layout, Shape
    from facadecli.patterns import (
        Choice,
        Letter,
        Word,
        compile_pattern,
        enumerate_words,
        make_word,
    )
    from facadecli.solve import retarget, solve
    from facadecli.spec import Spec, load_spec, parse_spec, spec_schema, validate_spec

__version__ = "0.1.0"

_HOMES = {  # public name -> the module that defines it
    "FacadeError": "facadecli.errors",
    "InfeasibleError": "facadecli.errors",
    "Problem": "facadecli.errors",
    "SpecError": "facadecli.errors",
    "Layout": "facadecli.layout",
    "Shape": "facadecli.layout",
    "Choice": "facadecli.patterns",
    "Letter": "facadecli.patterns",
    "Word": "facadecli.patterns",
    "compile_pattern": "facadecli.patterns",
    "enumerate_words": "facadecli.patterns",
    "make_word": "facadecli.patterns",
    "retarget": "facadecli.solve",
    "solve": "facadecli.solve",
    "Spec": "facadecli.spec",
    "load_spec": "facadecli.spec",
    "parse_spec": "facadecli.spec",
    "spec_schema": "facadecli.spec",
    "validate_spec": "facadecli.spec",
}


class _Package(types.ModuleType):
    """The package, kept from one clash: importing the submodule ``facadecli.solve`` sets
    the package's ``solve`` to that module; the public ``solve`` is the function (as when
    this file imported it at once), so that setting is left out."""

    def __setattr__(self, name: str, value: object) -> None:
        if not (name in _HOMES and isinstance(value, types.ModuleType)):
            super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str) -> object:
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module 'facadecli' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value  # once: later lookups find it here
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_HOMES})


__all__ = [
    "Choice",
    "FacadeError",
    "InfeasibleError",
    "Layout",
    "Letter",
    "Problem",
    "Shape",
    "Spec",
    "SpecError",
    "Word",
    "__version__",
    "compile_pattern",
    "enumerate_words",
    "load_spec",
    "make_word",
    "parse_spec",
    "retarget",
    "solve",
    "spec_schema",
    "validate_spec",
]
