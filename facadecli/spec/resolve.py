"""From a spec to compiled patterns: which text each layer uses on each axis, and where
in the file that text is (so errors can point into it)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

from facadecli.patterns import CompiledPattern, compile_pattern
from facadecli.spec.model import Layer, Spec, SubstitutedPattern
from facadecli.spec.source import Path

Axis = Literal["x", "y"]
AXES: tuple[Axis, Axis] = ("x", "y")


@dataclass(frozen=True)
class PatternText:
    """One piece of pattern text in a spec and where it is."""

    path: Path  # e.g. ('patterns', 'house_x') or ('layers', 1, 'x')
    text: str
    role: Literal["plain", "control", "content"]
    placeholder: str | None = None  # the `where` key, for a content pattern


def named_texts(spec: Spec, name: str) -> list[PatternText]:
    """The texts of the named pattern ``name``: itself, or its control and contents."""
    definition = spec.patterns[name]
    if isinstance(definition, str):
        return [PatternText(("patterns", name), definition, "plain")]
    texts = [PatternText(("patterns", name, "control"), definition.control, "control")]
    for placeholder, content in definition.where.items():
        path = ("patterns", name, "where", placeholder)
        texts.append(PatternText(path, content, "content", placeholder))
    return texts


def layer_reference(spec: Spec, index: int, axis: Axis) -> str | None:
    """The pattern name a layer uses on an axis, or None for an inline pattern."""
    value: str = getattr(spec.layers[index], axis)
    return value if value in spec.patterns else None


def layer_texts(spec: Spec, index: int, axis: Axis) -> list[PatternText]:
    """The texts behind a layer's word on one axis."""
    name = layer_reference(spec, index, axis)
    if name is not None:
        return named_texts(spec, name)
    text: str = getattr(spec.layers[index], axis)
    return [PatternText(("layers", index, axis), text, "plain")]


def compile_definition(definition: str | SubstitutedPattern) -> CompiledPattern:
    """Compile a pattern definition (raises PatternSyntaxError on bad text)."""
    if isinstance(definition, str):
        return _compile(definition, ())
    return _compile(definition.control, tuple(definition.where.items()))


def layer_pattern(spec: Spec, layer: Layer, axis: Axis) -> CompiledPattern:
    """The compiled pattern of a layer on an axis (the spec must have passed its checks)."""
    value: str = getattr(layer, axis)
    return compile_definition(spec.patterns.get(value, value))


@lru_cache(maxsize=4096)
def _compile(text: str, where: tuple[tuple[str, str], ...]) -> CompiledPattern:
    return compile_pattern(text, dict(where))
