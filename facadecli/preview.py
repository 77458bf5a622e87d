"""A preview of the words each layer can make on a canvas, before any alignment.

``facade words`` prints it: a quick way to check that patterns say what was meant.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

from facadecli.patterns import Enumerated, enumerate_words, format_word
from facadecli.spec.model import Spec
from facadecli.spec.resolve import AXES, Axis, layer_pattern

SCAN_LIMIT = 20_000  # words looked at per layer and axis, to keep the preview instant


@dataclass(frozen=True)
class WordPreview:
    layer: str
    axis: Axis
    canvas: float
    words: tuple[Enumerated, ...]  # nearest to the canvas first
    scanned: int

    def lines(self) -> list[str]:
        head = f"{self.layer} {self.axis} (canvas {self.canvas:g} m):"
        if not self.words:
            return [head, "  no word fits"]
        rows = [head]
        for item in self.words:
            counters = ", ".join(f"{k}={v}" for k, v in item.choice.values if "#" not in k)
            stretch = " + elastic" if item.elastic else ""
            rows.append(
                f"  {item.length:8.3f} m{stretch}  {format_word(item.word)}"
                + (f"   ({counters})" if counters else "")
            )
        return rows


def preview_words(spec: Spec, limit: int = 5) -> list[WordPreview]:
    """For every enabled layer and axis, the ``limit`` words nearest the canvas length."""
    sizes = {name: symbol.size for name, symbol in spec.symbols.items()}
    transparent = frozenset(n for n in spec.symbols if spec.qualifiers(n).transparent)
    counters = {name: counter.bounds for name, counter in spec.counters.items()}
    previews = []
    for layer in spec.layers:
        if not layer.enabled:
            continue
        for axis in AXES:
            canvas = spec.canvas.width if axis == "x" else spec.canvas.height
            found = enumerate_words(
                layer_pattern(spec, layer, axis),
                sizes=sizes,
                max_length=canvas + spec.solver.tolerance,
                transparent=transparent,
                counters=counters,
            )
            scanned = list(itertools.islice(found, SCAN_LIMIT))
            scanned.sort(key=lambda item: 0.0 if item.elastic else abs(canvas - item.length))
            previews.append(
                WordPreview(layer.name, axis, canvas, tuple(scanned[:limit]), len(scanned))
            )
    return previews
