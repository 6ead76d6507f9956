"""Rectangles on horizontal planes, turned or not: the footprints, surfaces and regions of a
scene. A turned rectangle keeps its bounds in its own frame and answers in the world's, so a
shelf at any yaw reads as an unturned one to whatever works in its frame; an unturned one
computes exactly as plain bounds would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Rect:
    """A rectangle on a horizontal plane at height `z`: the bounds `x_min`..`y_max` as it stands
    before it is turned by `yaw` (radians) about `pivot` (its centre when None). A shelf's
    rectangles (footprint, interior, top, prepush region) all turn about the shelf footprint's
    centre, so that its bounds read in the shelf's own frame, its open side towards low x.
    Widths are along its own axes; `contains`, `center` and `corners` are in the world."""

    x_min: float
    x_max: float
    y_min: float
    y_max: float
    z: float = 0.0
    yaw: float = 0.0
    pivot: tuple[float, float] | None = None

    @property
    def width_x(self) -> float:
        return self.x_max - self.x_min

    @property
    def width_y(self) -> float:
        return self.y_max - self.y_min

    @property
    def center(self) -> tuple[float, float]:
        return self.to_world((self.x_min + self.x_max) / 2, (self.y_min + self.y_max) / 2)

    def _turn(self) -> tuple[float, float, float, float]:
        px, py = self.pivot or ((self.x_min + self.x_max) / 2, (self.y_min + self.y_max) / 2)
        return px, py, math.cos(self.yaw), math.sin(self.yaw)

    def to_world(self, x: float, y: float) -> tuple[float, float]:
        """A point given in the rectangle's frame (its unturned bounds), in the world."""
        if self.yaw == 0.0:  # exactly as given: an unturned world computes as it always did
            return x, y
        px, py, c, s = self._turn()
        return px + c * (x - px) - s * (y - py), py + s * (x - px) + c * (y - py)

    def to_local(self, x: float, y: float) -> tuple[float, float]:
        """A world point in the rectangle's frame."""
        if self.yaw == 0.0:
            return x, y
        px, py, c, s = self._turn()
        return px + c * (x - px) + s * (y - py), py - s * (x - px) + c * (y - py)

    def direction(self, angle: float) -> float:
        """A direction given in the rectangle's frame (radians from its x), in the world."""
        return angle + self.yaw if self.yaw else angle

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        x, y = self.to_local(x, y)
        return (
            self.x_min - margin <= x <= self.x_max + margin
            and self.y_min - margin <= y <= self.y_max + margin
        )

    def corners(self) -> list[tuple[float, float]]:
        """The four corners in the world, in turn round the rectangle."""
        local = [(self.x_min, self.y_min), (self.x_max, self.y_min),
                 (self.x_max, self.y_max), (self.x_min, self.y_max)]  # fmt: skip
        return [self.to_world(x, y) for x, y in local]

    def overlaps(self, other: Rect) -> bool:
        """Whether the two share more than an edge."""
        if self.yaw == 0.0 and other.yaw == 0.0:
            return (
                self.x_min < other.x_max
                and other.x_min < self.x_max
                and self.y_min < other.y_max
                and other.y_min < self.y_max
            )
        return _separated(self, other) is False and _separated(other, self) is False


def _separated(a: Rect, b: Rect) -> bool:
    """Whether one of `a`'s axes separates the two (the separating-axis test, half of it)."""
    theirs = [a.to_local(x, y) for x, y in b.corners()]
    eps = 1e-9
    return (
        max(x for x, _ in theirs) <= a.x_min + eps
        or min(x for x, _ in theirs) >= a.x_max - eps
        or max(y for _, y in theirs) <= a.y_min + eps
        or min(y for _, y in theirs) >= a.y_max - eps
    )
