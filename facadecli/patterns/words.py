"""Words from patterns: one word for a choice, or every word within a length budget.

A *choice* fixes every free decision of a pattern: the value of each named counter, the
branch of each alternation and the count of each anonymous counter (``^*``, ``^+``).
Alternations and anonymous counters are chosen once per node: every repetition of
``(A | B)^3`` takes the same branch, just as every occurrence of a placeholder takes the
same content word (SPEC 2.3). This keeps words regular, as façades are, and keeps a word's
preferred length affine in each counter.

Keys of a choice: a named counter by its name; an alternation ``alt#I`` and an anonymous
counter ``rep#I`` by the pre-order index I of its node, prefixed ``P/`` inside the content
of placeholder P.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

from facadecli.patterns.ast import Alt, Anonymous, Fixed, Named, Node, Repeat, Seq, Sym, walk
from facadecli.patterns.parse import PatternSyntaxError, parse_pattern

EPS = 1e-9


class Letter(NamedTuple):
    """One letter of a word: a symbol occurrence with its flags. A named tuple, so that a
    word (a tuple of letters) hashes at C speed: the solver keys its tables by words."""

    symbol: str
    reflected: bool = False
    transparent: bool = False
    placeholder: str | None = None  # the placeholder whose content it came from


Word = tuple[Letter, ...]


@dataclass(frozen=True)
class Choice:
    """Values of a pattern's free decisions, e.g. ``{"k": 3, "alt#2": 1}``."""

    values: tuple[tuple[str, int], ...] = ()

    @classmethod
    def of(cls, values: Mapping[str, int]) -> Choice:
        return cls(tuple(sorted(values.items())))

    def as_dict(self) -> dict[str, int]:
        return dict(self.values)

    @property
    def counters(self) -> dict[str, int]:
        """Named counters only (the values shared with other patterns)."""
        return {k: v for k, v in self.values if "#" not in k}


@dataclass(frozen=True)
class CompiledPattern:
    """A plain pattern (no contents) or a substituted one (control + contents)."""

    root: Node
    contents: Mapping[str, Node] = field(default_factory=dict)

    @property
    def substituted(self) -> bool:
        return bool(self.contents)

    def keys(self) -> dict[int, str]:
        """Choice key of every alternation and anonymous repeat, by node identity."""
        keys: dict[int, str] = {}
        for scope, root in (("", self.root), *self.contents.items()):
            prefix = f"{scope}/" if scope else ""
            for index, node in enumerate(walk(root)):
                if isinstance(node, Alt):
                    keys[id(node)] = f"{prefix}alt#{index}"
                elif isinstance(node, Repeat) and isinstance(node.count, Anonymous):
                    keys[id(node)] = f"{prefix}rep#{index}"
        return keys

    def counter_names(self) -> frozenset[str]:
        return self._counter_names

    @cached_property
    def _counter_names(self) -> frozenset[str]:  # a pattern's words ask for them often
        return frozenset(
            node.count.name
            for root in (self.root, *self.contents.values())
            for node in walk(root)
            if isinstance(node, Repeat) and isinstance(node.count, Named)
        )


class PatternSourceError(PatternSyntaxError):
    """A syntax error in one part of a substituted pattern (``placeholder`` names it)."""

    def __init__(self, error: PatternSyntaxError, placeholder: str | None):
        super().__init__(error.message, error.offset, error.hint)
        self.placeholder = placeholder


def compile_pattern(text: str, where: Mapping[str, str] | None = None) -> CompiledPattern:
    """Parse a plain pattern, or a control pattern with its ``where`` contents."""
    try:
        root = parse_pattern(text)
    except PatternSyntaxError as error:
        raise PatternSourceError(error, None) from None
    contents: dict[str, Node] = {}
    for placeholder, content in (where or {}).items():
        try:
            contents[placeholder] = parse_pattern(content)
        except PatternSyntaxError as error:
            raise PatternSourceError(error, placeholder) from None
    return CompiledPattern(root, contents)


@dataclass(frozen=True)
class Frame:
    """A piece of pattern still to expand: the node, whose content it is, and its mirroring."""

    node: Node
    scope: str  # "" for the pattern itself, else the placeholder whose content this is
    reflect: bool


Stack = tuple[Frame, "Stack"] | None  # a linked list: O(1) push and pop while backtracking


@dataclass(frozen=True)
class Enumerated:
    """A word the enumerator yields, with the choice that makes it and its length."""

    choice: Choice
    word: Word
    length: float  # sum of the preferred sizes of its sized letters
    elastic: bool  # it has unsized letters, so it can stretch to any longer canvas


