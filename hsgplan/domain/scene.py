"""A world as data: the table, its shelves and regions, the object types and the cameras, and
the limits every part of the product derives from them.

A `World` is read from a scene file (`domain/scene_file.py`; the default is
`scenes/kitchen.toml`). The counting rules at the bottom (capacities, tower height) are what the
goal validator, the symbolic transition model and the PDDL domain all enforce, so the three
agree by construction, in whatever scene they are given.

Frame: origin at the robot base on the table top, z up, x away from the robot, y to the left.
All lengths are metres.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property

from hsgplan.domain.errors import InvalidInputError, UnknownNameError
from hsgplan.domain.rect import Rect


class Kind(StrEnum):
    CAN = "can"
    BOX = "box"


class EntityKind(StrEnum):
    OBJECT = "object"
    SHELF = "shelf"
    REGION = "region"


# A scene holds at most this many objects (instances are numbered up to it).
MAX_OBJECTS = 12
# What a learned network reads a scene by: "names" (one-hots over the kitchen's names, the
# paper's) or "geometry" (what the scene file says of each node); see docs/scenes.md.
FEATURES = ("names", "geometry")


def check_features(features: str) -> None:
    """Refuse, in one line, an encoding that is not one of FEATURES."""
    if features not in FEATURES:
        raise InvalidInputError(f"features '{features}': one of {', '.join(FEATURES)}")


_INSTANCE = re.compile(r"^(?P<type>[a-z][a-z_]*?)(?:_(?P<k>[0-9]+))?$")


@dataclass(frozen=True)
class ObjectType:
    """A kind of grocery item, described in the orientation it rests in.

    `size` is (extent along x, extent along y, height) when resting; for cans the first two are
    the diameter. Boxes rest so that the gripper (max opening `GRIPPER_MAX_OPENING`) can close
    across their narrow horizontal side: in the kitchen, cream cheese and butter lie flat,
    popcorn stands upright because its flat footprint (12.6 x 8.5 cm) is wider than the gripper
    opens. `color` is RGBA in [0, 1]; `friction` the lateral friction coefficient (PyBullet
    multiplies the two bodies' values at a contact).
    """

    name: str
    kind: Kind
    size: tuple[float, float, float]
    color: tuple[float, float, float, float]
    mass: float = 0.3
    friction: float = 0.8

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


@dataclass(frozen=True)
class Shelf:
    """An open-fronted cabinet, open at the low-x side of its own frame: turned by
    `yaw_degrees` about its footprint's centre, it faces that way.

    `outer` is its footprint on the table; `interior` the floor of the space inside (the table
    itself, so objects can be pushed in), None for a closed cabinet; `top` the flat board
    objects are placed on; `prepush` the region in front of it that pushes start from. Each
    rectangle turns with the shelf (`Rect.yaw`, `Rect.pivot`).
    """

    name: str
    outer: Rect
    interior: Rect | None
    clearance: float
    top: Rect
    prepush: str | None
    wall: float = 0.02
    yaw_degrees: float = 0.0


@dataclass(frozen=True)
class Board:
    """One box of a shelf: its footprint and the heights of its bottom and top faces."""

    rect: Rect
    z_min: float
    z_max: float


@dataclass(frozen=True)
class View:
    """A fixed camera the robot sees with: image size, pose (eye, the point it looks at, z up)
    and vertical field of view in degrees."""

    width: int
    height: int
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    fov: float


def make_shelf(
    name: str,
    x: tuple[float, float],
    y: tuple[float, float],
    clearance: float,
    wall: float,
    interior: bool,
    prepush: str | None,
    yaw_degrees: float = 0.0,
) -> Shelf:
    """A shelf from its footprint (in its own frame): walls `wall` thick, its top board on walls
    `clearance` high, turned by `yaw_degrees` about the footprint's centre."""
    turn = shelf_turn(x, y, yaw_degrees)
    outer = Rect(x[0], x[1], y[0], y[1], 0.0, **turn)
    inside = Rect(x[0], x[1] - wall, y[0] + wall, y[1] - wall, 0.0, **turn) if interior else None
    top = Rect(x[0], x[1], y[0], y[1], clearance + wall, **turn)
    return Shelf(name, outer, inside, clearance, top, prepush, wall, yaw_degrees)


def shelf_turn(x: tuple[float, float], y: tuple[float, float], yaw_degrees: float) -> dict:
    """The `Rect` fields that turn a rectangle with a shelf of this footprint (none unturned,
    so that an unturned shelf's rectangles are the plain ones they always were)."""
    if yaw_degrees == 0.0:
        return {}
    return {"yaw": math.radians(yaw_degrees), "pivot": ((x[0] + x[1]) / 2, (y[0] + y[1]) / 2)}


def shelf_boards(shelf: Shelf) -> tuple[Board, ...]:
    """A shelf's side walls, back wall and top board (and a front board when it has no
    interior); the floor is the table."""
    o, c, w = shelf.outer, shelf.clearance, shelf.wall
    turn = {"yaw": o.yaw, "pivot": o.pivot} if o.yaw else {}
    left = Rect(o.x_min, o.x_max, o.y_max - w, o.y_max, **turn)
    right = Rect(o.x_min, o.x_max, o.y_min, o.y_min + w, **turn)
    back = Rect(o.x_max - w, o.x_max, o.y_min + w, o.y_max - w, **turn)
    walls = [left, right, back]
    if shelf.interior is None:
        walls.append(Rect(o.x_min, o.x_min + w, o.y_min + w, o.y_max - w, **turn))
    return (*(Board(r, 0.0, c) for r in walls), Board(o, c, shelf.top.z))


# --- the rules every world is counted by (the robot's and the paper's, not the scene's) ---

GRIPPER_MAX_OPENING = 0.08

# The least cell each resting object is given when a surface is counted: the grid of cells that
# fits on a surface, with objects resting long side along y (`PLACE_LONG_AXIS_YAW`), leaves
# every kitchen object at least 1.5 cm of room for the open fingers. Measured: with 10 cm cells
# two boxes (10.4 cm) cannot lie in a 22 cm deep shelf top with that room. Counting cells (not
# areas) keeps capacities small integers that the PDDL domain can encode. A scene with larger
# objects counts in larger cells (`World.cell`).
SPOT = 0.11
# A cell holds its scene's largest footprint with this room: across the grasp (x) the open
# fingers' on either side; along the long side (y) the gap the kitchen's cells leave between its
# two longest boxes (11 cm cells, 10.4 cm boxes).
FINGER_ROOM = 0.015
ALONG_GAP = 0.006

# A top face narrower than this does not hold another object steadily (popcorn's 3.8 cm does not).
MIN_SUPPORT_SIDE = 0.045

# Highest a tower's top may rise above the table: the hand holds the top object from above and
# still needs room to approach and to withdraw.
REACH_MAX_Z = 0.40

# Farthest from the base's axis (horizontally) the hand reaches top-down at every height up to
# `REACH_MAX_Z`: the arm's inverse kinematics reaches 0.73-0.81 m in every direction (least at
# the top height), kept inside the least (a test holds the arm to it). A surface all of whose
# cells lie farther is out of reach.
REACH_MAX_XY = 0.72

# The robot's base on the table, around the origin: the collision box of the Panda's base link
# (its URDF; a test holds this to it). No fixture may stand on it.
ROBOT_BASE = Rect(-0.16, 0.08, -0.10, 0.10)

# Objects enter an interior only through its open front, so it is filled as one row across,
# a can's width plus a finger's gap apart (pushes measured to land within +-9 cm of the middle).
INTERIOR_SPOT = 0.09

# The region every world has: where objects are put aside and most start.
OPEN_SPACE = "open_space"


def spot_cells(rect: Rect, cell: tuple[float, float] = (SPOT, SPOT)) -> list[tuple[float, float]]:
    """World centres of the cells (at least `cell` wide along the surface's own x and y) a
    surface is counted in (its capacity), spread evenly over it."""
    nx = math.floor(rect.width_x / cell[0] + 1e-9)
    ny = math.floor(rect.width_y / cell[1] + 1e-9)
    return [
        rect.to_world(
            rect.x_min + rect.width_x * (i + 0.5) / nx, rect.y_min + rect.width_y * (j + 0.5) / ny
        )
        for i in range(nx)
        for j in range(ny)
    ]


@dataclass(frozen=True)
class World:
    """Everything a scene file says, and what follows from it.

    Attributes:
        regions: the regions on the table in the order the scene lists them (the open space
            first, then each shelf's prepush region); entity one-hots and PDDL objects follow
            this order, and that of `shelves` and `object_types`.
        goal_surfaces: the surfaces goal literals put objects on: shelf tops, then any regions
            the scene names for goals (a scene of no shelves has only those).
        goal_interior: the shelf whose interior `In` goals name (cans only, in evaluation
            goals); None in a scene where no shelf has an interior.
        fixture_friction: the table's and the shelves' lateral friction.
        cameras: the fixed views f_p sees the scene with.
    """

    name: str
    table: Rect
    shelf_list: tuple[Shelf, ...]
    region_list: tuple[tuple[str, Rect], ...]
    type_list: tuple[ObjectType, ...]
    goal_surfaces: tuple[str, ...]
    goal_interior: str | None
    fixture_friction: float
    cameras: tuple[View, ...]

    @cached_property
    def shelves(self) -> dict[str, Shelf]:
        return {s.name: s for s in self.shelf_list}

    @cached_property
    def regions(self) -> dict[str, Rect]:
        return dict(self.region_list)

    @cached_property
    def object_types(self) -> dict[str, ObjectType]:
        return {t.name: t for t in self.type_list}

    @cached_property
    def surfaces(self) -> tuple[str, ...]:
        """Every surface objects rest on: the regions, then the shelf tops."""
        return tuple(self.regions) + tuple(self.shelves)

    def surface_rect(self, name: str) -> Rect:
        """The rectangle of a named surface: a region, or a shelf's top."""
        if name in self.regions:
            return self.regions[name]
        return self.shelves[name].top

    @cached_property
    def cell(self) -> tuple[float, float]:
        """The cell (along x, along y) each resting object is counted in: the scene's widest
        and longest footprints with their room, never below the measured `SPOT`, so that any
        mix of its objects fits the count (as towers are counted with the tallest)."""
        # as objects rest on a surface: narrow side across the grasp (x), long side along y
        widest = max(min(t.footprint) for t in self.type_list)
        longest = max(max(t.footprint) for t in self.type_list)
        return max(SPOT, widest + 2 * FINGER_ROOM), max(SPOT, longest + ALONG_GAP)

    def grid_cells(self, surface: str) -> list[tuple[float, float]]:
        """Centres of every cell a named surface's size makes room for, reached or not."""
        return spot_cells(self.surface_rect(surface), self.cell)

    def spot_cells(self, surface: str) -> list[tuple[float, float]]:
        """Centres of the cells a named surface is counted in: those of its grid within the
        hand's reach (`REACH_MAX_XY`), since an object the arm cannot reach is neither put
        there nor taken from there (a shelf of a drawn layout may stand half beyond it)."""
        return [c for c in self.grid_cells(surface) if math.hypot(*c) <= REACH_MAX_XY]

    @cached_property
    def surface_capacity(self) -> dict[str, int]:
        """Objects each surface holds side by side: its cells within reach."""
        return {name: len(self.spot_cells(name)) for name in self.surfaces}

    @cached_property
    def goal_top_room(self) -> int:
        """Objects the goal surfaces hold side by side."""
        return sum(self.surface_capacity[t] for t in self.goal_surfaces)

    @cached_property
    def interior_capacity(self) -> dict[str, int]:
        """Objects each shelf's interior holds in its row (shelves with an interior only)."""
        return {
            name: math.floor(s.interior.width_y / INTERIOR_SPOT + 1e-9)
            for name, s in self.shelves.items()
            if s.interior is not None
        }

    def interior_slots(self, shelf: str) -> list[float]:
        """y of each spot in a shelf's interior row, evenly spread across its width, in the
        shelf's own frame (`Rect.to_world` with its interior's x gives the world point)."""
        r = self.shelves[shelf].interior
        assert r is not None, f"{shelf} has no interior"
        n = self.interior_capacity[shelf]
        return [r.y_min + r.width_y * (k + 0.5) / n for k in range(n)]

    @cached_property
    def max_tower_levels(self) -> int:
        """How many objects one tower may hold so that any tower stays within reach on any
        surface.

        Counted with the tallest object, so a tower that obeys it never rises past
        `REACH_MAX_Z`, whatever it is made of and whichever surface it stands on.
        """
        tallest = max(t.height for t in self.type_list)
        highest_surface = max(self.surface_rect(n).z for n in self.surfaces)
        return max(1, math.floor((REACH_MAX_Z - highest_surface) / tallest + 1e-9))

    def can_support(self, type_name: str) -> bool:
        """Whether an object of this type may carry another one on its top face."""
        return self.object_types[type_name].top_face_min_side >= MIN_SUPPORT_SIDE

    def fits_inside(self, type_name: str, shelf: str) -> bool:
        """Whether an object of this type, as it rests, fits into a shelf's interior."""
        t, s = self.object_types[type_name], self.shelves[shelf]
        if s.interior is None:
            return False
        return (
            t.height <= s.clearance
            and max(t.footprint) <= max(s.interior.width_x, s.interior.width_y)
            and min(t.footprint) <= min(s.interior.width_x, s.interior.width_y)
        )

    def prepush_shelf(self, x: float, y: float) -> str | None:
        """The shelf whose prepush region (within 1 cm) holds the point, if any."""
        for s in self.shelf_list:
            if s.prepush and self.regions[s.prepush].contains(x, y, margin=0.01):
                return s.name
        return None

    # --- names: object instances are named by their type (`cherries`, `cherries_2`, ...) ---

    @cached_property
    def fixtures(self) -> tuple[str, ...]:
        """The shelves, then the regions: every node of a scene graph that is no object."""
        return tuple(self.shelves) + tuple(self.regions)

    @cached_property
    def entity_types(self) -> tuple[str, ...]:
        """Entity types in a fixed order: the object types, the shelves, the regions."""
        return tuple(self.object_types) + self.fixtures

    def split_instance(self, name: str) -> tuple[str, int]:
        """(type, k) of an object instance name; raises UnknownNameError with the reason."""
        if name in self.object_types:
            return name, 1
        m = _INSTANCE.match(name)
        if m and m.group("type") in self.object_types and m.group("k") is not None:
            k = int(m.group("k"))
            if k < 2 or str(k) != m.group("k"):
                t = m.group("type")
                raise UnknownNameError(
                    f"unknown object '{name}' (the first {t} is named '{t}', "
                    f"later ones '{t}_2', '{t}_3', ...)"
                )
            if k > MAX_OBJECTS:
                raise UnknownNameError(
                    f"unknown object '{name}' (a scene holds at most {MAX_OBJECTS})"
                )
            return m.group("type"), k
        raise UnknownNameError(f"unknown name '{name}'")

    def kind_of(self, name: str) -> EntityKind:
        """Whether a name is an object, a shelf or a region; raises UnknownNameError otherwise."""
        if name in self.shelves:
            return EntityKind.SHELF
        if name in self.regions:
            return EntityKind.REGION
        self.split_instance(name)
        return EntityKind.OBJECT

    def type_of(self, name: str) -> str:
        """The entity type of a name: the object type for instances, the name itself
        otherwise."""
        return self.split_instance(name)[0] if self.kind_of(name) is EntityKind.OBJECT else name

    def object_type(self, name: str) -> ObjectType:
        """The type of an object instance."""
        return self.object_types[self.split_instance(name)[0]]

    def sort_objects(self, names: Iterable[str]) -> tuple[str, ...]:
        """Object names in canonical order: by type as the scene lists them, then instance
        number."""
        order = {t: i for i, t in enumerate(self.object_types)}

        def key(n: str) -> tuple[int, int]:
            t, k = self.split_instance(n)
            return order[t], k

        return tuple(sorted(set(names), key=key))
