"""The compiled inner loops (the grammar search, the exact alignment search), and the
example specs and samples shipped inside the package; everything else is in
pyproject.toml.

Both extensions are optional: where they cannot be built (no C compiler, no Python
headers) the install goes on without them, and facadecli runs the same searches in pure
Python (``facadecli.native`` says which is in use: ``facadecli.native.describe()``).

The examples live once in git, at the root (``specs/``, ``samples/``), where the docs and
tests use them; ``build_py`` copies them into the built package as
``facadecli/_examples/`` (``facade examples DIR``, ``facade city`` without a manifest),
so a wheel carries them and the repository holds no second copy."""

import shutil
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py
from setuptools.errors import CCompilerError, ExecError, PlatformError

NOTE = "facadecli: C compiler not available, using the pure-Python search (slower)"
FAILURES = (CCompilerError, ExecError, PlatformError, OSError, ValueError)


class OptionalBuildExt(build_ext):
    """``build_ext`` that installs anyway, with one note, when an extension does not build."""

    def run(self) -> None:
        try:
            super().run()
        except FAILURES as error:  # no compiler at all (PlatformError) or no headers
            self._skip("the C extensions", error)

    def build_extension(self, ext: Extension) -> None:
        try:
            super().build_extension(ext)
        except FAILURES as error:
            self._skip(ext.name, error)

    def _skip(self, what: str, error: Exception) -> None:
        if not getattr(self, "_noted", False):  # one line, however many fail
            print(NOTE, file=sys.stderr)
            self._noted = True
        self.announce(f"facadecli: {what} not built: {error}", level=2)


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
            "facadecli.grammar._adp",
            ["facadecli/grammar/_adp.c"],
            extra_compile_args=["-O2", "-Wall", "-Wextra", "-Wno-unused-parameter"],
            optional=True,
        ),
        Extension(
            "facadecli.solver._exact",
            ["facadecli/solver/_exact.c"],
            extra_compile_args=["-O3", "-Wall", "-Wextra", "-Wno-unused-parameter"],
            optional=True,
        ),
    ],
)
