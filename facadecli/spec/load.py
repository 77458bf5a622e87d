"""Loading a spec: file -> YAML with positions -> model -> cross-checks.

Every problem, from the YAML parser, the model or the cross-checks, is reported as
``FILE:LINE:COL: error: WHAT (HOW TO FIX)`` through :class:`SpecError`.
"""

from __future__ import annotations

import types
import typing
from pathlib import Path as FilePath
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError
from pydantic_core import ErrorDetails

from facadecli.errors import Problem, SpecError
from facadecli.files import read_prefix
from facadecli.hints import did_you_mean
from facadecli.limits import COUNT_MAX, LENGTH_MAX, SPEC_BYTES_MAX
from facadecli.spec.check import checked
from facadecli.spec.model import Spec
from facadecli.spec.source import Path, SourceMap, format_path, read_document

_HINTS = {
    "missing": "add it",
    "float_type": "write a number, e.g. 1.5",
    "int_type": "write a whole number, e.g. 3",
    "bool_type": "write true or false",
    "string_type": "write text; quote it if it looks like a number or a boolean",
    "dict_type": "write a mapping of 'key: value' lines",
    "model_type": "write a mapping of 'key: value' lines",
    "list_type": "write a list, e.g. [A, B]",
    "greater_than": "use a positive value",
    "greater_than_equal": "use a value that is not negative",
    "less_than_equal": "use a smaller value",
    "too_short": "add at least one entry",
    "literal_error": "use one of the allowed values",
    "finite_number": "use a finite number",
    "value_error": "fix the values so they agree",
}
_LIMIT_HINTS = {  # a bound that is one of the limits: the hint names it
    LENGTH_MAX: f"the limit of a length: at most {LENGTH_MAX:,g} m either way",
    COUNT_MAX: f"the limit of a count: at most {COUNT_MAX:,}",
}
_NAME_HINT = "names start with a letter or '_', then letters, digits or '_'"


def load_spec(path: str | FilePath) -> Spec:
    """Read, validate and cross-check a spec file; raises :class:`SpecError`."""
    file = FilePath(path)
    try:
        raw = read_prefix(file, SPEC_BYTES_MAX)  # past the limit: read_document says where
    except FileNotFoundError:
        raise SpecError.at(str(path), None, None, "no such file", "check the path") from None
    except IsADirectoryError:
        raise SpecError.at(
            str(path), None, None, "is a folder, not a spec file", "name a .yaml file"
        ) from None
    except OSError as error:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"cannot read: {error.strerror}",
            "check the path and its permissions",
        ) from None
    return parse_spec(raw, str(path), base_dir=file.parent)


def parse_spec(raw: bytes | str, file: str = "<spec>", base_dir: FilePath | None = None) -> Spec:
    """Validate a spec given as YAML text; ``file`` names it in error messages."""
    data = raw.encode() if isinstance(raw, str) else raw
    document = read_document(data, file)
    return validate_spec(document.data, document.source, base_dir)


def validate_spec(
    data: Any, source: SourceMap | None = None, base_dir: FilePath | None = None
) -> Spec:
    """Validate plain data (e.g. parsed YAML) as a spec; raises :class:`SpecError`."""
    source = source or SourceMap("<spec>")
    spec = validate_model(Spec, data, source, "version, name, canvas, ...")
    problems, warnings = checked(spec, source, base_dir)
    if problems:
        raise SpecError(problems)
    spec._warnings = tuple(warnings)  # the layout's report and the command line tell them
    return spec


ModelT = TypeVar("ModelT", bound=BaseModel)


def validate_model(model: type[ModelT], data: Any, source: SourceMap, keys: str) -> ModelT:
    """Validate a YAML document as ``model``; every problem is positioned in its file."""
    if not isinstance(data, dict):
        kind = type(data).__name__ if data is not None else "nothing"
        raise SpecError(
            [
                source.problem(
                    (),
                    f"the file must be a mapping of keys ({keys}), not {kind}",
                    "start from an example in the README",
                )
            ]
        )
    try:
        return model.model_validate(data)
    except ValidationError as error:
        raise SpecError(_model_problem(e, data, source, model) for e in error.errors()) from None


