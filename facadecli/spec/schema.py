"""The JSON Schema of the spec format, for editors (``facade schema``)."""

from __future__ import annotations

import json
from typing import Any

from facadecli.spec.model import Spec


def spec_schema() -> dict[str, Any]:
    """JSON Schema (draft 2020-12) of a spec file."""
    schema = Spec.model_json_schema(mode="validation")
    schema["$id"] = "https://facadecli.invalid/facade.schema.json"
    return schema


def spec_schema_text() -> str:
    """The schema as stable, pretty JSON text (what ``specs/facade.schema.json`` holds)."""
    return json.dumps(spec_schema(), indent=2, sort_keys=True, ensure_ascii=False) + "\n"
