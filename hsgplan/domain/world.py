"""The constants of the robot and the paper's discretisation, which no scene changes.

A scene's facts (its object types, shelves, regions, capacities, friction) are its `World`'s
(`domain/scene.py`), passed to whatever needs them; the default world is `domain/kitchen.py`.

Frame: origin at the robot base on the table top, z up, x away from the robot, y to the left.
All lengths are metres.
"""

from __future__ import annotations

import math

from hsgplan.domain.scene import (
    GRIPPER_MAX_OPENING,
    INTERIOR_SPOT,
    MAX_OBJECTS,
    MIN_SUPPORT_SIDE,
    REACH_MAX_Z,
    Board,
    Kind,
    ObjectType,
    Rect,
    Shelf,
    World,
    shelf_boards,
)

__all__ = [
    "GRIPPER_MAX_OPENING", "INTERIOR_SPOT", "MAX_OBJECTS", "MIN_SUPPORT_SIDE", "REACH_MAX_Z",
    "Board", "Kind", "ObjectType", "Rect", "Shelf", "World", "shelf_boards",
]  # fmt: skip

# --- motion primitive parameters (the paper's discretisation) ---

PLACE_BINS = 10  # x and y bins over the target region or shelf top
# Objects are placed with the long side of their footprint (local y) along world y: the shelf
# tops are wider (y) than deep (x), and the fingers then close along x, clear of the shelf walls.
PLACE_LONG_AXIS_YAW = 0.0
PUSH_ANGLE_BINS = 21
PUSH_DIST_BINS = 21
# Push direction, in radians from +x (shelves open towards -x, so pushes go roughly along +x).
PUSH_ANGLE_RANGE = (-math.pi / 4, math.pi / 4)
# Push length (the fingertips' travel). Measured over 4,466 uniform trials with 4-24 cm: under
# 11 cm no push got a can from its prepush region into the shelf, and past 19 cm the hand always
# met the shelf's walls or top board; the range keeps a margin on both sides.
PUSH_DIST_RANGE = (0.08, 0.20)

# --- episodes ---

# Primitives an episode may take before it counts as an overstep (the paper's limit), in the
# simulated world and in the symbolic loop alike.
MAX_STEPS = 50
