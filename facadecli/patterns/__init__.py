"""The pattern language (SPEC 2.2, 2.3): text -> AST -> words."""

from facadecli.patterns.ast import (
    Alt,
    Anonymous,
    Count,
    Fixed,
    Named,
    Node,
    Repeat,
    Seq,
    Sym,
)
from facadecli.patterns.parse import PatternSyntaxError, parse_pattern
from facadecli.patterns.words import (
    Choice,
    CompiledPattern,
    Enumerated,
    Letter,
    Word,
    compile_pattern,
    enumerate_words,
    format_word,
    length_range,
    make_word,
    mirror,
)

__all__ = [
    "Alt",
    "Anonymous",
    "Choice",
    "CompiledPattern",
    "Count",
    "Enumerated",
    "Fixed",
    "Letter",
    "Named",
    "Node",
    "PatternSyntaxError",
    "Repeat",
    "Seq",
    "Sym",
    "Word",
    "compile_pattern",
    "enumerate_words",
    "format_word",
    "length_range",
    "make_word",
    "mirror",
    "parse_pattern",
]
