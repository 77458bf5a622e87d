"""YAML with positions: every value of a document knows the line and column it came from.

PyYAML composes the document into nodes (which carry marks); we build plain Python data
from them ourselves, recording where each key and value was. Hostile input is refused
early: oversized files, alias bombs (the expanded document is bounded, however small the
text), recursive aliases, deep nesting, duplicate keys, and tags (on a scalar, all but
the core schema's ``!!str``, ``!!int``, ``!!float``, ``!!bool`` and ``!!null``).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import yaml

from facadecli.errors import Problem, SpecError
from facadecli.files import place
from facadecli.limits import SPEC_BYTES_MAX, SPEC_DEPTH_MAX, SPEC_VALUES_MAX

MAX_BYTES = SPEC_BYTES_MAX
MAX_NODES = SPEC_VALUES_MAX
MAX_DEPTH = SPEC_DEPTH_MAX

try:  # libyaml is about three times faster; the pure-Python loader gives the same nodes
    _Loader: type = yaml.CSafeLoader
except AttributeError:  # pragma: no cover - depends on how PyYAML was built
    _Loader = yaml.SafeLoader

_MERGE_TAG = "tag:yaml.org,2002:merge"
# the tags a list or a mapping may have: its own kind's, given or not
_PLAIN_TAGS: dict[type[yaml.Node], str] = {
    yaml.SequenceNode: "tag:yaml.org,2002:seq",
    yaml.MappingNode: "tag:yaml.org,2002:map",
}
_SCALAR_CONSTRUCTOR = yaml.constructor.SafeConstructor()
_RESOLVER = yaml.resolver.Resolver()  # the tag a scalar has when none is given
# the tags a scalar may be given: YAML's core schema (plain values, as when untagged)
_SCALAR_TAGS = frozenset(
    f"tag:yaml.org,2002:{name}" for name in ("str", "int", "float", "bool", "null")
)

Path = tuple[str | int, ...]


def format_path(path: Path) -> str:
    """``('layers', 1, 'x')`` -> ``layers[1].x``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


@dataclass
class SourceMap:
    """Where each value (and each mapping key) of a document is in its file."""

    file: str
    values: dict[Path, yaml.Node] = field(default_factory=dict)
    keys: dict[Path, yaml.Node] = field(default_factory=dict)

    def node(self, path: Path) -> yaml.Node | None:
        """The value node at ``path``, or at its longest prefix that has one."""
        for end in range(len(path), -1, -1):
            node = self.values.get(path[:end])
            if node is not None:
                return node
        return None

    def position(self, path: Path, key: bool = False) -> tuple[int | None, int | None]:
        """1-based (line, column) of the value at ``path`` (of its key with ``key=True``)."""
        node = self.keys.get(path) if key else None
        node = node or self.node(path)
        if node is None:
            return None, None
        return node.start_mark.line + 1, node.start_mark.column + 1

    def position_in(self, path: Path, offset: int) -> tuple[int | None, int | None]:
        """Position of character ``offset`` inside the string scalar at ``path``."""
        node = self.values.get(path)
        if not isinstance(node, yaml.ScalarNode):
            return self.position(path)
        line, col = node.start_mark.line + 1, node.start_mark.column + 1
        single_line = node.start_mark.line == node.end_mark.line
        if single_line and node.style in (None, "'", '"'):
            col += offset + (1 if node.style else 0)
        return line, col

    def problem(
        self, path: Path, message: str, hint: str = "", *, key: bool = False, offset: int = -1
    ) -> Problem:
        line, col = self.position_in(path, offset) if offset >= 0 else self.position(path, key)
        return Problem(self.file, line, col, message, hint)


@dataclass(frozen=True)
class Document:
    """A parsed YAML document: plain data and where each piece of it came from."""

    data: Any
    source: SourceMap


