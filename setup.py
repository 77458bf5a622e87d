"""The compiled inner loops (the grammar search, the exact alignment search); everything
else is in pyproject.toml.

Both are optional: where they cannot be built (no C compiler, no Python headers) the
install goes on without them, and facadecli runs the same searches in pure Python
(``facadecli.native`` says which is in use: ``facadecli.native.describe()``)."""

import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
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


setup(
    cmdclass={"build_ext": OptionalBuildExt},
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
