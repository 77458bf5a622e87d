"""The texture images of a scene's drawn materials (the library's: base colour, normal,
and occlusion-roughness-metallic packed as glTF packs them) as PNG files for the formats
that keep their pictures beside the model (OBJ, USD): one file per picture, however many
materials use it, named after the first material that does."""

from __future__ import annotations

import io
from collections.abc import Iterable
from dataclasses import dataclass

#: the pictures of a drawn material: slot -> (the PBRMaterial attribute, file suffix)
SLOTS = {
    "base_colour": ("baseColorTexture", "basecolor"),
    "normal": ("normalTexture", "normal"),
    "orm": ("metallicRoughnessTexture", "orm"),
}


def drawn(material: object) -> bool:
    """Whether a material carries a drawn texture set (a library material)."""
    return getattr(material, "normalTexture", None) is not None


def png(image: object) -> bytes:
    """The image as PNG, encoded as the glb encodes it (the same bytes every time)."""
    with io.BytesIO() as buffer:
        image.save(buffer, format="png")  # type: ignore[attr-defined]
        return buffer.getvalue()


@dataclass(frozen=True)
class TextureFiles:
    """Where each drawn material's pictures are, and the files' bytes."""

    names: dict[tuple[str, str], str]  # (material name, slot) -> file name
    files: dict[str, bytes]  # file name -> PNG


def texture_files(materials: Iterable[tuple[str, object]], stem: str) -> TextureFiles:
    """The PNG files of the drawn ones among ``(name, material)`` pairs, taken in the
    order of their names (so every format names a shared picture alike)."""
    names: dict[tuple[str, str], str] = {}
    files: dict[str, bytes] = {}
    by_bytes: dict[bytes, str] = {}
    for name, material in sorted(materials, key=lambda pair: pair[0]):
        if not drawn(material):
            continue
        for slot, (attribute, suffix) in SLOTS.items():
            data = png(getattr(material, attribute))
            file = by_bytes.setdefault(data, f"{stem}_{name}_{suffix}.png")
            files[file] = data
            names[(name, slot)] = file
    return TextureFiles(names, files)
