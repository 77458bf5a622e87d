"""Materials a renderer can use: a library of procedural PBR texture sets (brick in its
bonds, ashlar, render, concrete, timber, metal, roof tiles, slate, glass) that specs name."""

from facadecli.materials.library import LIBRARY, TILES, Images, finished, images, resolve

__all__ = ["LIBRARY", "TILES", "Images", "finished", "images", "resolve"]
