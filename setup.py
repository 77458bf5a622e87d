"""The compiled inner loops (the grammar search, the exact alignment search), and the
example specs and samples shipped inside the package; everything else is in
pyproject.toml.

Both extensions are optional: where they cannot be built (no C compiler, no Python
headers) the install goes on without them, and facadecli runs the same searches in pure
Python (``facadecli.native`` says which is in use: ``facadecli.native.describe()``).

Each is a ``.py`` module compiled by Cython (its types in the ``.pxd`` beside it): the
grammar search's loop ``facadecli/grammar/adp.py`` and the exact alignment search's walk
``facadecli/solver/network.py``. A compiled module is stamped with the digest of the sources
it was built from, so that ``facadecli.native`` never runs a compiled module older than its
source.

The examples live once in git, at the root (``specs/``, ``samples/``), where the docs and
tests use them; ``build_py`` copies them into the built package as
``facadecli/_examples/`` (``facade examples DIR``, ``facade city`` without a manifest),
so a wheel carries them and the repository holds no second copy."""

import hashlib
import shutil
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py
from setuptools.errors import CCompilerError, ExecError, PlatformError

NOTE = "facadecli: C compiler not available, using the pure-Python search (slower)"
FAILURES = (CCompilerError, ExecError, PlatformError, OSError, ValueError)

GRAMMAR_SEARCH = "facadecli.grammar.adp"  # compiled from facadecli/grammar/adp.py by Cython
EXACT_SEARCH = "facadecli.solver.network"  # compiled from facadecli/solver/network.py by Cython
CYTHONIZED = (GRAMMAR_SEARCH, EXACT_SEARCH)
STAMP = "COMPILED_FROM: str | None = None"  # the line of the .py that says what it was built from
# the .pxd types the arrays' elements: no bounds or sign checks on their indices
DIRECTIVES = {
    "language_level": 3,
    "annotation_typing": False,  # types: the .pxd
    "boundscheck": False,
    "wraparound": False,
    "initializedcheck": False,
    "cdivision": True,
}


def source_digest(module: Path) -> str:
    """The digest of a module's ``.py`` and ``.pxd`` (as ``facadecli.native.source_digest``)."""
    digest = hashlib.sha256()
    for path in (module.with_suffix(".py"), module.with_suffix(".pxd")):
        digest.update(path.read_bytes() if path.exists() else b"")
    return digest.hexdigest()


class OptionalBuildExt(build_ext):
    """``build_ext`` that installs anyway, with one note, when an extension does not build;
    it makes the C of a module written for Cython first."""

    def run(self) -> None:
        try:
            super().run()
        except FAILURES as error:  # no compiler at all (PlatformError) or no headers
            self._skip("the C extensions", error)

    def build_extension(self, ext: Extension) -> None:
        try:
            if ext.name in CYTHONIZED:
                ext.sources = [self._cythonized(ext.name, Path(ext.sources[0]))]
            super().build_extension(ext)
        except (*FAILURES, ImportError) as error:  # ImportError: no Cython (no build isolation)
            self._skip(ext.name, error)

    def _cythonized(self, name: str, source: Path) -> str:
        """The C of a ``.py`` module compiled by Cython, from a copy stamped with the digest of
        its sources (``COMPILED_FROM``; the copy is otherwise the file itself)."""
        from Cython.Build import cythonize  # a build requirement (pyproject.toml)

        copy = Path(self.build_temp) / "cython" / source
        copy.parent.mkdir(parents=True, exist_ok=True)
        text = source.read_text(encoding="utf-8")
        if STAMP not in text:
            raise ValueError(f"{source} has no line '{STAMP}' to stamp")
        stamped = text.replace(STAMP, f'COMPILED_FROM: str | None = "{source_digest(source)}"')
        _write_if_changed(copy, stamped.encode())  # unchanged files keep Cython's C
        _write_if_changed(copy.with_suffix(".pxd"), source.with_suffix(".pxd").read_bytes())
        (made,) = cythonize(
            [Extension(name, [str(copy)], extra_compile_args=["-O3"])],
            compiler_directives=DIRECTIVES,
            quiet=True,
        )
        return str(made.sources[0])

    def _skip(self, what: str, error: Exception) -> None:
        if not getattr(self, "_noted", False):  # one line, however many fail
            print(NOTE, file=sys.stderr)
            self._noted = True
        self.announce(f"facadecli: {what} not built: {error}", level=2)


def _write_if_changed(path: Path, data: bytes) -> None:
    if not path.exists() or path.read_bytes() != data:
        path.write_bytes(data)


EXAMPLES = ("specs", "samples")  # folders at the root, shipped as facadecli/_examples/<folder>


class BuildPyWithExamples(build_py):
    """``build_py`` that also copies the example folders into the built package."""

    def run(self) -> None:
        super().run()
        root = Path(__file__).resolve().parent
        target = Path(self.build_lib) / "facadecli" / "_examples"
        shutil.rmtree(target, ignore_errors=True)  # a build folder left by an earlier build
        for folder in EXAMPLES:
            if (root / folder).is_dir():  # an sdist without them builds a wheel without them
                shutil.copytree(root / folder, target / folder, dirs_exist_ok=True)


setup(
    cmdclass={"build_ext": OptionalBuildExt, "build_py": BuildPyWithExamples},
    ext_modules=[
        Extension(
            GRAMMAR_SEARCH, ["facadecli/grammar/adp.py"], extra_compile_args=["-O3"], optional=True
        ),
        Extension(
            EXACT_SEARCH, ["facadecli/solver/network.py"], extra_compile_args=["-O3"], optional=True
        ),
    ],
)
