"""Memory a city run's client has freed, given back to the system (:func:`give_back`).

The client frees most of what planning makes (every footprint read, as Python and GEOS
objects, the neighbours' party walls...) and, as buildings end, what their tiles took.
The C heap keeps freed memory for its next allocations, and the few long-lived pieces
made between the freed ones (the packed tasks' chunks) keep it from trimming its top:
planning a generated town of 8,000 buildings (docs/benchmarks.md), 20 of the 27 MiB it
added stayed resident, free. glibc's ``malloc_trim`` returns every free page, wherever
it is; elsewhere nothing is done (the memory is still reused by the run).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
from collections.abc import Callable

# buildings ended between two calls while building: a call took 17-35 ms of CPU on a
# heap of 200,000 shapes freed among kept ones (``time.process_time``), 0.03 ms a building
EVERY = 1024


@functools.cache
def _trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, None where there is none."""
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    try:
        function: Callable[[int], int] = ctypes.CDLL(name).malloc_trim
    except (OSError, AttributeError):  # another C library (musl, macOS, Windows)
        return None
    return function


def give_back() -> bool:
    """The C heap's free pages returned to the system; False where that cannot be done."""
    trim = _trim()
    if trim is None:
        return False
    trim(0)
    return True
