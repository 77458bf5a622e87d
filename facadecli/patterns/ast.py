"""The abstract syntax of a pattern (SPEC 2.2).

Every node remembers ``pos``, the character offset in the pattern text where it starts, so
later stages (cross-checks, the solver's reasons) can point at it in the spec file.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass


@dataclass(frozen=True)
class Sym:
    """One symbol, e.g. ``A``."""

    name: str
    pos: int


@dataclass(frozen=True)
class Seq:
    """Concatenation; an empty ``items`` is the empty word."""

    items: tuple[Node, ...]
    pos: int


@dataclass(frozen=True)
class Alt:
    """Alternation: exactly one branch is chosen."""

    branches: tuple[Node, ...]
    pos: int


@dataclass(frozen=True)
class Fixed:
    """A fixed count ``^3``; negative reflects (``^-1``)."""

    value: int

    @property
    def reflect(self) -> bool:
        return self.value < 0


@dataclass(frozen=True)
class Named:
    """A named counter ``^k`` shared by every pattern naming it; ``^-k`` reflects."""

    name: str
    reflect: bool
    pos: int


@dataclass(frozen=True)
class Anonymous:
    """``^*`` (at least 0) or ``^+`` (at least 1): a count chosen for this node alone."""

    min: int


Count = Fixed | Named | Anonymous


@dataclass(frozen=True)
class Repeat:
    """``body ^ count``."""

    body: Node
    count: Count
    pos: int


Node = Sym | Seq | Alt | Repeat


def walk(node: Node) -> Iterator[Node]:
    """Every node of the tree, parents before children, in text order."""
    yield node
    if isinstance(node, Seq):
        for item in node.items:
            yield from walk(item)
    elif isinstance(node, Alt):
        for branch in node.branches:
            yield from walk(branch)
    elif isinstance(node, Repeat):
        yield from walk(node.body)


def symbols(node: Node) -> list[Sym]:
    """The symbol occurrences of a pattern, in text order."""
    return [n for n in walk(node) if isinstance(n, Sym)]


def named_counters(node: Node) -> list[Named]:
    """The named-counter occurrences of a pattern, in text order."""
    return [n.count for n in walk(node) if isinstance(n, Repeat) and isinstance(n.count, Named)]


def to_text(node: Node) -> str:
    """Canonical text of a pattern; parsing it gives the same tree (positions aside)."""
    if isinstance(node, Sym):
        return node.name
    if isinstance(node, Seq):
        return " ".join(_atom_text(item) for item in node.items)
    if isinstance(node, Alt):
        return " | ".join(to_text(b) for b in node.branches)
    return f"{_atom_text(node.body, repeat=True)}^{_count_text(node.count)}"


def _atom_text(node: Node, repeat: bool = False) -> str:
    if isinstance(node, Sym) or (isinstance(node, Repeat) and not repeat):
        return to_text(node)
    return f"({to_text(node)})"


def _count_text(count: Count) -> str:
    if isinstance(count, Fixed):
        return str(count.value)
    if isinstance(count, Named):
        return ("-" if count.reflect else "") + count.name
    return "*" if count.min == 0 else "+"
