"""The spec: model, loading with positions, cross-checks, JSON Schema."""

from facadecli.spec.load import load_spec, parse_spec, validate_spec
from facadecli.spec.model import Spec
from facadecli.spec.schema import spec_schema, spec_schema_text

__all__ = ["Spec", "load_spec", "parse_spec", "spec_schema", "spec_schema_text", "validate_spec"]
