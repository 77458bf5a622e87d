"""Pattern text -> AST (SPEC 2.2), with the offset of every error.

pattern := alt
alt     := seq ('|' seq)*
seq     := item*
item    := atom ('^' count)?
atom    := SYMBOL | '(' alt ')'
count   := INT | COUNTER | '-' INT | '-' COUNTER | '*' | '+'
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from facadecli.limits import COUNT_MAX
from facadecli.patterns.ast import Alt, Anonymous, Count, Fixed, Named, Node, Repeat, Seq, Sym

MAX_PATTERN_LENGTH = 10_000
MAX_NESTING = 64
MAX_FIXED_COUNT = COUNT_MAX

_TOKEN = re.compile(
    r"(?P<space>\s+)|(?P<name>[A-Za-z_][A-Za-z0-9_]*)|(?P<int>[0-9]+)|(?P<op>[()|^*+-])"
)


class PatternSyntaxError(ValueError):
    """A pattern that does not parse; ``offset`` is the character where it goes wrong."""

    def __init__(self, message: str, offset: int, hint: str = ""):
        super().__init__(message)
        self.message = message
        self.offset = offset
        self.hint = hint


@dataclass(frozen=True)
class _Token:
    kind: str  # "name", "int", or the operator character itself; "end" at the end
    text: str
    pos: int


def _tokenize(text: str) -> list[_Token]:
    tokens: list[_Token] = []
    pos = 0
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None:
            char = text[pos]
            raise PatternSyntaxError(
                f"unexpected character {char!r}",
                pos,
                "patterns use symbol names, spaces, ( ) | and ^ with a count",
            )
        kind = match.lastgroup or ""
        if kind != "space":
            tokens.append(_Token(match.group() if kind == "op" else kind, match.group(), pos))
        pos = match.end()
    tokens.append(_Token("end", "", len(text)))
    return tokens


class _Parser:
    def __init__(self, text: str):
        self.tokens = _tokenize(text)
        self.index = 0
        self.depth = 0

    @property
    def token(self) -> _Token:
        return self.tokens[self.index]

    def advance(self) -> _Token:
        token = self.token
        self.index += 1
        return token

    def parse(self) -> Node:
        if self.token.kind == "end":
            raise PatternSyntaxError(
                "the pattern is empty", 0, "write at least one symbol, e.g. 'A (B A)^k'"
            )
        node = self.alt()
        token = self.token
        if token.kind == ")":
            raise PatternSyntaxError(
                "unbalanced ')': no '(' opens it", token.pos, "remove it or add a matching '('"
            )
        if token.kind != "end":  # pragma: no cover - every other token is consumed by seq
            raise PatternSyntaxError(f"unexpected {token.text!r}", token.pos)
        return node

    def alt(self) -> Node:
        pos = self.token.pos
        branches = [self.seq()]
        while self.token.kind == "|":
            self.advance()
            branches.append(self.seq())
        return branches[0] if len(branches) == 1 else Alt(tuple(branches), pos)

    def seq(self) -> Node:
        pos = self.token.pos
        items: list[Node] = []
        while self.token.kind in ("name", "("):
            items.append(self.item())
        token = self.token
        if token.kind == "^":
            raise PatternSyntaxError(
                "'^' has nothing to repeat",
                token.pos,
                "put a symbol or a parenthesised group before '^', e.g. 'A^3' or '(A B)^k'",
            )
        if token.kind in ("int", "-", "*", "+"):
            raise PatternSyntaxError(
                f"unexpected {token.text!r}",
                token.pos,
                "counts follow '^', e.g. 'A^3'; symbol names start with a letter or '_'",
            )
        return items[0] if len(items) == 1 else Seq(tuple(items), pos)

    def item(self) -> Node:
        atom = self.atom()
        if self.token.kind != "^":
            return atom
        caret = self.advance()
        count = self.count(caret)
        if self.token.kind == "^":
            raise PatternSyntaxError(
                "a count cannot be repeated again",
                self.token.pos,
                "group it first, e.g. '(A^2)^3'",
            )
        return Repeat(atom, count, atom.pos)

    def atom(self) -> Node:
        token = self.advance()
        if token.kind == "name":
            return Sym(token.text, token.pos)
        # token.kind == "("
        self.depth += 1
        if self.depth > MAX_NESTING:
            raise PatternSyntaxError(
                f"parentheses nested deeper than {MAX_NESTING} levels", token.pos, "simplify"
            )
        node = self.alt()
        if self.token.kind != ")":
            raise PatternSyntaxError(
                "unbalanced '(': it is never closed", token.pos, "add a matching ')'"
            )
        self.advance()
        self.depth -= 1
        # keep the group's own position (its '(') so errors point at it
        if isinstance(node, Seq):
            return Seq(node.items, token.pos)
        if isinstance(node, Alt):
            return Alt(node.branches, token.pos)
        return node

    def count(self, caret: _Token) -> Count:
        token = self.advance()
        if token.pos != caret.pos + 1:
            token = _Token("end", "", token.pos)  # a count must follow '^' directly
        if token.kind == "*":
            return Anonymous(0)
        if token.kind == "+":
            return Anonymous(1)
        negative = token.kind == "-"
        if negative:
            sign, token = token, self.advance()
            if token.pos != sign.pos + 1:
                token = _Token("end", "", token.pos)
        if token.kind == "int":
            value = int(token.text)
            if value > MAX_FIXED_COUNT:
                raise PatternSyntaxError(
                    f"count {value} is too large",
                    token.pos,
                    f"use at most {MAX_FIXED_COUNT}, or a counter",
                )
            return Fixed(-value if negative else value)
        if token.kind == "name":
            return Named(token.text, negative, token.pos)
        raise PatternSyntaxError(
            "'^' needs a count after it",
            caret.pos,
            "write a number, a counter name, '-' and either for a reflection, '*' or '+', "
            "e.g. 'A^3', 'A^k', 'A^-1', 'A^*'",
        )


def parse_pattern(text: str) -> Node:
    """Parse pattern text into an AST; raises :class:`PatternSyntaxError`."""
    if len(text) > MAX_PATTERN_LENGTH:
        raise PatternSyntaxError(
            f"the pattern is {len(text)} characters long",
            MAX_PATTERN_LENGTH,
            f"keep it under {MAX_PATTERN_LENGTH}; use counters for repetition",
        )
    return _Parser(text).parse()
