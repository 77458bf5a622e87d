"""Checks that need the whole spec: names that must exist, rules across patterns and axes.

Each check returns problems positioned in the file (when the spec came from one), so a
user sees every mistake at once, each with a way to fix it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path as FilePath

from facadecli.errors import Problem
from facadecli.hints import closest, did_you_mean, split_into
from facadecli.patterns import PatternSyntaxError, parse_pattern
from facadecli.patterns.ast import Named, Node, Repeat, Sym, named_counters, symbols, walk
from facadecli.spec.assets import mesh_problem, texture_problem
from facadecli.spec.model import BUILTIN_MESHES, ShapeRule, Spec
from facadecli.spec.resolve import (
    AXES,
    Axis,
    PatternText,
    layer_reference,
    layer_texts,
    named_texts,
)
from facadecli.spec.source import Path, SourceMap

MESH_SUFFIXES = (".glb", ".gltf", ".obj", ".stl", ".ply")
TEXTURE_SUFFIXES = (".png", ".jpg", ".jpeg")


class Checker:
    """Runs every cross-check of a spec; ``problems`` collects what it finds."""

    def __init__(self, spec: Spec, source: SourceMap | None, base_dir: FilePath | None):
        self.spec = spec
        self.source = source or SourceMap("<spec>")
        self.base_dir = base_dir
        self.problems: list[Problem] = []
        self.warnings: list[Problem] = []  # what is used as written but reads wrong
        self.parsed: dict[Path, Node | None] = {}
        self.file_problems: dict[FilePath, str | None] = {}  # each file is read once

    def report(
        self, path: Path, message: str, hint: str = "", *, key: bool = False, offset: int = -1
    ) -> None:
        self.problems.append(self.source.problem(path, message, hint, key=key, offset=offset))

    def warn(self, path: Path, message: str, hint: str) -> None:
        problem = self.source.problem(path, message, hint)
        self.warnings.append(replace(problem, severity="warning"))

    def run(self) -> list[Problem]:
        for name in self.spec.patterns:
            self.check_named_pattern(name)
        self.check_layers()
        self.check_counter_axes()
        self.check_appearance()
        self.check_glass()
        return self.problems

    # -- patterns ---------------------------------------------------------------------
    def parse(self, text: PatternText) -> Node | None:
        if text.path not in self.parsed:
            try:
                self.parsed[text.path] = parse_pattern(text.text)
            except PatternSyntaxError as error:
                self.parsed[text.path] = None
                self.report(
                    text.path,
                    f"{_describe(text)}: {error.message}",
                    error.hint,
                    offset=error.offset,
                )
        return self.parsed[text.path]

    def check_named_pattern(self, name: str) -> None:
        texts = named_texts(self.spec, name)
        trees = [self.parse(text) for text in texts]
        if texts[0].role == "control":
            self.check_substitution(texts, trees)
        for text, tree in zip(texts, trees, strict=True):
            if tree is not None:
                self.check_symbols(text, tree)
                self.check_counters_declared(text, tree)

    def check_substitution(self, texts: list[PatternText], trees: list[Node | None]) -> None:
        control, control_tree = texts[0], trees[0]
        placeholders = {text.placeholder for text in texts[1:]}
        if control_tree is not None:
            used = {sym.name for sym in symbols(control_tree)}
            for placeholder in sorted(p for p in placeholders if p and p not in used):
                self.report(
                    (*control.path[:-1], "where", placeholder),
                    f"placeholder '{placeholder}' is not used by the control pattern "
                    f"'{control.text}'",
                    f"use '{placeholder}' in the control pattern or remove it from 'where'",
                    key=True,
                )
        for placeholder in sorted(p for p in placeholders if p):
            declared = self.spec.symbols.get(placeholder)
            if declared is not None and declared.size is not None:
                self.report(
                    ("symbols", placeholder, "size"),
                    f"placeholder '{placeholder}' has a size",
                    "remove it: a placeholder takes the length of its content word",
                )
        for text, tree in zip(texts[1:], trees[1:], strict=True):
            for sym in symbols(tree) if tree is not None else []:
                if sym.name not in placeholders:
                    continue
                kind = "itself" if sym.name == text.placeholder else f"placeholder '{sym.name}'"
                self.report(
                    text.path,
                    f"the content of '{text.placeholder}' contains {kind}: substitutions "
                    "are applied once and cannot nest",
                    f"write the content of '{sym.name}' out in full instead of naming it",
                    offset=sym.pos,
                )

    def check_symbols(self, text: PatternText, tree: Node) -> None:
        if text.role == "control":
            return  # anything goes: undeclared names are transparent, elastic placeholders
        placeholders = self.placeholders_of(text)
        for sym in symbols(tree):
            if sym.name in placeholders:
                continue  # reported by check_substitution
            declared = self.spec.symbols.get(sym.name)
            if declared is None:
                self.report(
                    text.path,
                    f"{_describe(text)}: unknown symbol '{sym.name}'",
                    self.symbol_hint(sym.name),
                    offset=sym.pos,
                )
            elif declared.size is None:
                self.report(
                    text.path,
                    f"{_describe(text)}: symbol '{sym.name}' has no size; unsized symbols "
                    "are only allowed in the control pattern of a substituted pattern",
                    f"give it a preferred size under symbols, e.g. '{sym.name}: 1.0'",
                    offset=sym.pos,
                )

    def placeholders_of(self, text: PatternText) -> set[str]:
        if text.role != "content":
            return set()
        definition = self.spec.patterns[str(text.path[1])]
        return set(getattr(definition, "where", {}))

    def symbol_hint(self, name: str) -> str:
        known = sorted(self.spec.symbols)
        split = split_into(name, set(known))
        if split:
            return f"did you mean '{' '.join(split)}'? symbols are separated by spaces"
        close = closest(name, known)
        if close is not None:
            return f"did you mean '{close}'? or declare '{name}' under symbols"
        return f"declare it under symbols, e.g. '{name}: 1.0'"

    def check_counters_declared(self, text: PatternText, tree: Node) -> None:
        for counter in named_counters(tree):
            if counter.name in self.spec.counters:
                continue
            hint = did_you_mean(counter.name, self.spec.counters)
            self.report(
                text.path,
                f"{_describe(text)}: unknown counter '{counter.name}'",
                hint
                + f"declare it under counters, e.g. 'counters: {{{counter.name}: {{min: 1}}}}'",
                offset=counter.pos,
            )

    # -- layers -----------------------------------------------------------------------
    def check_layers(self) -> None:
        seen: dict[str, int] = {}
        for index, layer in enumerate(self.spec.layers):
            if layer.name in seen:
                self.report(
                    ("layers", index, "name"),
                    f"duplicate layer name '{layer.name}' (also layer {seen[layer.name]})",
                    "give every layer its own name",
                )
            seen.setdefault(layer.name, index)
            for axis in AXES:
                self.check_layer_axis(index, axis)
            for rule_index, rule in enumerate(layer.shapes):
                self.check_rule(("layers", index, "shapes", rule_index), rule)

    def check_layer_axis(self, index: int, axis: Axis) -> None:
        if layer_reference(self.spec, index, axis) is None:  # inline; named ones are checked once
            text = layer_texts(self.spec, index, axis)[0]
            tree = self.parse(text)
            if tree is None:
                return
            if isinstance(tree, Sym) and tree.name not in self.spec.symbols:
                self.report_unknown_pattern(text, tree.name)
                return
            self.check_symbols(text, tree)
            self.check_counters_declared(text, tree)
        mask = self.spec.layers[index].visible
        visible = getattr(mask, axis) if mask is not None else None
        if visible is not None:
            texts = layer_texts(self.spec, index, axis)
            used = {sym.name for text in texts for sym in self.symbols_of(text)}
            self.check_mask(index, axis, visible, used)

    def report_unknown_pattern(self, text: PatternText, name: str) -> None:
        close = closest(name, self.spec.patterns)
        hint = (
            f"did you mean '{close}'?"
            if close is not None
            else ("name one of: " + ", ".join(sorted(self.spec.patterns)) + ", or write a pattern")
        )
        self.report(text.path, f"unknown pattern '{name}'", hint)

    def symbols_of(self, text: PatternText) -> list[Sym]:
        tree = self.parse(text)
        return symbols(tree) if tree is not None else []

    def check_mask(self, index: int, axis: Axis, visible: list[str], used: set[str]) -> None:
        for position, name in enumerate(visible):
            if name not in used:
                self.report(
                    ("layers", index, "visible", axis, position),
                    f"mask symbol '{name}' does not occur in this layer's {axis} pattern",
                    "list symbols of the pattern: " + ", ".join(sorted(used)),
                )

    def check_counter_axes(self) -> None:
        first_axis: dict[str, tuple[Axis, str]] = {}
        for index, layer in enumerate(self.spec.layers):
            for axis in AXES:
                for text in layer_texts(self.spec, index, axis):
                    for counter in self.counters_in(text):
                        where = f"layer '{layer.name}'"
                        seen = first_axis.setdefault(counter.name, (axis, where))
                        if seen[0] != axis:
                            self.report(
                                text.path,
                                f"counter '{counter.name}' is used on both axes: by the {seen[0]} "
                                f"pattern of {seen[1]} and by the {axis} pattern of {where}",
                                "the axes are solved apart: use a separate counter for each",
                                offset=counter.pos,
                            )

    def counters_in(self, text: PatternText) -> Iterator[Named]:
        tree = self.parse(text)
        if tree is not None:
            for node in walk(tree):
                if isinstance(node, Repeat) and isinstance(node.count, Named):
                    yield node.count

    # -- appearance -------------------------------------------------------------------
    def check_appearance(self) -> None:
        from facadecli.materials.library import LIBRARY  # it builds on the spec's model

        for index, rule in enumerate(self.spec.shapes):
            self.check_rule(("shapes", index), rule)
        for name, material in self.spec.materials.items():
            if material.library is not None and material.library not in LIBRARY:
                self.report(
                    ("materials", name, "library"),
                    f"unknown library material '{material.library}'",
                    did_you_mean(material.library, LIBRARY)
                    + f"the library has {', '.join(LIBRARY)}",
                )
            if material.texture is not None:
                self.check_file(
                    ("materials", name, "texture"), material.texture, TEXTURE_SUFFIXES, "texture"
                )
        defaults = self.spec.defaults
        if defaults.material is not None:
            self.check_material(("defaults", "material"), defaults.material)
        self.check_mesh(("defaults", "mesh"), defaults.mesh)

    def check_glass(self) -> None:
        """A glass that lets less than :data:`GLASS_LEAST` of the light through in some
        channel darkens and tints the rooms drawn behind it: a warning at its colour (or
        its transmission, when that is what dims it)."""
        from facadecli.materials.library import GLASS_LEAST, LIBRARY, finished, light_through

        for name, declared in self.spec.materials.items():
            if declared.library is not None and declared.library not in LIBRARY:
                continue  # reported as unknown
            material = finished(declared)
            if material.transmission <= 0:
                continue
            through = light_through(material)
            if min(through) >= GLASS_LEAST:
                continue
            fields = declared.model_fields_set
            set_here = [key for key in ("color", "transmission") if key in fields]
            shares = " / ".join(f"{round(100 * share)}%" for share in through)
            self.warn(
                ("materials", name, *set_here[:1]),
                f"glass '{name}' lets {shares} of the red / green / blue light through "
                f"(less than {GLASS_LEAST:.0%} in a channel): the rooms behind it read dark "
                "and tinted",
                "use the library's float glass ('library: float-glass', #dde6e4, 72% / 79% "
                "/ 78%), or a paler colour",
            )

    def check_rule(self, path: Path, rule: ShapeRule) -> None:
        for axis in AXES:
            name = getattr(rule.match, axis)
            if name != "*" and name not in self.spec.symbols:
                self.report(
                    (*path, "match", axis),
                    f"shape rule matches unknown symbol '{name}'",
                    self.symbol_hint(name) + "; or '*' for any symbol",
                )
        if rule.material is not None:
            self.check_material((*path, "material"), rule.material)
        if rule.pane_material is not None and rule.pane_material != "glass":
            self.check_material((*path, "pane_material"), rule.pane_material)
        if rule.mesh is not None:
            self.check_mesh((*path, "mesh"), rule.mesh)

    def check_material(self, path: Path, name: str) -> None:
        from facadecli.materials.library import LIBRARY

        if name in self.spec.materials or name in LIBRARY:
            return
        hint = did_you_mean(name, [*self.spec.materials, *LIBRARY])
        self.report(
            path,
            f"unknown material '{name}'",
            hint + f"define it under materials, e.g. '{name}: {{color: \"#c9a27e\"}}', "
            f"or name a library material ({', '.join(LIBRARY)})",
        )

    def check_mesh(self, path: Path, mesh: str) -> None:
        if mesh in BUILTIN_MESHES:
            return
        candidate = FilePath(mesh)
        if candidate.suffix.lower() not in MESH_SUFFIXES:
            hint = did_you_mean(mesh, BUILTIN_MESHES)
            self.report(
                path,
                f"unknown mesh '{mesh}'",
                hint + f"use one of {', '.join(BUILTIN_MESHES)}, or a path to a "
                f"{'/'.join(MESH_SUFFIXES)} file next to the spec",
            )
            return
        self.check_file(path, mesh, MESH_SUFFIXES, "mesh")

    def check_file(self, path: Path, value: str, suffixes: tuple[str, ...], kind: str) -> None:
        """A file named in the spec: of a known kind, inside the spec's folder, present,
        readable as its kind and within the limits (:mod:`facadecli.spec.assets`)."""
        if any(ord(c) < 32 for c in value):
            self.report(
                path,
                f"{kind} path {value!r} holds a control character",
                "write the file name without NUL, tab or line breaks",
            )
            return
        candidate = FilePath(value)
        if candidate.suffix.lower() not in suffixes:
            self.report(
                path,
                f"{kind} '{value}' is not a {'/'.join(suffixes)} file",
                f"name a {'/'.join(suffixes)} file next to the spec",
            )
            return
        if candidate.is_absolute() or ".." in candidate.parts:
            self.report(
                path,
                f"{kind} path '{value}' leaves the spec's folder",
                "use a path relative to the spec file, inside its folder",
            )
            return
        if self.base_dir is None:
            return
        try:
            base = self.base_dir.resolve()
            resolved = (base / candidate).resolve()
            if not resolved.is_relative_to(base):
                self.report(
                    path,
                    f"{kind} path '{value}' leaves the spec's folder (through a link)",
                    f"copy the {kind} into the spec's folder",
                )
            elif not resolved.is_file():
                self.report(
                    path,
                    f"{kind} file '{value}' does not exist",
                    f"put it at {resolved} or fix the path (relative to the spec file)",
                )
            else:
                if resolved not in self.file_problems:
                    check = mesh_problem if kind == "mesh" else texture_problem
                    self.file_problems[resolved] = check(resolved)
                problem = self.file_problems[resolved]
                if problem is not None:
                    self.report(
                        path,
                        f"{kind} file '{value}' {problem}",
                        f"export the {kind} again, lighter, or name another file",
                    )
        except OSError as error:
            self.report(
                path,
                f"{kind} file '{value}' cannot be read: {error.strerror or error}",
                "check the path and its permissions",
            )


def _describe(text: PatternText) -> str:
    label = "pattern" if text.path[0] == "patterns" else "layer"
    name = text.path[1]
    if text.path[0] == "layers":
        return f"layer {name} {text.path[2]} pattern"
    if text.role == "control":
        return f"{label} '{name}' control"
    if text.role == "content":
        return f"{label} '{name}' content of '{text.placeholder}'"
    return f"{label} '{name}'"


def check_spec(
    spec: Spec, source: SourceMap | None = None, base_dir: FilePath | None = None
) -> list[Problem]:
    """Every cross-check problem of a spec (empty when it is valid)."""
    return checked(spec, source, base_dir)[0]


def checked(
    spec: Spec, source: SourceMap | None = None, base_dir: FilePath | None = None
) -> tuple[list[Problem], list[Problem]]:
    """Every cross-check problem of a spec, and every warning: what is used as written
    but reads wrong (a glass that darkens the rooms behind it)."""
    checker = Checker(spec, source, base_dir)
    return checker.run(), checker.warnings
