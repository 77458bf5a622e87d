"""What the solver needs to know about the words of one axis: rows and letter properties.

A *row* is one word in one alignment group; layers of a group whose words are identical
share a row (they move together: the same pattern makes the same word, SPEC 2.6).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from facadecli.patterns import Letter, Word
from facadecli.patterns.ast import symbols
from facadecli.spec.model import Spec
from facadecli.spec.resolve import Axis, layer_pattern


@dataclass(frozen=True)
class LetterTraits:
    """The qualifiers of one letter that the alignment uses (SPEC 2.4)."""

    size: float | None  # preferred size; None for an unsized (elastic) placeholder
    transparent: bool
    opaque: bool  # never true for a transparent letter
    attached: bool
    unoccludable: bool
    segment: int = 0  # an entry never spans two segments (used for merged columns)


def letter_traits(spec: Spec, letter: Letter) -> LetterTraits:
    qualifiers = spec.qualifiers(letter.symbol)
    transparent = letter.transparent or qualifiers.transparent
    return LetterTraits(
        size=spec.size(letter.symbol),
        transparent=transparent,
        opaque=qualifiers.opaque and not transparent,
        attached=qualifiers.attached,
        unoccludable=qualifiers.unoccludable and not transparent,
    )


@dataclass(frozen=True)
class Row:
    """One word of an alignment group and the layers (stack indices) that show it."""

    layers: tuple[int, ...]
    word: Word
    traits: tuple[LetterTraits, ...]
    full_height: bool = True  # its layers cover the whole other axis (see covers())

    def __hash__(self) -> int:
        # the traits follow from the word (hashing them calls Python for every letter)
        return hash((self.layers, self.word, self.full_height))

    @property
    def lowest(self) -> int:
        return self.layers[0]

    @property
    def highest(self) -> int:
        return self.layers[-1]

    def is_above(self, other: Row) -> bool:
        """Some layer of this row lies in front of some layer of ``other`` (so it may cover
        an unoccludable letter of it)."""
        return self is not other and self.highest > other.lowest

    def covers(self, other: Row) -> bool:
        """``other`` may make room for an opaque letter of this row: every layer of this row
        lies in front of every layer of ``other``, and shows all along the other axis (no
        mask, no transparent letter there), so the room made leaves no hole in the plane."""
        return self is not other and self.full_height and self.lowest > other.highest


WordTraits = dict[Word, tuple[tuple[LetterTraits, ...], bool]]  # and: has it unoccludable ones


@dataclass
class RowCache:
    """What :func:`make_rows` keeps between calls (the caller keeps it): each word object's
    canonical equal (by identity, the object kept too, so its identity stays its own), the
    canonical words by value, and the rows made (by canonical word and layers)."""

    ids: dict[int, tuple[Word, Word, bool]] = field(default_factory=dict)  # id -> (word,
    # its canonical equal, has it an unoccludable letter)
    canonical: dict[Word, tuple[Word, bool]] = field(default_factory=dict)
    rows: dict[tuple[int, tuple[int, ...]], Row] = field(default_factory=dict)
    letters: dict[Letter, LetterTraits] = field(default_factory=dict)  # letter_traits()


def make_rows(
    spec: Spec,
    words: list[tuple[int, Word]],
    full: frozenset[int] = frozenset(),
    known: WordTraits | None = None,
    cache: RowCache | None = None,
) -> list[Row]:
    """Rows of one group from (layer index, word) pairs; identical words share a row.
    ``full``: the layers that show all along the other axis; ``known``: the traits of
    words met before, ``cache``: words and rows met before (caches the caller keeps, for
    one spec and axis)."""
    known = {} if known is None else known
    cache = RowCache() if cache is None else cache
    # a long word is hashed once: equal words are found by value, then by identity
    by_word: dict[tuple[int, int], list[int]] = {}
    canonical: dict[int, Word] = {}
    for layer, word in sorted(words, key=lambda item: item[0]):
        found = cache.ids.get(id(word))
        if found is None:
            same = cache.canonical.get(word)
            if same is None:
                same = cache.canonical[word] = (
                    word,
                    _word_traits(spec, word, known, cache.letters)[1],
                )
            found = cache.ids[id(word)] = (word, *same)
        _, first, unoccludable = found
        canonical[id(first)] = first
        # a word with an unoccludable letter keeps a row of its own in every layer: the same
        # word in front would cover it, so the front layer must be free to make room
        alone = layer if unoccludable else -1
        by_word.setdefault((id(first), alone), []).append(layer)
    rows = []
    for (key, _), layers in by_word.items():
        row = cache.rows.get((key, tuple(layers)))
        if row is None:
            word = canonical[key]
            full_height = all(layer in full for layer in layers)
            traits = known[word][0]
            row = cache.rows[key, tuple(layers)] = Row(tuple(layers), word, traits, full_height)
        rows.append(row)
    return sorted(rows, key=lambda row: row.lowest)


def _word_traits(
    spec: Spec, word: Word, known: WordTraits, letters: dict[Letter, LetterTraits]
) -> tuple[tuple[LetterTraits, ...], bool]:
    """A word's letters' traits, and whether one is unoccludable (kept in ``known``; each
    letter's in ``letters``: a long word has few distinct letters)."""
    found = known.get(word)
    if found is None:
        distinct = set(word)
        for letter in distinct.difference(letters):
            letters[letter] = letter_traits(spec, letter)
        traits = tuple(map(letters.__getitem__, word))
        found = known[word] = (traits, any(letters[letter].unoccludable for letter in distinct))
    return found


def full_layers(spec: Spec, axis: Axis) -> frozenset[int]:
    """Layers that show all along the other axis: no mask there, and a plain pattern of
    opaque, non-transparent symbols (so on this axis, lower layers may make room for them
    without leaving a hole in the plane)."""
    other: Axis = "y" if axis == "x" else "x"
    full = set()
    for index, layer in enumerate(spec.layers):
        mask = layer.visible
        if mask is not None and getattr(mask, other) is not None:
            continue
        pattern = layer_pattern(spec, layer, other)
        if pattern.substituted:
            continue
        names = {sym.name for sym in symbols(pattern.root)}
        if all(spec.qualifiers(n).opaque and not spec.qualifiers(n).transparent for n in names):
            full.add(index)
    return frozenset(full)
