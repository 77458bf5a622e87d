"""The compiled inner loops (the grammar search, the exact alignment search); everything
else is in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "facadecli.grammar._adp",
            ["facadecli/grammar/_adp.c"],
            extra_compile_args=["-O2", "-Wall", "-Wextra", "-Wno-unused-parameter"],
        ),
        Extension(
            "facadecli.solver._exact",
            ["facadecli/solver/_exact.c"],
            extra_compile_args=["-O3", "-Wall", "-Wextra", "-Wno-unused-parameter"],
        ),
    ]
)
