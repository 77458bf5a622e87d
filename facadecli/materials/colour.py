"""Colours as specs write them (sRGB-encoded) and as light adds up (linear): plain
Python, so that checking a spec needs no numpy (``facade validate`` starts fast)."""

from __future__ import annotations


def linear(encoded: float) -> float:
    """An sRGB-encoded value (0-1, as colours are written) in linear light: the inverse
    of :func:`facadecli.materials.textures.srgb`."""
    return encoded / 12.92 if encoded <= 0.04045 else ((encoded + 0.055) / 1.055) ** 2.4