class _Expander:
    """Shared machinery of :func:`make_word` and :func:`enumerate_words`."""

    def __init__(
        self,
        pattern: CompiledPattern,
        sizes: Mapping[str, float | None],
        transparent: frozenset[str],
        counters: Mapping[str, tuple[int, int | None]],
        max_length: float,
        max_letters: int,
    ):
        self.pattern = pattern
        self.sizes = sizes
        self.transparent = transparent
        self.counters = counters
        self.max_length = max_length
        self.max_letters = max_letters
        self.keys = pattern.keys()
        self.letters: dict[tuple[int, str, bool], Letter] = {}
        self.frames: dict[tuple[int, str, bool], tuple[Frame, ...]] = {}
        self.settled: dict[tuple[int, str, bool], tuple[Word, tuple[float, ...]] | None] = {}

    # -- lower bounds over what is still to expand -------------------------------------
    def minimum(self, node: Node, scope: str, env: Mapping[str, int]) -> tuple[float, int]:
        """Least (length, letter count) that ``node`` can still produce under ``env``."""
        if isinstance(node, Sym):
            if not scope and node.name in self.pattern.contents:
                return self.minimum(self.pattern.contents[node.name], node.name, env)
            return (self.sizes.get(node.name) or 0.0, 1)
        if isinstance(node, Seq):
            length, letters = 0.0, 0
            for item in node.items:
                item_length, item_letters = self.minimum(item, scope, env)
                length += item_length
                letters += item_letters
            return length, letters
        if isinstance(node, Alt):
            chosen = env.get(self.keys[id(node)])
            branches = node.branches if chosen is None else (node.branches[chosen],)
            bounds = [self.minimum(b, scope, env) for b in branches]
            return min(b[0] for b in bounds), min(b[1] for b in bounds)
        count = self.count_floor(node, scope, env)
        length, letters = self.minimum(node.body, scope, env)
        return count * length, count * letters

    def count_floor(self, node: Repeat, scope: str, env: Mapping[str, int]) -> int:
        count = node.count
        if isinstance(count, Fixed):
            return abs(count.value)
        key = self.count_key(node, scope)
        if key in env:
            return env[key]
        if isinstance(count, Named):
            return self.counters[count.name][0]
        return count.min

    def count_key(self, node: Repeat, scope: str) -> str:
        if isinstance(node.count, Named):
            return node.count.name
        return self.keys[id(node)]

    def stack_minimum(self, stack: Stack, env: Mapping[str, int]) -> tuple[float, int]:
        length, letters = 0.0, 0
        seen: dict[int, tuple[float, int]] = {}  # repeats push one frame object many times
        while stack is not None:
            frame, stack = stack
            bound = seen.get(id(frame))
            if bound is None:
                bound = seen[id(frame)] = self.minimum(frame.node, frame.scope, env)
            length += bound[0]
            letters += bound[1]
        return length, letters

    def fits(self, stack: Stack, env: Mapping[str, int], length: float, n: int) -> bool:
        rest_length, rest_letters = self.stack_minimum(stack, env)
        return (
            length + rest_length <= self.max_length + EPS and n + rest_letters <= self.max_letters
        )

    # -- expansion ----------------------------------------------------------------------
    def expand(
        self, stack: Stack, env: dict[str, int], out: list[Letter], length: float
    ) -> Iterator[tuple[dict[str, int], Word, float]]:
        """Depth-first over the choices. ``stack`` is a linked list of what is left to
        expand; ``out`` holds the letters so far and is restored before returning."""
        mark = len(out)
        try:
            while stack is not None:
                frame, stack = stack
                node = frame.node
                if isinstance(node, Sym):
                    if not frame.scope and node.name in self.pattern.contents:
                        content = self.pattern.contents[node.name]
                        stack = (Frame(content, node.name, frame.reflect), stack)
                        continue
                    out.append(self.letter(node, frame))
                    length += self.sizes.get(node.name) or 0.0
                    if length > self.max_length + EPS or len(out) > self.max_letters:
                        return
                elif isinstance(node, Seq):
                    for child in self.children(node, frame):
                        stack = (child, stack)
                elif isinstance(node, Alt):
                    key = self.keys[id(node)]
                    if key in env:
                        stack = (Frame(node.branches[env[key]], frame.scope, frame.reflect), stack)
                        continue
                    for index, branch in enumerate(node.branches):
                        branch_env = {**env, key: index}
                        branch_stack = (Frame(branch, frame.scope, frame.reflect), stack)
                        if self.fits(branch_stack, branch_env, length, len(out)):
                            yield from self.expand(branch_stack, branch_env, out, length)
                    return
                else:
                    fixed = isinstance(node.count, Fixed)
                    key = "" if fixed else self.count_key(node, frame.scope)
                    if fixed or key in env:
                        times = abs(node.count.value) if fixed else env[key]  # type: ignore[union-attr]
                        reflect = frame.reflect != _reflects(node)
                        body = Frame(node.body, frame.scope, reflect)
                        settled = self.settle(body)
                        if settled is None:
                            stack = _push(stack, body, times)
                            continue
                        letters, sizes = settled  # no decision inside: its letters at once
                        for _ in range(times):
                            out.extend(letters)
                            for size in sizes:
                                length += size
                        if length > self.max_length + EPS or len(out) > self.max_letters:
                            return
                        continue
                    low, high = self.count_range(node)
                    value = low
                    while high is None or value <= high:
                        count_env = {**env, key: value}
                        count_stack = (frame, stack)  # expanded with the count now set
                        if not self.fits(count_stack, count_env, length, len(out)):
                            break  # lengths never shrink as a count grows
                        yield from self.expand(count_stack, count_env, out, length)
                        value += 1
                    return
            yield env, tuple(out), length
        finally:
            del out[mark:]

    def settle(self, frame: Frame) -> tuple[Word, tuple[float, ...]] | None:
        """The letters a piece of pattern with no decision in it makes, with their sizes
        (0 unsized); None if it has a decision (an alternation or a free count)."""
        key = (id(frame.node), frame.scope, frame.reflect)
        if key in self.settled:
            return self.settled[key]
        node = frame.node
        found: tuple[Word, tuple[float, ...]] | None = None
        if isinstance(node, Sym):
            if not frame.scope and node.name in self.pattern.contents:
                content = self.pattern.contents[node.name]
                found = self.settle(Frame(content, node.name, frame.reflect))
            else:
                found = (self.letter(node, frame),), (self.sizes.get(node.name) or 0.0,)
        elif isinstance(node, Seq):
            parts = [self.settle(child) for child in reversed(self.children(node, frame))]
            if all(part is not None for part in parts):
                found = (
                    tuple(letter for part in parts if part for letter in part[0]),
                    tuple(size for part in parts if part for size in part[1]),
                )
        elif isinstance(node, Repeat) and isinstance(node.count, Fixed):
            reflect = frame.reflect != _reflects(node)
            body = self.settle(Frame(node.body, frame.scope, reflect))
            if body is not None:
                times = abs(node.count.value)
                found = body[0] * times, body[1] * times
        self.settled[key] = found
        return found

    def children(self, node: Seq, frame: Frame) -> tuple[Frame, ...]:
        """The frames of a sequence's items, last first (the order they are pushed in)."""
        key = (id(node), frame.scope, frame.reflect)
        children = self.frames.get(key)
        if children is None:
            items = reversed(node.items) if frame.reflect else node.items
            children = self.frames[key] = tuple(
                Frame(item, frame.scope, frame.reflect) for item in reversed(tuple(items))
            )
        return children

    def count_range(self, node: Repeat) -> tuple[int, int | None]:
        count = node.count
        if isinstance(count, Named):
            low, high = self.counters[count.name]
        else:
            assert isinstance(count, Anonymous)
            low, high = count.min, None
        return low, (self.max_letters if high is None else high)

    def letter(self, node: Sym, frame: Frame) -> Letter:
        key = (id(node), frame.scope, frame.reflect)
        letter = self.letters.get(key)
        if letter is None:
            letter = self.letters[key] = self.make_letter(node, frame)
        return letter

    def make_letter(self, node: Sym, frame: Frame) -> Letter:
        from_control = self.pattern.substituted and not frame.scope
        return Letter(
            symbol=node.name,
            reflected=frame.reflect,
            transparent=from_control or node.name in self.transparent,
            placeholder=frame.scope or None,
        )


