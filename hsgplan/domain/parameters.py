"""Motion-primitive parameters: the paper's discrete bins and the continuous values they mean.

`place(o, target, x_bin, y_bin)`: PLACE_BINS x PLACE_BINS bin centres over the target surface,
inset so that the object, whichever way it is turned, stays wholly on it. Stacking on an object
takes its position from geometry instead (the bins are None).
`push(o, angle_bin, dist_bin)`: PUSH_ANGLE_BINS directions over PUSH_ANGLE_RANGE and
PUSH_DIST_BINS distances over PUSH_DIST_RANGE, both including their ends. The distance is the
fingertip's travel; it starts PUSH_LEAD behind the object, so the object moves PUSH_LEAD less.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import Kind, World
from hsgplan.domain.world import (
    PLACE_BINS,
    PLACE_LONG_AXIS_YAW,
    PUSH_ANGLE_BINS,
    PUSH_ANGLE_RANGE,
    PUSH_DIST_BINS,
    PUSH_DIST_RANGE,
)

PLACE_EDGE_GAP = 0.005
PUSH_LEAD = 0.01


@dataclass(frozen=True)
class PickParams:
    obj: str


@dataclass(frozen=True)
class PlaceParams:
    obj: str
    target: str
    x_bin: int | None = None
    y_bin: int | None = None


@dataclass(frozen=True)
class PushParams:
    obj: str
    angle_bin: int
    dist_bin: int


PrimitiveParams = PickParams | PlaceParams | PushParams


class MotionPrimitive(StrEnum):
    """The primitives whose parameters are chosen over bins (a pick has none)."""

    PLACE = "place"
    PUSH = "push"


# The bin grid of each primitive: (x, y) for place, (angle, distance) for push.
BINS: dict[MotionPrimitive, tuple[int, int]] = {
    MotionPrimitive.PLACE: (PLACE_BINS, PLACE_BINS),
    MotionPrimitive.PUSH: (PUSH_ANGLE_BINS, PUSH_DIST_BINS),
}


def params_for(
    primitive: MotionPrimitive, obj: str, target: str, bins: tuple[int, int]
) -> PlaceParams | PushParams:
    """The primitive's parameters for a pair of bins."""
    if primitive is MotionPrimitive.PLACE:
        return PlaceParams(obj, target, *bins)
    return PushParams(obj, *bins)


def _check_bin(value: int, bins: int, what: str) -> None:
    if not 0 <= value < bins:
        raise InvalidInputError(f"{what} {value} is outside 0..{bins - 1}")


def place_inset(obj: str, world: World) -> tuple[float, float]:
    """How far a bin centre stays from a surface's x and y edges: half the object's footprint
    as it is placed (long side along y), plus a small gap."""
    fx, fy = sorted(world.object_type(obj).footprint)
    return fx / 2 + PLACE_EDGE_GAP, fy / 2 + PLACE_EDGE_GAP


def place_xy(obj: str, target: str, x_bin: int, y_bin: int, world: World) -> tuple[float, float]:
    """The world (x, y) of a place bin's centre on a surface (the bins run along the surface's
    own axes, which turn with its shelf)."""
    if target not in world.surface_capacity:
        raise InvalidInputError(f"place bins are over surfaces, not '{target}'")
    _check_bin(x_bin, PLACE_BINS, "x_bin")
    _check_bin(y_bin, PLACE_BINS, "y_bin")
    r, (ix, iy) = world.surface_rect(target), place_inset(obj, world)
    x0, x1 = r.x_min + ix, r.x_max - ix
    y0, y1 = r.y_min + iy, r.y_max - iy
    if x1 < x0:
        x0 = x1 = (r.x_min + r.x_max) / 2
    if y1 < y0:
        y0 = y1 = (r.y_min + r.y_max) / 2
    return r.to_world(
        x0 + (x1 - x0) * (x_bin + 0.5) / PLACE_BINS,
        y0 + (y1 - y0) * (y_bin + 0.5) / PLACE_BINS,
    )


def place_yaw(target: str, world: World) -> float:
    """The yaw an object is placed at on a surface: long side along the surface's own y
    (`PLACE_LONG_AXIS_YAW`, turned with its shelf)."""
    return world.surface_rect(target).direction(PLACE_LONG_AXIS_YAW)


def place_centre(
    obj: str, target: str, x_bin: int, y_bin: int, world: World
) -> tuple[float, float, float]:
    """Where a place at these bins stands the object's centre: over the bin's centre, resting
    on the surface (long side along its y, `place_yaw`)."""
    x, y = place_xy(obj, target, x_bin, y_bin, world)
    return x, y, world.surface_rect(target).z + world.object_type(obj).height / 2


def push_carry(dist: float) -> float:
    """How far a push of stroke `dist` carries its object's centre at most: the fingertips
    start `PUSH_LEAD` short of the object."""
    return dist - PUSH_LEAD


def push_values(angle_bin: int, dist_bin: int, yaw: float = 0.0) -> tuple[float, float]:
    """(direction in radians from +x, distance in metres) of a push's bins, into a shelf turned
    by `yaw` radians (the bins run about the shelf's own inward x)."""
    _check_bin(angle_bin, PUSH_ANGLE_BINS, "angle_bin")
    _check_bin(dist_bin, PUSH_DIST_BINS, "dist_bin")
    a0, a1 = PUSH_ANGLE_RANGE
    d0, d1 = PUSH_DIST_RANGE
    angle = a0 + (a1 - a0) * angle_bin / (PUSH_ANGLE_BINS - 1)
    return (
        angle + yaw if yaw else angle,
        d0 + (d1 - d0) * dist_bin / (PUSH_DIST_BINS - 1),
    )


def extent_along(obj: str, yaw: float, angle: float, world: World) -> float:
    """How far an object standing at `yaw` reaches from its centre towards `angle`."""
    t = world.object_type(obj)
    if t.kind is Kind.CAN:
        return t.size[0] / 2
    rel = angle - yaw
    return abs(math.cos(rel)) * t.size[0] / 2 + abs(math.sin(rel)) * t.size[1] / 2


def nearest_push_bins(angle: float, dist: float, yaw: float = 0.0) -> tuple[int, int]:
    """The bins whose values are closest to a wanted direction and distance, into a shelf
    turned by `yaw` radians."""
    if yaw:
        angle = math.remainder(angle - yaw, 2 * math.pi)
    a0, a1 = PUSH_ANGLE_RANGE
    d0, d1 = PUSH_DIST_RANGE
    ab = round((angle - a0) / (a1 - a0) * (PUSH_ANGLE_BINS - 1))
    db = round((dist - d0) / (d1 - d0) * (PUSH_DIST_BINS - 1))
    return min(max(ab, 0), PUSH_ANGLE_BINS - 1), min(max(db, 0), PUSH_DIST_BINS - 1)
