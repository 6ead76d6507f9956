"""The kitchen-storage world: every size, region and fixture, in one place.

Frame: origin at the robot base on the table top, z up, x away from the robot, y to the left.
All lengths are metres. Other modules import these values; none repeats them.

The derived limits at the bottom (capacities, tower height) are what the goal validator, the
symbolic transition model and the PDDL domain all enforce, so the three agree by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum


class Kind(StrEnum):
    CAN = "can"
    BOX = "box"


@dataclass(frozen=True)
class ObjectType:
    """A kind of grocery item, described in the orientation it rests in.

    `size` is (extent along x, extent along y, height) when resting; for cans the first two are
    the diameter. Boxes rest so that the gripper (max opening `GRIPPER_MAX_OPENING`) can close
    across their narrow horizontal side: cream cheese and butter lie flat, popcorn stands upright
    because its flat footprint (12.6 x 8.5 cm) is wider than the gripper opens.
    """

    name: str
    kind: Kind
    size: tuple[float, float, float]
    color: tuple[float, float, float, float]

    @property
    def height(self) -> float:
        return self.size[2]

    @property
    def footprint(self) -> tuple[float, float]:
        return self.size[0], self.size[1]

    @property
    def grasp_width(self) -> float:
        return min(self.footprint)

    @property
    def top_face_min_side(self) -> float:
        return min(self.footprint)


# Sizes from the HOPE/DOPE cuboids (cm in the design notes, metres here).
OBJECT_TYPES: dict[str, ObjectType] = {
    t.name: t
    for t in (
        ObjectType("cherries", Kind.CAN, (0.069, 0.069, 0.058), (0.80, 0.10, 0.15, 1.0)),
        ObjectType("alphabet_soup", Kind.CAN, (0.071, 0.071, 0.084), (0.95, 0.75, 0.10, 1.0)),
        ObjectType("tomato_soup", Kind.CAN, (0.070, 0.070, 0.083), (0.90, 0.35, 0.10, 1.0)),
        ObjectType("popcorn", Kind.BOX, (0.038, 0.085, 0.126), (0.20, 0.45, 0.90, 1.0)),
        ObjectType("cream_cheese", Kind.BOX, (0.053, 0.104, 0.024), (0.25, 0.70, 0.30, 1.0)),
        ObjectType("butter", Kind.BOX, (0.053, 0.103, 0.024), (0.95, 0.90, 0.55, 1.0)),
    )
}


@dataclass(frozen=True)
class Rect:
    """An axis-aligned rectangle on a horizontal plane at height `z`."""

    x_min: float
    x_max: float
    y_min: float
    y_max: float
    z: float = 0.0

    @property
    def width_x(self) -> float:
        return self.x_max - self.x_min

    @property
    def width_y(self) -> float:
        return self.y_max - self.y_min

    @property
    def center(self) -> tuple[float, float]:
        return (self.x_min + self.x_max) / 2, (self.y_min + self.y_max) / 2

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        return (
            self.x_min - margin <= x <= self.x_max + margin
            and self.y_min - margin <= y <= self.y_max + margin
        )


@dataclass(frozen=True)
class Shelf:
    """An open-fronted cabinet facing the robot (open at its low-x side).

    `outer` is its footprint on the table; `interior` the floor of the space inside (the table
    itself, so objects can be pushed in); `top` the flat board objects are placed on.
    """

    name: str
    outer: Rect
    interior: Rect
    clearance: float
    top: Rect
    prepush: str


GRIPPER_MAX_OPENING = 0.08
TABLE = Rect(-0.30, 1.00, -0.80, 0.80, 0.0)

WALL = 0.02
SHELF_CLEARANCE = 0.12
SHELF_TOP_Z = SHELF_CLEARANCE + WALL


def _shelf(name: str, x_min: float, x_max: float, y_near: float, y_far: float, prepush: str):
    y_min, y_max = min(y_near, y_far), max(y_near, y_far)
    outer = Rect(x_min, x_max, y_min, y_max, 0.0)
    interior = Rect(x_min, x_max - WALL, y_min + WALL, y_max - WALL, 0.0)
    top = Rect(x_min, x_max, y_min, y_max, SHELF_TOP_Z)
    return Shelf(name, outer, interior, SHELF_CLEARANCE, top, prepush)


@dataclass(frozen=True)
class Board:
    """One box of a shelf: its footprint and the heights of its bottom and top faces."""

    rect: Rect
    z_min: float
    z_max: float


def shelf_boards(shelf: Shelf) -> tuple[Board, ...]:
    """A shelf's side walls, back wall and top board; the front (low x) is open, the floor is
    the table."""
    o, c = shelf.outer, shelf.clearance
    left = Rect(o.x_min, o.x_max, o.y_max - WALL, o.y_max)
    right = Rect(o.x_min, o.x_max, o.y_min, o.y_min + WALL)
    back = Rect(o.x_max - WALL, o.x_max, o.y_min + WALL, o.y_max - WALL)
    return (*(Board(r, 0.0, c) for r in (left, right, back)), Board(o, c, shelf.top.z))


SHELVES: dict[str, Shelf] = {
    "shelf_a": _shelf("shelf_a", 0.38, 0.60, 0.22, 0.54, "prepush_a"),
    "shelf_b": _shelf("shelf_b", 0.38, 0.60, -0.22, -0.54, "prepush_b"),
}

REGIONS: dict[str, Rect] = {
    # Starts 26 cm out: nearer the base, top-down grasps are at the edge of the arm's reach.
    "open_space": Rect(0.26, 0.70, -0.20, 0.20, 0.0),
    "prepush_a": Rect(0.24, 0.37, 0.24, 0.52, 0.0),
    "prepush_b": Rect(0.24, 0.37, -0.52, -0.24, 0.0),
}

# --- derived limits, shared by the validator, the transition model and the PDDL domain ---

# The cell each resting object is given when a surface is counted: the grid of SPOT cells that
# fits on a surface, with objects resting long side along y (`PLACE_LONG_AXIS_YAW`), leaves
# every object at least 1.5 cm of room for the open fingers. Measured: with 10 cm cells two
# boxes (10.4 cm) cannot lie in a 22 cm deep shelf top with that room. Counting cells (not
# areas) keeps capacities small integers that the PDDL domain can encode.
SPOT = 0.11

# A top face narrower than this does not hold another object steadily (popcorn's 3.8 cm does not).
MIN_SUPPORT_SIDE = 0.045

# Highest a tower's top may rise above the table: the hand holds the top object from above and
# still needs room to approach and to withdraw.
REACH_MAX_Z = 0.40

MAX_OBJECTS = 12


def spot_cells(rect: Rect) -> list[tuple[float, float]]:
    """Centres of the cells a surface is counted in (its capacity), spread evenly over it."""
    nx, ny = math.floor(rect.width_x / SPOT + 1e-9), math.floor(rect.width_y / SPOT + 1e-9)
    return [
        (rect.x_min + rect.width_x * (i + 0.5) / nx, rect.y_min + rect.width_y * (j + 0.5) / ny)
        for i in range(nx)
        for j in range(ny)
    ]


def capacity(rect: Rect) -> int:
    """How many objects fit side by side on a rectangle: its SPOT cells."""
    return len(spot_cells(rect))


def surface_rect(name: str) -> Rect:
    """The rectangle of a named surface: a region, or a shelf's top."""
    if name in REGIONS:
        return REGIONS[name]
    return SHELVES[name].top


