"""One colour per label, the same in every picture of a grammar and its derivations."""

from __future__ import annotations

import hashlib

NAMED = {  # CMP labels, close to the database's own colours where they are clear
    "facade": "#4a6fb5",
    "window": "#e7f2fa",
    "door": "#b5651d",
    "shop": "#d98c8c",
    "balcony": "#7a7a7a",
    "cornice": "#c9b18f",
    "molding": "#d6c7a8",
    "sill": "#b8a88a",
    "pillar": "#9c8f7a",
    "blind": "#5e8c4a",
    "deco": "#e0b341",
    "background": "#202020",
}


def label_colour(label: str) -> str:
    if label in NAMED:
        return NAMED[label]
    digest = hashlib.sha1(label.encode()).digest()
    return "#{:02x}{:02x}{:02x}".format(*(80 + b % 150 for b in digest[:3]))
