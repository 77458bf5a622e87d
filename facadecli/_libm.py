"""The functions of C's math library that the modules written for Cython (the exact and the
grammar searches) take from ``libc.math`` when compiled, as Python for when they run
interpreted, with C's results: the same bits either way."""


def nearbyint(x: float) -> float:
    """The nearest whole number, ties to even (C's in the default rounding mode)."""
    return float(round(x))
