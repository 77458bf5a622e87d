"""An independent check of SPEC 2.4 and 2.7 on a layout report.

It reads only the report (plain data) and the spec's qualifiers, and shares no code with
the solver, so the solver cannot pass by agreeing with itself.
"""

from __future__ import annotations

import itertools
from typing import Any

from facadecli.spec.model import Spec

TOL = 1e-5


def violations(spec: Spec, report: dict[str, Any]) -> list[str]:
    found: list[str] = []
    layers = [layer for layer in spec.layers if layer.enabled]
    for axis, canvas in (("x", report["canvas"]["width"]), ("y", report["canvas"]["height"])):
        words = {entry["name"]: entry[axis] for entry in report["layers"]}
        lengths: dict[str, float] = {}
        for name, word in words.items():
            previous_end = 0.0
            for letter in word:
                where = f"{axis} {name} {letter['symbol']}@{letter['start']}"
                if letter["start"] < previous_end - TOL:
                    found.append(f"{where}: overlaps the letter before it")
                if letter["end"] < letter["start"] - TOL:
                    found.append(f"{where}: ends before it starts")
                if letter["start"] < -TOL or letter["end"] > canvas + TOL:
                    found.append(f"{where}: outside the canvas")
                previous_end = letter["end"]
                length = letter["end"] - letter["start"]
                known = lengths.setdefault(letter["symbol"], length)
                if abs(known - length) > TOL:
                    found.append(f"{where}: length {length} differs from {known}")
        for layer in layers:
            group = getattr(layer.groups, axis)
            columns = report["alignment"][axis][group]["columns"]
            if abs(columns[0]) > TOL or abs(columns[-1] - canvas) > TOL:
                found.append(f"{axis} group {group}: columns do not span the canvas")
            for letter in words[layer.name]:
                if letter["transparent"]:
                    continue
                for boundary in columns:
                    if letter["start"] + TOL < boundary < letter["end"] - TOL:
                        found.append(f"{axis} {layer.name} {letter['symbol']}: cut at {boundary}")
        groups: dict[str, list[int]] = {}
        for index, layer in enumerate(layers):
            groups.setdefault(getattr(layer.groups, axis), []).append(index)
        for group, members in groups.items():
            columns = report["alignment"][axis][group]["columns"]
            for start, end in itertools.pairwise(columns):
                if not any(_opaque_cover(spec, words[layers[i].name], start, end) for i in members):
                    found.append(
                        f"{axis} group {group}: column [{start}, {end}] has no opaque backing"
                    )
            for position, i in enumerate(members):
                for letter in words[layers[i].name]:
                    qualifiers = spec.qualifiers(letter["symbol"])
                    if qualifiers.unoccludable and not letter["transparent"]:
                        for j in members[position + 1 :]:
                            if words[layers[j].name] == words[layers[i].name]:
                                continue  # one word in two layers: one row (SPEC 2.6)
                            for other in words[layers[j].name]:
                                if not other["transparent"] and _overlap(letter, other):
                                    found.append(
                                        f"{axis} {layers[i].name} {letter['symbol']}: covered by "
                                        f"{layers[j].name} {other['symbol']}"
                                    )
        for name, word in words.items():
            for k, letter in enumerate(word):
                if not spec.qualifiers(letter["symbol"]).attached:
                    continue
                before = word[k - 1]["end"] if k else 0.0
                after = word[k + 1]["start"] if k + 1 < len(word) else canvas
                if abs(before - letter["start"]) > TOL or abs(after - letter["end"]) > TOL:
                    found.append(f"{axis} {name} {letter['symbol']}: attached letter separated")
    return found


def _overlap(a: dict[str, Any], b: dict[str, Any]) -> bool:
    return a["start"] < b["end"] - TOL and b["start"] < a["end"] - TOL


def _opaque_cover(spec: Spec, word: list[dict[str, Any]], start: float, end: float) -> bool:
    """Is [start, end] covered, without gaps, by opaque visible letters of the word?"""
    cursor = start
    for letter in word:
        if letter["end"] <= cursor + TOL or letter["start"] >= end - TOL:
            continue
        if letter["start"] > cursor + TOL:
            return False
        if letter["transparent"] or not spec.qualifiers(letter["symbol"]).opaque:
            return False
        cursor = letter["end"]
    return cursor >= end - TOL
