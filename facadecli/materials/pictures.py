"""Drawn texture pictures that keep their PNG encoding.

trimesh's glTF export encodes every texture picture again for every file it writes (a
PIL ``save`` per image), which made each textured building of a city cost about half a
second of CPU. A :class:`Picture` is a PIL image that encodes itself once, the same way
(PNG, PIL's defaults: the same bytes as before), and hands those bytes to every later
``save(..., format="png")`` into a file object; any other save is PIL's own."""

from __future__ import annotations

import io
from typing import Any

from PIL import Image


class Picture(Image.Image):
    """A PIL image whose PNG bytes are made once (see the module)."""

    _png: bytes | None = None

    def png(self) -> bytes:
        if self._png is None:
            with io.BytesIO() as buffer:
                Image.Image.save(self, buffer, format="png")
                self._png = buffer.getvalue()
        return self._png

    def save(self, fp: Any, format: str | None = None, **params: Any) -> None:
        if not params and hasattr(fp, "write") and (format or "").lower() == "png":
            fp.write(self.png())
            return
        super().save(fp, format, **params)


def picture(image: Image.Image) -> Picture:
    """``image`` as a :class:`Picture` (the same object, its class changed: no copy)."""
    image.__class__ = Picture
    return image  # type: ignore[return-value]