def read_document(raw: bytes, file: str) -> Document:
    """Parse one YAML document from bytes; raises :class:`SpecError` with positions."""
    if len(raw) > MAX_BYTES:
        line, col = place(raw, MAX_BYTES)
        raise SpecError.at(
            file,
            line,
            col,
            f"the file is longer than specs are limited to ({MAX_BYTES:,} bytes, the limit "
            "of a spec file or manifest): its first byte past the limit is here",
            "is this the right file? a spec is a page of YAML: generate repeated layers "
            "with patterns",
        )
    text = _decode(raw, file)
    if not text.strip() or _only_comments(text):
        raise SpecError.at(file, 1, 1, "the file is empty", "start from an example in specs/")
    try:
        root = yaml.compose(text, Loader=_loader_for(text))
    except yaml.MarkedYAMLError as error:
        raise _yaml_problem(error, file, text) from None
    except yaml.YAMLError as error:
        raise SpecError.at(
            file, 1, 1, f"invalid YAML: {error}", "check the file's syntax"
        ) from None
    except RecursionError:
        raise SpecError.at(
            file, 1, 1, "the document is nested too deeply", f"nest at most {MAX_DEPTH} levels"
        ) from None
    if root is None:
        raise SpecError.at(file, 1, 1, "the file is empty", "start from an example in specs/")
    source = SourceMap(file)
    builder = _Builder(source)
    data = builder.build(root, ())
    return Document(data, source)


def _loader_for(text: str) -> type:
    """libyaml, unless the text could nest deeply: libyaml's composer then overflows the C
    stack, while the pure-Python one stops with a RecursionError we report."""
    depth = deepest = 0
    for char in text:
        if char in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif char in "]}":
            depth -= 1
    if deepest > 4 * MAX_DEPTH:
        raise RecursionError
    # block nesting needs indentation, so it is bounded by the longest line
    longest = max(len(line) for line in text.splitlines())
    return yaml.SafeLoader if deepest > MAX_DEPTH or longest > 4 * MAX_DEPTH else _Loader


def _decode(raw: bytes, file: str) -> str:
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = raw.count(b"\n", 0, error.start) + 1
        col = error.start - (raw.rfind(b"\n", 0, error.start) + 1) + 1
        raise SpecError.at(
            file,
            line,
            col,
            "the file is not UTF-8 text (is it a binary file?)",
            "save the spec as UTF-8 YAML",
        ) from None
    bad = next((i for i, c in enumerate(text) if c == "\x00"), None)
    if bad is not None:
        line = text.count("\n", 0, bad) + 1
        col = bad - (text.rfind("\n", 0, bad) + 1) + 1
        raise SpecError.at(
            file,
            line,
            col,
            "the file contains NUL bytes (is it a binary file?)",
            "save the spec as UTF-8 YAML",
        )
    return text


def _only_comments(text: str) -> bool:
    return all(not line.strip() or line.lstrip().startswith("#") for line in text.splitlines())


def _yaml_problem(error: yaml.MarkedYAMLError, file: str, text: str = "") -> SpecError:
    mark = error.problem_mark or error.context_mark
    if mark is not None and text[mark.index : mark.index + 1] == "\t":
        error.problem = "found a tab character"
    what = error.problem or "invalid YAML"
    if error.context and error.problem:
        what = f"{error.context}: {error.problem}"
    hint = "check indentation, colons and quotes"
    if "tab character" in what:
        hint = "YAML forbids tabs for indentation: use spaces"
    elif "could not determine a constructor" in what:
        hint = "remove the '!' tag: specs hold plain values only"
    line = mark.line + 1 if mark else 1
    col = mark.column + 1 if mark else 1
    return SpecError.at(file, line, col, f"invalid YAML: {what}", hint)


def _untagged(node: yaml.ScalarNode) -> str:
    """The tag the scalar would have without one (a date's stays as YAML reads it)."""
    plain = not node.style  # None (PyYAML) or "" (libyaml)
    tag = _RESOLVER.resolve(yaml.ScalarNode, node.value, (plain, not plain))  # type: ignore[no-untyped-call]
    return str(tag)


def _shown_tag(tag: str) -> str:
    return tag.replace("tag:yaml.org,2002:", "!!")


