"""facadecli: layered procedural façades from declarative YAML specs.

The public API; everything else is internal and may change.
"""

import facadecli._blas  # noqa: F401  (first: before anything loads numpy)
from facadecli.errors import FacadeError, InfeasibleError, Problem, SpecError
from facadecli.layout import Layout, Shape
from facadecli.patterns import Choice, Letter, Word, compile_pattern, enumerate_words, make_word
from facadecli.solve import retarget, solve
from facadecli.spec import Spec, load_spec, parse_spec, spec_schema, validate_spec

__version__ = "0.1.0"

__all__ = [
    "Choice",
    "FacadeError",
    "InfeasibleError",
    "Layout",
    "Letter",
    "Problem",
    "Shape",
    "Spec",
    "SpecError",
    "Word",
    "__version__",
    "compile_pattern",
    "enumerate_words",
    "load_spec",
    "make_word",
    "parse_spec",
    "retarget",
    "solve",
    "spec_schema",
    "validate_spec",
]
