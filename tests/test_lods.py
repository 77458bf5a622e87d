"""A building's coarser levels of detail (lods.py), made from its CityJSON feature: LOD1
blocks closed and as tall as the building, LOD2 walls and roofs closed, both facing out,
on every roof shape and footprint the CityJSON tests use, parts lifted off the ground
too."""

from __future__ import annotations

from typing import get_args

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from facadecli.city.cityjson import BuildingSolids, building_object
from facadecli.city.lods import lod_meshes, roof_depth
from facadecli.city.manifest import Roof, RoofType
from facadecli.city.s3db import Volume

BOX = Polygon([(0, 0), (10, 0), (10, 8), (0, 8)])
ELL = Polygon([(40, 0), (52, 0), (52, 5), (45, 5), (45, 10), (40, 10)])
COURT = Polygon([(60, 0), (80, 0), (80, 20), (60, 20)], [[(66, 6), (66, 14), (74, 14), (74, 6)]])
SHAPES = {"box": BOX, "ell": ELL, "court": COURT}


def _closed(meshes: dict[str, trimesh.Trimesh]) -> trimesh.Trimesh:
    whole = trimesh.util.concatenate([m for m in meshes.values() if len(m.faces)])
    whole.merge_vertices()
    assert whole.is_watertight and whole.is_winding_consistent
    assert whole.volume > 0  # facing out
    return whole


@pytest.mark.parametrize("kind", get_args(RoofType))
@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_blocks_and_roofs_close_on_every_roof(kind: str, shape: str) -> None:
    part = SHAPES[shape]
    feature = building_object(BuildingSolids(shape, [Volume(part, 0.0, 7.0, Roof(type=kind))]))
    top = max(v[2] for v in feature["vertices"]) / 1000
    block = _closed(lod_meshes(feature, 1))
    assert block.volume == pytest.approx(part.area * top, rel=1e-6)
    assert block.bounds[1][1] == pytest.approx(top)  # glTF: y up
    roofed = _closed(lod_meshes(feature, 2))
    assert part.area * 7.0 * (1 - 1e-6) <= roofed.volume <= block.volume * (1 + 1e-6)
    depth = roof_depth(feature)
    if kind == "flat":
        assert depth == 0 and roofed.volume == pytest.approx(block.volume)
    else:  # the block fills what the roof leaves out
        assert depth > 0 and roofed.volume < block.volume
    assert len(lod_meshes(feature, 2)["roof"].faces) > 0


def test_a_lifted_part_is_a_block_from_its_base() -> None:
    hall = Polygon([(0, 20), (10, 20), (10, 30), (0, 30)])
    wing = Polygon([(10, 22), (18, 22), (18, 28), (10, 28)])
    feature = building_object(
        BuildingSolids(
            "hall", [Volume(hall, 0.0, 15.0, Roof()), Volume(wing, 3.0, 8.0, Roof(type="gable"))]
        )
    )
    block = _closed(lod_meshes(feature, 1))
    wing_top = max(v[2] for v in feature["vertices"] if v[0] > 10_000) / 1000
    assert block.volume == pytest.approx(100 * 15 + 48 * (wing_top - 3.0), rel=1e-6)
    lowest = np.min(block.vertices[block.vertices[:, 0] > 10.001][:, 1])
    assert lowest == pytest.approx(3.0)  # the wing's underside, not the ground


def test_other_levels_are_not_made_here() -> None:
    feature = building_object(BuildingSolids("b", [Volume(BOX, 0.0, 3.0, Roof())]))
    with pytest.raises(ValueError, match="LOD3"):
        lod_meshes(feature, 3)