class _Builder:
    """Builds plain data from nodes, recording positions, within a node budget."""

    def __init__(self, source: SourceMap):
        self.source = source
        self.count = 0
        self.active: set[int] = set()  # ids of collection nodes on the current path

    def fail(self, node: yaml.Node, message: str, hint: str) -> SpecError:
        mark = node.start_mark
        return SpecError.at(self.source.file, mark.line + 1, mark.column + 1, message, hint)

    def build(self, node: yaml.Node, path: Path) -> Any:
        self.count += 1
        if self.count > MAX_NODES:
            raise self.fail(
                node,
                f"the document expands to more than {MAX_NODES:,} values (an alias bomb?)",
                "use fewer anchors and aliases ('&name' / '*name')",
            )
        if len(path) > MAX_DEPTH:
            raise self.fail(node, "the document is nested too deeply", f"nest at most {MAX_DEPTH}")
        self.source.values.setdefault(path, node)
        if isinstance(node, yaml.ScalarNode):
            if node.tag not in _SCALAR_TAGS and node.tag != _untagged(node):
                raise self.fail(
                    node,
                    f"the value has the tag '{_shown_tag(node.tag)}': specs hold plain values "
                    "only (of the tags, !!str, !!int, !!float, !!bool and !!null)",
                    "remove the '!' tag",
                )
            try:
                return _SCALAR_CONSTRUCTOR.construct_object(node, deep=True)
            except yaml.MarkedYAMLError as error:
                raise _yaml_problem(error, self.source.file) from None
            except (ValueError, TypeError) as error:  # pragma: no cover - defensive
                raise self.fail(node, f"invalid value: {error}", "check the value") from None
        plain = _PLAIN_TAGS.get(type(node))
        if plain is not None and node.tag != plain:
            kind = "list" if isinstance(node, yaml.SequenceNode) else "mapping"
            raise self.fail(
                node,
                f"the {kind} has the tag '{_shown_tag(node.tag)}': specs hold plain values only",
                "remove the '!' tag",
            )
        if id(node) in self.active:
            raise self.fail(
                node, "a recursive alias: this value contains itself", "remove the alias"
            )
        self.active.add(id(node))
        try:
            if isinstance(node, yaml.SequenceNode):
                return [self.build(item, (*path, i)) for i, item in enumerate(node.value)]
            if isinstance(node, yaml.MappingNode):
                return self.mapping(node, path)
        finally:
            self.active.discard(id(node))
        raise self.fail(node, "unsupported YAML node", "use plain mappings, lists and scalars")

    def mapping(self, node: yaml.MappingNode, path: Path) -> dict[str, Any]:
        result: dict[str, Any] = {}
        first_seen: dict[str, yaml.Node] = {}
        merged: list[tuple[yaml.Node, yaml.Node]] = []
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE_TAG:
                merged.extend(self.merge_sources(value_node))
                continue
            key = self.key(key_node)
            if key in first_seen:
                first = first_seen[key].start_mark.line + 1
                raise self.fail(
                    key_node,
                    f"duplicate key '{key}' (first given on line {first})",
                    "keep one of them",
                )
            first_seen[key] = key_node
            self.source.keys[(*path, key)] = key_node
            result[key] = self.build(value_node, (*path, key))
        for key_node, value_node in merged:  # '<<: *base' fills in what is not given
            key = self.key(key_node)
            if key not in result:
                self.source.keys[(*path, key)] = key_node
                result[key] = self.build(value_node, (*path, key))
        return result

    def merge_sources(self, node: yaml.Node) -> Iterator[tuple[yaml.Node, yaml.Node]]:
        sources = node.value if isinstance(node, yaml.SequenceNode) else [node]
        for source in sources:
            if not isinstance(source, yaml.MappingNode):
                raise self.fail(source, "'<<' merges mappings only", "merge an anchored mapping")
            self.count += len(source.value)
            yield from source.value

    def key(self, node: yaml.Node) -> str:
        if not isinstance(node, yaml.ScalarNode):
            raise self.fail(node, "a mapping key must be a plain name", "use a name as the key")
        if node.tag not in _SCALAR_TAGS and node.tag != _untagged(node):
            raise self.fail(
                node,
                f"the key has the tag '{_shown_tag(node.tag)}': a key is a plain name",
                "remove the '!' tag",
            )
        # keys are names: keep their text, so 'on', 'no' or '1' stay names, not booleans
        return str(node.value)
