"""An independent acceptor for the pattern language, used to check the enumerator.

It *matches* a word against a pattern AST by backtracking (the enumerator *generates*),
so the two share no code beyond the AST. Semantics as in SPEC 2.2/2.3 and words.py: a
named counter has one value per word, an alternation or anonymous counter one value per
node, a placeholder one content word for all its occurrences.
"""

from __future__ import annotations

from collections.abc import Iterator

from facadecli.patterns.ast import Alt, Anonymous, Fixed, Named, Node, Repeat, Seq, Sym
from facadecli.patterns.words import Word

Env = dict[object, object]


def accepts(root: Node, word: Word, contents: dict[str, Node] | None = None) -> bool:
    matcher = _Matcher(word, contents or {})
    return any(end == len(word) for end, _ in matcher.match(root, 0, {}, False, ""))


class _Matcher:
    def __init__(self, word: Word, contents: dict[str, Node]):
        self.word = word
        self.contents = contents

    def match(
        self, node: Node, i: int, env: Env, reflect: bool, scope: str
    ) -> Iterator[tuple[int, Env]]:
        if isinstance(node, Sym):
            if not scope and node.name in self.contents:
                yield from self.placeholder(node.name, i, env, reflect)
                return
            if i < len(self.word):
                letter = self.word[i]
                if letter.symbol == node.name and letter.reflected == reflect:
                    yield i + 1, env
            return
        if isinstance(node, Seq):
            items = list(reversed(node.items)) if reflect else list(node.items)
            yield from self.sequence(items, i, env, reflect, scope)
            return
        if isinstance(node, Alt):
            key = ("alt", scope, id(node))
            for index, branch in enumerate(node.branches):
                if env.get(key, index) != index:
                    continue
                yield from self.match(branch, i, {**env, key: index}, reflect, scope)
            return
        assert isinstance(node, Repeat)
        count = node.count
        inner_reflect = reflect != (isinstance(count, (Fixed, Named)) and count.reflect)
        if isinstance(count, Fixed):
            counts: list[int] = [abs(count.value)]
            key = None
        else:
            key = ("counter", count.name) if isinstance(count, Named) else ("rep", scope, id(node))
            low = count.min if isinstance(count, Anonymous) else 0
            counts = [env[key]] if key in env else list(range(low, len(self.word) - i + 2))  # type: ignore[list-item]
        for n in counts:
            new_env = env if key is None else {**env, key: n}
            yield from self.sequence([node.body] * n, i, new_env, inner_reflect, scope)

    def sequence(
        self, items: list[Node], i: int, env: Env, reflect: bool, scope: str
    ) -> Iterator[tuple[int, Env]]:
        if not items:
            yield i, env
            return
        for j, env2 in self.match(items[0], i, env, reflect, scope):
            yield from self.sequence(items[1:], j, env2, reflect, scope)

    def placeholder(self, name: str, i: int, env: Env, reflect: bool) -> Iterator[tuple[int, Env]]:
        key = ("content", name)
        if key in env:  # the same content word again (mirrored if this occurrence is reflected)
            content: Word = env[key]  # type: ignore[assignment]
            if reflect != env[("content-reflect", name)]:
                content = tuple(reversed(content))
                expected = [(lt.symbol, not lt.reflected) for lt in content]
            else:
                expected = [(lt.symbol, lt.reflected) for lt in content]
            got = [(lt.symbol, lt.reflected) for lt in self.word[i : i + len(content)]]
            if got == expected:
                yield i + len(content), env
            return
        for j, env2 in self.match(self.contents[name], i, env, reflect, name):
            yield j, {**env2, key: self.word[i:j], ("content-reflect", name): reflect}
