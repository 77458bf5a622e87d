"""The compiled inner loops, where this install has them: the one place that says, per
module, whether it runs compiled or as Python.

- :mod:`facadecli.grammar.adp`: the grammar search's inner loop (``facade grammar``).
- :mod:`facadecli.solver.network`: the exact alignment search's walk through the network
  (every ``facade solve`` that the constructions leave a question to) and the elimination
  of the sizing's equalities.

setup.py compiles each ``.py`` itself with Cython (its types in the ``.pxd`` beside it) where
there is a C compiler; without one the same file runs interpreted, slower, giving the same
grammars and layouts. A compiled module built from another version of its ``.py`` or
``.pxd`` (an editable install whose sources changed since) is never used: the source runs
instead.

setup.py builds them when it can and installs without them when there is no C compiler.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

GRAMMAR_SEARCH = "facadecli.grammar.adp"
EXACT_SEARCH = "facadecli.solver.network"
STALE: set[str] = set()  # modules whose compiled build was passed over for their source


def source_digest(module: Path) -> str:
    """The digest of a compiled module's sources: the ``.py`` and its ``.pxd`` (setup.py
    stamps it into the compiled module as ``COMPILED_FROM``)."""
    digest = hashlib.sha256()
    for path in (module.with_suffix(".py"), module.with_suffix(".pxd")):
        digest.update(path.read_bytes() if path.exists() else b"")
    return digest.hexdigest()


def _interpreted(name: str, source: Path) -> ModuleType:
    """The module run from its ``.py``, whatever compiled module sits beside it."""
    loader = importlib.machinery.SourceFileLoader(name, str(source))
    spec = importlib.util.spec_from_file_location(name, source, loader=loader)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # replaces the compiled one
    loader.exec_module(module)
    return module


def load(name: str) -> ModuleType:
    """Import a module that may be compiled: the compiled one when it was built from the
    sources beside it, else the ``.py`` (a stale build never runs old code)."""
    module = sys.modules.get(name) or importlib.import_module(name)
    if compiled(module):
        source = Path(str(module.__file__)).parent / (name.rpartition(".")[2] + ".py")
        if source_digest(source) != module.COMPILED_FROM:
            STALE.add(name)
            return _interpreted(name, source)
    return module


def compiled(module: ModuleType) -> bool:
    """Whether the module runs compiled (Cython) rather than interpreted."""
    return module.__spec__ is not None and not str(module.__spec__.origin).endswith(".py")


def describe() -> str:
    """One line on which searches run compiled (for a bug report, or a doctor command)."""

    def which(name: str) -> str:
        module = load(name)
        if name in STALE:
            return "pure Python (its compiled build is older than its source: reinstall)"
        return "compiled" if compiled(module) else "pure Python (no C compiler at install)"

    return f"grammar search: {which(GRAMMAR_SEARCH)}; exact search: {which(EXACT_SEARCH)}"


__all__ = [
    "EXACT_SEARCH",
    "GRAMMAR_SEARCH",
    "compiled",
    "describe",
    "load",
    "source_digest",
]
