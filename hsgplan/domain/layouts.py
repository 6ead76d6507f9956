"""Random layouts of a world: shelves moved and resized, groceries resized, or groceries never
seen before. Their scene files are what the learned planners are measured on, beyond the scene
they were trained in (`hsgplan scenes`).

The ranges (documented in docs/scenes.md) keep every layout one the Panda can work: the shelves
stay in front of it and within reach, their tops within the tower-height rule, every object's
narrow side within what the gripper opens.
"""

from __future__ import annotations

import random
import re
from collections import Counter
from dataclasses import replace
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import GRIPPER_MAX_OPENING, Kind, ObjectType, Shelf, World
from hsgplan.domain.scene_file import (
    derived_prepush_name,
    derived_prepush_span,
    world_of,
)
from hsgplan.domain.scene_write import object_data, scene_data, to_toml
from hsgplan.files import write_atomically

SHELF_NEAR = (0.34, 0.44)  # x of a shelf's open front
SHELF_DEPTH = (0.20, 0.26)
SHELF_WIDTH = (0.28, 0.36)
SHELF_SIDE_GAP = (0.02, 0.08)  # between the open space's side and the shelf beside it
SHELF_CLEARANCE = (0.11, 0.14)
OBJECT_SCALE = (0.8, 1.2)  # each dimension of each object type, drawn apart
# A shelf that does not stand beside the open space facing the robot (turned, behind it, on
# another side) keeps its place, moved within SHELF_SHIFT along each of its own axes, its
# depth, width and clearance scaled within SHELF_SCALE of its own.
SHELF_SHIFT = 0.04
SHELF_SCALE = (0.9, 1.1)
MAX_GRASP = GRIPPER_MAX_OPENING - 0.004  # a resized object's narrow side
TRIES = 200
# A layout's goal shelf tops hold at least this many objects, and its towers this many levels,
# so that goals of every size (2 to 6 objects) and every kind the paper measures can be drawn.
GOAL_ROOM = 6
TOWER_LEVELS = 2
# Groceries no model was trained on, by kind: drawn without replacement for `--new-objects`.
NEW_NAMES = {
    Kind.CAN: ("peaches", "corn", "tuna", "beans", "coconut_milk"),
    Kind.BOX: ("crackers", "tea", "rice", "pasta", "oats"),
}
NEW_CAN = ((0.060, 0.076), (0.050, 0.110))  # diameter, height
NEW_BOX = ((0.030, 0.070), (0.080, 0.130), (0.020, 0.130))  # along x (grasped), along y, height


def _span(rng: random.Random, bounds: tuple[float, float]) -> float:
    return round(rng.uniform(*bounds), 3)


def beside_open_space(base: World) -> bool:
    """Whether every shelf faces the robot (yaw 0) beside the open space, on one side of it or
    the other, as the kitchen's do: such a scene's shelves are drawn along its sides."""
    space = base.regions.get("open_space")
    return space is not None and all(
        s.yaw_degrees == 0.0 and (s.outer.y_min >= space.y_max or s.outer.y_max <= space.y_min)
        for s in base.shelf_list
    )


def _shelves(base: World, rng: random.Random, turn: float = 0.0) -> list[dict]:
    """Each shelf moved and resized on the side of the robot it stands on; shelves sharing a
    side keep their order outwards from the open space, each beyond the one before. With a
    `turn` (degrees), each shelf's yaw is its base's plus a uniform draw within +-`turn` (drawn
    only then, so that layouts drawn without one stay as they were). A scene whose shelves do
    not all stand so (`beside_open_space`) has each moved about its own place instead."""
    if not beside_open_space(base):
        return [_moved(s, rng, turn) for s in base.shelf_list]
    open_space = base.regions["open_space"]
    out: dict[str, dict] = {}
    for left in (True, False):
        side = [s for s in base.shelf_list if (s.outer.y_min >= 0) == left]
        side.sort(key=lambda s: abs(s.outer.y_min + s.outer.y_max))  # nearest the middle first
        edge = open_space.y_max if left else open_space.y_min
        for s in side:
            near, depth = _span(rng, SHELF_NEAR), _span(rng, SHELF_DEPTH)
            width, gap = _span(rng, SHELF_WIDTH), _span(rng, SHELF_SIDE_GAP)
            y = (edge + gap, edge + gap + width) if left else (edge - gap - width, edge - gap)
            edge = y[1] if left else y[0]
            out[s.name] = {
                "name": s.name,
                "x": [near, round(near + depth, 3)],
                "y": [round(v, 3) for v in y],
                "clearance": _span(rng, SHELF_CLEARANCE),
                "wall": s.wall,
                "interior": s.interior is not None,
            }  # fmt: skip
            _turned(out[s.name], s, rng, turn)
            _named_prepush(out[s.name], s)
    return [out[s.name] for s in base.shelf_list]


def _moved(s: Shelf, rng: random.Random, turn: float) -> dict:
    """A shelf moved within `SHELF_SHIFT` and resized within `SHELF_SCALE` of its own place and
    size, in the scene file's frame of it (before its yaw turns it)."""
    x0, x1, y0, y1 = s.outer.x_min, s.outer.x_max, s.outer.y_min, s.outer.y_max  # unturned
    cx, cy = (
        (x0 + x1) / 2 + rng.uniform(-SHELF_SHIFT, SHELF_SHIFT),
        (y0 + y1) / 2 + rng.uniform(-SHELF_SHIFT, SHELF_SHIFT),
    )
    depth, width = (x1 - x0) * rng.uniform(*SHELF_SCALE), (y1 - y0) * rng.uniform(*SHELF_SCALE)
    entry = {
        "name": s.name,
        "x": [round(cx - depth / 2, 3), round(cx + depth / 2, 3)],
        "y": [round(cy - width / 2, 3), round(cy + width / 2, 3)],
        "clearance": round(s.clearance * rng.uniform(*SHELF_SCALE), 3),
        "wall": s.wall,
        "interior": s.interior is not None,
    }
    _turned(entry, s, rng, turn)
    _named_prepush(entry, s)
    return entry