def _push(stack: Stack, frame: Frame, times: int) -> Stack:
    for _ in range(times):
        stack = (frame, stack)
    return stack


def _reflects(node: Repeat) -> bool:
    count = node.count
    return isinstance(count, (Fixed, Named)) and count.reflect


def make_word(
    pattern: CompiledPattern,
    choice: Choice | Mapping[str, int],
    *,
    transparent: frozenset[str] = frozenset(),
) -> Word:
    """The word a choice makes. Every decision the word meets must be in ``choice``."""
    env = choice.as_dict() if isinstance(choice, Choice) else dict(choice)
    expander = _Expander(pattern, {}, transparent, {}, float("inf"), 1 << 62)
    needed = _missing_decisions(expander, env)
    if needed:
        raise KeyError(f"the choice does not fix {', '.join(sorted(needed))}")
    for _, word, _ in expander.expand((Frame(pattern.root, "", False), None), env, [], 0.0):
        return word
    raise AssertionError("unreachable: a complete choice makes exactly one word")


def _missing_decisions(expander: _Expander, env: Mapping[str, int]) -> set[str]:
    """Decisions reached by expanding under ``env`` that ``env`` leaves open."""
    missing: set[str] = set()
    pattern = expander.pattern

    def visit(node: Node, scope: str) -> None:
        if isinstance(node, Sym):
            if not scope and node.name in pattern.contents:
                visit(pattern.contents[node.name], node.name)
        elif isinstance(node, Seq):
            for item in node.items:
                visit(item, scope)
        elif isinstance(node, Alt):
            key = expander.keys[id(node)]
            if key in env:
                visit(node.branches[env[key]], scope)
            else:
                missing.add(key)
        else:
            if not isinstance(node.count, Fixed):
                key = expander.count_key(node, scope)
                if key not in env:
                    missing.add(key)
                elif env[key] == 0:
                    return
            elif node.count.value == 0:
                return
            visit(node.body, scope)

    visit(pattern.root, "")
    return missing


