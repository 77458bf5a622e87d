"""The "did you mean" hints of every error message, in one place, with bounded work.

A hint compares an unknown name with the names it could have meant. difflib's comparison
takes time that grows with the product of the lengths, so a long name (a spec allows one of
half a megabyte) is compared only where a hint could come of it: names longer than
``HINT_CHARS_MAX`` get none, and a candidate of a length too far from the name's to reach the
similarity cutoff is never compared (the result is the same as comparing it).
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from facadecli.limits import HINT_NAME_CHARS_MAX

HINT_CHARS_MAX = HINT_NAME_CHARS_MAX
CUTOFF = 0.6  # difflib's default similarity for a close match


def closest(name: str, known: Iterable[str]) -> str | None:
    """The known name most like ``name`` (difflib's close match), or None."""
    if len(name) > HINT_CHARS_MAX:
        return None
    # similarity is 2 * matches / (both lengths), and matches <= the shorter length
    candidates = [
        other
        for other in known
        if len(other) <= HINT_CHARS_MAX
        and 2 * min(len(name), len(other)) >= CUTOFF * (len(name) + len(other))
    ]
    found = difflib.get_close_matches(name, candidates, n=1, cutoff=CUTOFF)
    return found[0] if found else None


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """``"did you mean 'x'? "`` for the closest known name, else ``""``."""
    found = closest(name, known)
    return f"did you mean '{found}'? " if found is not None else ""


def split_into(name: str, known: set[str]) -> list[str] | None:
    """``'BA'`` -> ``['B', 'A']`` when the name is a run of known names (two or more); each
    end of the name is tried against the known names that could end there, so the work is
    linear in the name (of at most ``HINT_CHARS_MAX`` characters)."""
    longest = max(map(len, known), default=0)
    if len(name) > HINT_CHARS_MAX or not longest:
        return None
    best: dict[int, list[str]] = {0: []}
    for end in range(1, len(name) + 1):
        for start in range(max(0, end - longest), end):
            if start in best and name[start:end] in known:
                best[end] = [*best[start], name[start:end]]
                break
    result = best.get(len(name))
    return result if result and len(result) > 1 else None