SURFACES: tuple[str, ...] = tuple(REGIONS) + tuple(SHELVES)

SURFACE_CAPACITY: dict[str, int] = {name: capacity(surface_rect(name)) for name in SURFACES}
# Objects enter an interior only through its open front, so it is filled as one row across,
# a can's width plus a finger's gap apart (pushes measured to land within +-9 cm of the middle).
INTERIOR_SPOT = 0.09
INTERIOR_CAPACITY: dict[str, int] = {
    name: math.floor(s.interior.width_y / INTERIOR_SPOT + 1e-9) for name, s in SHELVES.items()
}


def interior_slots(shelf: str) -> list[float]:
    """y of each spot in a shelf's interior row, evenly spread across its width."""
    r = SHELVES[shelf].interior
    n = INTERIOR_CAPACITY[shelf]
    return [r.y_min + r.width_y * (k + 0.5) / n for k in range(n)]


def max_tower_levels() -> int:
    """How many objects one tower may hold so that any tower stays within reach on any surface.

    Counted with the tallest object, so a tower that obeys it never rises past `REACH_MAX_Z`,
    whatever it is made of and whichever surface it stands on.
    """
    tallest = max(t.height for t in OBJECT_TYPES.values())
    highest_surface = max(surface_rect(n).z for n in SURFACES)
    return max(1, math.floor((REACH_MAX_Z - highest_surface) / tallest + 1e-9))


MAX_TOWER_LEVELS = max_tower_levels()


def can_support(type_name: str) -> bool:
    """Whether an object of this type may carry another one on its top face."""
    return OBJECT_TYPES[type_name].top_face_min_side >= MIN_SUPPORT_SIDE


def fits_inside(type_name: str, shelf: str) -> bool:
    """Whether an object of this type, as it rests, fits into a shelf's interior."""
    t, s = OBJECT_TYPES[type_name], SHELVES[shelf]
    return (
        t.height <= s.clearance
        and max(t.footprint) <= max(s.interior.width_x, s.interior.width_y)
        and min(t.footprint) <= min(s.interior.width_x, s.interior.width_y)
    )


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

# --- the paper's goal kinds ---

# Goal literals put an object on one of these shelf tops, stack it on another object, or put it
# into this shelf's interior (cans only, in evaluation goals); pushes go into the same shelf.
GOAL_SHELF_TOPS: tuple[str, ...] = ("shelf_a", "shelf_b")
GOAL_INTERIOR = "shelf_a"

# --- friction ---

# Lateral friction coefficients; PyBullet multiplies the two bodies' values at a contact.
FIXTURE_FRICTION = 0.6  # the table and the shelves' walls and top boards
OBJECT_FRICTION = 0.8  # the grocery objects