def length_range(
    pattern: CompiledPattern,
    *,
    least: Mapping[str, float | None],
    most: Mapping[str, float | None],
    counters: Mapping[str, tuple[int, int | None]],
) -> tuple[float, float]:
    """The least and greatest length of any word of ``pattern``: each letter between its
    ``least`` and ``most`` size (None: 0 and unbounded), each counter within its bounds
    (an anonymous one unbounded), each alternation at its shortest / longest branch; a
    placeholder's content is followed. A relaxation: counters shared with other patterns,
    and one branch for all repetitions, are not enforced, so every word lies in the range
    (the greatest may be infinite)."""
    expander = _Expander(pattern, least, frozenset(), counters, float("inf"), 1 << 62)
    low = expander.minimum(pattern.root, "", {})[0]
    return low, _longest(pattern, pattern.root, "", most, counters)


def _longest(
    pattern: CompiledPattern,
    node: Node,
    scope: str,
    most: Mapping[str, float | None],
    counters: Mapping[str, tuple[int, int | None]],
) -> float:
    if isinstance(node, Sym):
        if not scope and node.name in pattern.contents:
            return _longest(pattern, pattern.contents[node.name], node.name, most, counters)
        size = most.get(node.name)
        return float("inf") if size is None else size
    if isinstance(node, Seq):
        return sum((_longest(pattern, item, scope, most, counters) for item in node.items), 0.0)
    if isinstance(node, Alt):
        return max(_longest(pattern, branch, scope, most, counters) for branch in node.branches)
    count = node.count
    times: float
    if isinstance(count, Fixed):
        times = abs(count.value)
    elif isinstance(count, Named):
        high = counters.get(count.name, (0, None))[1]
        times = float("inf") if high is None else high
    else:
        times = float("inf")
    body = _longest(pattern, node.body, scope, most, counters)
    return 0.0 if times == 0 or body == 0 else times * body


def enumerate_words(
    pattern: CompiledPattern,
    *,
    sizes: Mapping[str, float | None],
    max_length: float,
    min_length: float = 0.0,
    transparent: frozenset[str] = frozenset(),
    counters: Mapping[str, tuple[int, int | None]] | None = None,
    fixed: Mapping[str, int] | None = None,
    max_letters: int = 512,
) -> Iterator[Enumerated]:
    """Lazily yield every word with ``min_length <= length <= max_length``.

    ``length`` is the sum of the preferred sizes of the sized letters; a word with unsized
    (elastic) letters passes the lower bound whatever its length, as it can stretch.
    Counters range over ``counters[name] = (min, max or None)`` (named counters absent from
    it range from 0), anonymous ones from their floor; a count stops growing as soon as the
    word cannot fit any more, and at ``max_letters`` letters in all, so unbounded spaces are
    walked, never materialised. ``fixed`` pins decisions (e.g. a counter shared with another
    pattern). Words come in lexicographic order of their decisions, smallest counts first.
    """
    bounds: dict[str, tuple[int, int | None]] = {n: (0, None) for n in pattern.counter_names()}
    bounds.update(counters or {})
    expander = _Expander(pattern, sizes, transparent, bounds, max_length, max_letters)
    stack: Stack = (Frame(pattern.root, "", False), None)
    env = dict(fixed or {})
    if not expander.fits(stack, env, 0.0, 0):
        return
    for values, word, length in expander.expand(stack, env, [], 0.0):
        elastic = any(sizes.get(letter.symbol) is None for letter in word)
        if length >= min_length - EPS or elastic:
            yield Enumerated(Choice.of(values), word, length, elastic)


def format_word(word: Word) -> str:
    """Readable text of a word: ``A B'`` for a reflected B, ``[e]`` for a transparent e."""
    parts = []
    for letter in word:
        text = letter.symbol + ("'" if letter.reflected else "")
        parts.append(f"[{text}]" if letter.transparent else text)
    return " ".join(parts) if parts else "(empty)"


def mirror(word: Word) -> Word:
    """The word read backwards with every letter's reflection flipped (``X^-1`` of ``X``)."""
    return tuple(
        Letter(letter.symbol, not letter.reflected, letter.transparent, letter.placeholder)
        for letter in reversed(word)
    )
