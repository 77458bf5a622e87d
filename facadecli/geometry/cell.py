"""What a shape's geometry is sized from, shared by the meshes and the SVG elevation (no
mesh library needed to read it)."""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_SEGMENTS = 12


@dataclass(frozen=True)
class Cell:
    """What a primitive is sized from: the cell and the shape rule's parameters."""

    width: float
    height: float
    thickness: float
    frame_width: float | None = None
    pane_depth: float | None = None
    segments: int | None = None

    @property
    def frame(self) -> float:
        """Frame width: the rule's, or a tenth of the smaller side (at most 12 cm)."""
        default = min(0.12, 0.1 * min(self.width, self.height))
        wanted = self.frame_width if self.frame_width is not None else default
        return max(1e-3, min(wanted, 0.45 * min(self.width, self.height)))

    @property
    def pane(self) -> float:
        """How far the pane sits behind the frame's front."""
        return self.pane_depth if self.pane_depth is not None else max(0.02, 0.5 * self.thickness)


def arch_radius(width: float, height: float, frame: float) -> float:
    """The radius of an arch's outer curve: a semicircle as wide as its cell, when it fits."""
    return min(width / 2, height - frame)
