"""What the solver considers for each layer: the words of its candidates, in its order.

``facade words`` prints it: a quick way to check that patterns say what was meant, and
to see which word ``facade solve`` picks (marked ``*``) among the ones it looked at.
"""

from __future__ import annotations

from dataclasses import dataclass

from facadecli.errors import FacadeError
from facadecli.patterns import Enumerated, format_word
from facadecli.solver.axis import axis_words, solve_axis
from facadecli.solver.budgets import CANDIDATE_LIMIT, safety_clock
from facadecli.solver.candidates import generate_candidates, pattern_uses
from facadecli.spec.model import Spec
from facadecli.spec.resolve import AXES, Axis


@dataclass(frozen=True)
class WordPreview:
    layer: str
    axis: Axis
    canvas: float
    words: tuple[Enumerated, ...]  # in the order the solver tries them
    chosen: str | None  # the word solve picks, as text (None when the axis has no layout)
    considered: int  # distinct words of this pattern among the solver's candidates

    def lines(self) -> list[str]:
        head = f"{self.layer} {self.axis} (canvas {self.canvas:g} m, {self.considered} words):"
        if not self.words:
            return [head, "  no word: the patterns' words cannot fit the canvas together"]
        rows = [head]
        for item in self.words:
            counters = ", ".join(f"{k}={v}" for k, v in item.choice.values if "#" not in k)
            stretch = " + elastic" if item.elastic else ""
            mark = "*" if format_word(item.word) == self.chosen else " "
            rows.append(
                f" {mark}{item.length:8.3f} m{stretch}  {format_word(item.word)}"
                + (f"   ({counters})" if counters else "")
            )
        return rows


def preview_words(spec: Spec, limit: int = 5) -> list[WordPreview]:
    """For every enabled layer and axis, the first ``limit`` distinct words of the solver's
    candidates (the order in which it tries them), and the word it picks."""
    previews: dict[tuple[str, Axis], WordPreview] = {}
    for axis in AXES:
        canvas = spec.canvas.width if axis == "x" else spec.canvas.height
        uses = pattern_uses(spec, axis_words(spec, axis))
        candidates = generate_candidates(spec, uses, canvas, CANDIDATE_LIMIT)
        try:
            chosen = dict(solve_axis(spec, axis, canvas, safety_clock() + 60).words)
        except FacadeError:
            chosen = {}
        for use in uses:
            distinct: dict[str, Enumerated] = {}
            for candidate in candidates:
                item = candidate.words[use.key]
                distinct.setdefault(format_word(item.word), item)
            shown = list(distinct.values())[:limit]
            picked = distinct.get(chosen.get(use.key, ""))
            if picked is not None and picked not in shown:
                shown.append(picked)
            for layer, _ in use.layers:
                name = spec.layers[layer].name
                previews[(name, axis)] = WordPreview(
                    name, axis, canvas, tuple(shown), chosen.get(use.key), len(distinct)
                )
    return [previews[(layer.name, axis)] for layer in spec.layers if layer.enabled for axis in AXES]