def _turned(entry: dict, s: Shelf, rng: random.Random, turn: float) -> None:
    yaw = s.yaw_degrees + (round(rng.uniform(-turn, turn), 1) if turn else 0.0)
    yaw = (yaw + 180.0) % 360.0 - 180.0 if abs(yaw) > 180.0 else yaw
    if yaw:
        entry["yaw"] = yaw


def _named_prepush(entry: dict, s: Shelf) -> None:
    """A prepush region the base names otherwise than the derived one keeps its name, drawn
    where the derived one would stand (in front of the moved shelf)."""
    if s.prepush is None or s.prepush == derived_prepush_name(s.name):
        return
    x, y = derived_prepush_span(entry["x"], entry["y"], s.wall)
    entry["prepush"] = {"name": s.prepush, "x": x, "y": y}


def _resized(t: ObjectType, rng: random.Random) -> ObjectType:
    while True:
        x, y, h = (round(v * rng.uniform(*OBJECT_SCALE), 3) for v in t.size)
        if t.kind is Kind.CAN:
            y = x
        if min(x, y) <= MAX_GRASP:
            return replace(t, size=(x, y, h))


def _new(kind: Kind, name: str, rng: random.Random) -> ObjectType:
    if kind is Kind.CAN:
        d, h = _span(rng, NEW_CAN[0]), _span(rng, NEW_CAN[1])
        size = (d, d, h)
    else:
        size = tuple(_span(rng, r) for r in NEW_BOX)
    colour = tuple(round(rng.uniform(0.05, 0.95), 2) for _ in range(3))
    mass = 0.30 if kind is Kind.CAN else 0.15
    return ObjectType(name, kind, size, (*colour, 1.0), mass, 0.8)


def _objects(base: World, rng: random.Random, new_objects: bool) -> list[ObjectType]:
    if not new_objects:
        return [_resized(t, rng) for t in base.type_list]
    names = {k: rng.sample(v, len(v)) for k, v in NEW_NAMES.items()}
    return [_new(t.kind, names[t.kind].pop(), rng) for t in base.type_list]


def random_layout(
    base: World, seed: int, index: int, new_objects: bool = False, turn: float = 0.0
) -> World:
    """Layout `index` of `seed`: `base` with its shelves moved, resized (and, with `turn`,
    turned) and its object types resized (or, with `new_objects`, replaced by as many new ones
    of each kind); the same arguments give the same world."""
    rng = random.Random(f"layout-{seed}-{index}-{int(new_objects)}" + (f"-{turn}" if turn else ""))
    why_not: Counter[str] = Counter()  # what refused the draws, said once the tries run out
    example: dict[str, str] = {}  # a refusal, as first said, for each with its numbers left out
    for _ in range(TRIES):
        data = scene_data(base)
        data["name"] = f"{base.name}-layout-{seed}-{index}" + ("-new" if new_objects else "")
        data["shelves"] = _shelves(base, rng, turn)
        data["objects"] = [object_data(t) for t in _objects(base, rng, new_objects)]
        try:
            world = world_of(data, "the layout")
        except InvalidInputError as e:  # a draw the scene file refuses: draw again
            said = str(e).splitlines()[0]
            why_not[example.setdefault(re.sub(r"-?\d+\.\d+", "#", said), said)] += 1
            continue
        if world.goal_top_room < GOAL_ROOM:
            why_not[f"its goal surfaces hold fewer than {GOAL_ROOM} objects"] += 1
        elif world.max_tower_levels < TOWER_LEVELS:
            why_not[f"its towers hold fewer than {TOWER_LEVELS} objects"] += 1
        else:
            return world
    reason, n = why_not.most_common(1)[0]
    raise InvalidInputError(
        f"no valid layout of '{base.name}' in {TRIES} draws (seed {seed}); most often "
        f"({n} of {TRIES}): {reason}"
    )


def write_layouts(
    base: World,
    layouts: int,
    seed: int,
    folder: Path,
    new_objects: bool = False,
    header: str = "",
    turn: float = 0.0,
) -> list[Path]:
    """Layouts 0 .. `layouts` - 1 of `seed` as scene files `layout-NNN.toml` in `folder`, with
    `header` as their first comment. A file already there with the same content is kept (a
    rerun, or one cut short, repeats nothing); one with other content is refused before
    anything is written."""
    stem = "new-objects" if new_objects else "layout"
    planned = []
    for index in range(layouts):
        path = folder / f"{stem}-{index:03d}.toml"
        world = random_layout(base, seed, index, new_objects, turn)
        text = f"# {header}\n" + to_toml(scene_data(world))
        if path.exists() and path.read_text() != text:
            raise InvalidInputError(f"'{path}' holds another scene; choose another --out")
        planned.append((path, text))
    folder.mkdir(parents=True, exist_ok=True)
    for path, text in planned:
        if not path.exists():
            write_atomically(path, text)
    return [p for p, _ in planned]
