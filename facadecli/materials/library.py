"""The material library a spec names (``material: brick-flemish``, or ``library:`` under
``materials`` with overrides): each entry is a :class:`Material` whose texture set the
package draws itself (:mod:`.textures`), tiling over a square of ``tile`` metres."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache

from facadecli.spec.model import Material

#: a side of the square one copy of a library texture covers, in metres, before ``scale``
TILES = {
    "brick-stretcher": 0.9,  # 4 stretchers of 225 mm (with their joint), 12 courses of 75 mm
    "brick-english": 0.9,
    "brick-flemish": 1.35,  # 4 stretcher-and-header pairs, 18 courses
    "stone-ashlar": 2.4,
    "render": 2.0,
    "concrete": 2.4,  # formwork panels of 1.2 m
    "timber": 1.2,  # boards of 150 mm
    "metal": 1.0,  # standing seams 500 mm apart
    "roof-tiles": 1.2,
    "slate": 1.0,
    "float-glass": 2.0,
    "gravel": 1.0,  # stones of about 18 mm
    "membrane": 2.0,  # rolls a metre wide
    "rooms": 1.0,  # not tiled: each window's back plate shows one room of the atlas
}

#: library name -> the surface generator drawing it (:data:`.textures.GENERATORS`)
KINDS = {
    "brick-stretcher": "brick-stretcher",
    "brick-english": "brick-english",
    "brick-flemish": "brick-flemish",
    "stone-ashlar": "ashlar",
    "render": "render",
    "concrete": "concrete",
    "timber": "timber",
    "metal": "metal",
    "roof-tiles": "roof-tiles",
    "slate": "slate",
    "float-glass": "glass",
    "gravel": "gravel",
    "membrane": "membrane",
    "rooms": "rooms",
}


def _entry(name: str, color: str, roughness: float, **more: float) -> Material:
    return Material(library=name, color=color, roughness=roughness, **more)  # type: ignore[arg-type]


#: name -> the library material with its own colour, roughness, ...; a spec's overrides
#: replace the fields it sets
LIBRARY: dict[str, Material] = {
    "brick-stretcher": _entry("brick-stretcher", "#9c4f38", 0.85),
    "brick-english": _entry("brick-english", "#8e4433", 0.85),
    "brick-flemish": _entry("brick-flemish", "#a0583c", 0.85),
    "stone-ashlar": _entry("stone-ashlar", "#d6cdb8", 0.8),
    "render": _entry("render", "#e6e0d4", 0.9),
    "concrete": _entry("concrete", "#b5b2ab", 0.85),
    "timber": _entry("timber", "#8a5a36", 0.7),
    "metal": _entry("metal", "#a3a7ab", 0.35, metallic=1.0),
    "roof-tiles": _entry("roof-tiles", "#a4553b", 0.75),
    "slate": _entry("slate", "#464b53", 0.6),
    "float-glass": _entry("float-glass", "#dde6e4", 0.04, opacity=0.35, transmission=1.0, ior=1.52),
    "gravel": _entry("gravel", "#9a958c", 0.95),
    "membrane": _entry("membrane", "#3f4042", 0.8),  # bitumen felt; lighter: a single-ply sheet
    "rooms": _entry("rooms", "#ffffff", 0.9),  # the colour dims or tints every room
}


def resolve(declared: Mapping[str, Material], name: str) -> Material | None:
    """The material a name stands for: the spec's own (over the library entry it starts
    from, if any), else the library's of that name, else None (a built-in)."""
    own = declared.get(name)
    if own is not None:
        return finished(own)
    return LIBRARY.get(name)


def finished(material: Material) -> Material:
    """A spec material with its library entry under it: the fields the spec sets win."""
    if material.library is None:
        return material
    base = LIBRARY[material.library]
    update = {field: getattr(material, field) for field in material.model_fields_set}
    return base.model_copy(update=update)


@dataclass(frozen=True)
class Images:
    """A library material's texture images (PIL) and the metres one copy covers."""

    base_colour: object
    normal: object
    orm: object  # occlusion (R), roughness (G), metallic (B): glTF's packing
    size: float


def images(material: Material) -> Images:
    """The texture images of a finished library material (see :func:`finished`)."""
    assert material.library is not None
    if material.emissive:  # the same pictures as unlit: a lit room's are its room's
        material = material.model_copy(update={"emissive": 0.0})
    return _images(material)


@lru_cache(maxsize=32)  # at most 32 x 9 MB of pictures at 1024 px
def _images(material: Material) -> Images:
    from PIL import Image

    from facadecli.materials.pictures import picture
    from facadecli.materials.textures import linear, texture_set

    assert material.library is not None
    tile = TILES[material.library]
    hexa = material.color.lstrip("#")
    rgb = tuple(linear(int(hexa[i : i + 2], 16) / 255.0) for i in (0, 2, 4))
    made = texture_set(
        KINDS[material.library],
        material.resolution,
        tile,
        material.seed,
        (rgb[0], rgb[1], rgb[2]),
        material.roughness,
        material.metallic,
    )
    return Images(  # pictures that keep their PNG bytes: a city exports them per building
        picture(Image.fromarray(made.base_colour, "RGB")),
        picture(Image.fromarray(made.normal, "RGB")),
        picture(Image.fromarray(made.orm, "RGB")),
        tile * material.scale,
    )