def _model_problem(
    error: ErrorDetails, data: Any, source: SourceMap, model: type[BaseModel]
) -> Problem:
    path = _data_path(error["loc"], data)
    kind = error["type"]
    where = format_path(path)
    if kind == "extra_forbidden":
        key = str(error["loc"][-1])
        allowed = _allowed_keys(error["loc"][:-1], model)
        hint = did_you_mean(key, allowed) + (
            "allowed keys: " + ", ".join(allowed) if allowed else "remove it"
        )
        parent = format_path(path[:-1])
        return source.problem(
            path, f"unknown key '{key}'" + (f" in {parent}" if parent else ""), hint, key=True
        )
    if kind == "missing":
        key = str(error["loc"][-1])
        path = path[:-1] if path and path[-1] == key else path
        parent = format_path(path)
        return source.problem(
            path,
            f"missing required key '{key}'" + (f" in {parent}" if parent else ""),
            f"add '{key}: ...'",
        )
    message = error["msg"]
    if kind == "value_error":
        message = message.removeprefix("Value error, ")
    if kind in ("string_type", "float_type", "int_type", "bool_type") and "input" in error:
        message += f", got {error['input']!r}"
    hint = _HINTS.get(kind, "see the spec reference in the README")
    bound = error.get("ctx", {}).get("le", error.get("ctx", {}).get("ge"))
    if kind in ("less_than_equal", "greater_than_equal") and isinstance(bound, (int, float)):
        hint = _LIMIT_HINTS.get(abs(bound), hint)
    if kind == "string_pattern_mismatch":
        hint = (
            _NAME_HINT
            if "A-Za-z_" in str(error.get("ctx", {}))
            else (
                "use letters, digits, '_', '.' or '-'"
                if "A-Za-z0-9_.-" in str(error.get("ctx"))
                else 'write a colour as "#rrggbb"'
            )
        )
    if kind == "literal_error" and path == ("version",):
        message, hint = "unsupported version", "write 'version: 1'"
    return source.problem(path, f"{where}: {message}" if where else message, hint)


def _data_path(loc: tuple[int | str, ...], data: Any) -> Path:
    """The error's location in the data, without pydantic's union tags (e.g. 'substituted')."""
    path: list[str | int] = []
    node = data
    for part in loc:
        in_dict = isinstance(node, dict) and part in node
        in_list = isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node)
        if in_dict or in_list:
            node = node[part]
        elif isinstance(node, dict) and part not in node and part == loc[-1]:
            pass  # a missing or unknown key: keep it so the message can name it
        else:
            continue
        path.append(part)
    return tuple(path)


def _allowed_keys(loc: tuple[int | str, ...], root: type[BaseModel]) -> list[str]:
    """Field names of the model found at ``loc`` (following lists, dicts and unions)."""
    candidates: list[Any] = [root]
    for part in loc:
        advanced: list[Any] = []
        for leaf in (leaf for c in candidates for leaf in _leaves(c)):
            if isinstance(leaf, type) and issubclass(leaf, BaseModel):
                if isinstance(part, str) and part in leaf.model_fields:
                    advanced.append(leaf.model_fields[part].annotation)
            elif typing.get_origin(leaf) is list and isinstance(part, int):
                advanced.append(typing.get_args(leaf)[0])
            elif typing.get_origin(leaf) is dict and isinstance(part, str):
                advanced.append(typing.get_args(leaf)[1])
        if advanced:
            candidates = advanced  # else the part was a union tag: stay where we are
    names: list[str] = []
    for leaf in (leaf for c in candidates for leaf in _leaves(c)):
        if isinstance(leaf, type) and issubclass(leaf, BaseModel):
            names.extend(n for n in leaf.model_fields if n not in names)
    return names


def _leaves(annotation: Any) -> list[Any]:
    """Unwrap Annotated, Optional and unions down to concrete types."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _leaves(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return [leaf for arg in typing.get_args(annotation) for leaf in _leaves(arg)]
    return [annotation]
