"""Scene files: a `World` from TOML (and back, `scene_write`).

Every field is checked as it is read, and every bad one is refused, one line each naming the
file, the field's place (`shelves[2].clearance`) and what is wrong with it, as every other input
of the product is. docs/scenes.md describes the fields; `scenes/kitchen.toml` is the default
world.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Callable
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

from hsgplan.domain.checks import check_number, read_text
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.scene import (
    GRIPPER_MAX_OPENING,
    OPEN_SPACE,
    Kind,
    ObjectType,
    Rect,
    Shelf,
    View,
    World,
    make_shelf,
    shelf_turn,
)
from hsgplan.domain.workable import unworkable
from hsgplan.paths import KITCHEN_SCENE

MAX_SCENE_BYTES = 2**20
# No cap on fixtures but the table's: each takes at least a square of a shelf's least span (two
# of the thinnest walls and 5 cm between them), so a file asks for no more than its table holds.
FIXTURE_LEAST = 2 * 0.005 + 0.05
MAX_TYPES = 16
MAX_CAMERAS = 8
EXTENT = 3.0  # no table reaches further than this from the robot's base
TYPE_NAME = re.compile(r"^[a-z]+(?:_[a-z]+)*$")  # `_2` on a type name is its second instance
FIXTURE_NAME = re.compile(r"^[a-z][a-z0-9]*(?:_[a-z0-9]+)*$")
SCENE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,79}$")
# A prepush region a scene does not give: in front of its shelf's open side, inset from its walls
PREPUSH_DEPTH = 0.13
PREPUSH_GAP = 0.01


class _Bad(Exception):
    """A field refused: its place in the file and why (made one line by `read_world`)."""


class _Faults:
    """Every refusal of a file gathered, so that each bad field is named, not the first alone."""

    def __init__(self) -> None:
        self.said: list[str] = []

    def read(self, read: Callable[..., Any], *args: Any) -> Any:
        """`read(*args)`, or None with its refusal kept."""
        try:
            return read(*args)
        except _Bad as e:
            self.said.append(str(e))
            return None

    def check(self) -> None:
        """Refuse the file with every refusal kept so far, one line each."""
        if self.said:
            raise _Bad("\n".join(self.said))


def _number(v: Any, at: str, lo: float, hi: float) -> float:
    try:
        return check_number(at, v, lo, hi)  # the project's one number check, its words
    except InvalidInputError as e:
        raise _Bad(str(e)) from None


def _numbers(v: Any, at: str, count: int | tuple[int, ...], lo: float, hi: float) -> tuple:
    counts = (count,) if isinstance(count, int) else count
    if not isinstance(v, list) or len(v) not in counts:
        need = " or ".join(map(str, counts))
        raise _Bad(f"{at} {v!r}: need a list of {need} numbers")
    return tuple(_number(x, f"{at}[{k}]", lo, hi) for k, x in enumerate(v, 1))


def _span(v: Any, at: str) -> tuple[float, float]:
    low, high = _numbers(v, at, 2, -EXTENT, EXTENT)
    if low >= high:
        raise _Bad(f"{at} {v!r}: need [low, high] with low below high")
    return low, high


def _name(v: Any, at: str, pattern: re.Pattern) -> str:
    if not isinstance(v, str) or not pattern.match(v):
        allowed = {
            TYPE_NAME: "lower-case letters and underscores",
            FIXTURE_NAME: "lower-case letters, digits and underscores",
        }.get(pattern, "letters, digits, '.', '-' and '_'")
        raise _Bad(f"{at} {v!r}: need a name of {allowed}")
    return v


def _table(v: Any, at: str, required: set[str], optional: set[str] = frozenset()) -> dict:
    if not isinstance(v, dict):
        raise _Bad(f"{at}: need a table of fields")
    if missing := sorted(required - set(v)):
        raise _Bad(f"{at}: missing {', '.join(missing)}")
    if unknown := sorted(set(v) - required - set(optional)):
        raise _Bad(f"{at}: unknown field(s) {', '.join(map(repr, unknown))}")
    return v


def _tables(v: Any, at: str, lo: int, hi: int) -> list[dict]:
    if not isinstance(v, list) or not lo <= len(v) <= hi:
        raise _Bad(f"{at}: need between {lo} and {hi} of them ([[{at}]] tables)")
    return v


def _rect(v: dict, at: str, z: float = 0.0) -> Rect:
    (x0, x1), (y0, y1) = _span(v["x"], f"{at}.x"), _span(v["y"], f"{at}.y")
    return Rect(x0, x1, y0, y1, z)


def _object(v: Any, at: str) -> ObjectType:
    v = _table(v, at, {"name", "kind", "size", "colour"}, {"mass", "friction"})
    name = _name(v["name"], f"{at}.name", TYPE_NAME)
    if v["kind"] not in set(Kind):
        raise _Bad(f"{at}.kind {v['kind']!r}: need 'can' or 'box'")
    kind = Kind(v["kind"])
    size = _numbers(v["size"], f"{at}.size", 3, 0.01, 0.30)
    if kind is Kind.CAN and size[0] != size[1]:
        raise _Bad(f"{at}.size {v['size']!r}: a can's first two sizes are its diameter")
    if min(size[:2]) > GRIPPER_MAX_OPENING:
        raise _Bad(
            f"{at}.size {v['size']!r}: its narrow side is wider than the gripper opens "
            f"({GRIPPER_MAX_OPENING} m); stand it so that it is not"
        )
    colour = _numbers(v["colour"], f"{at}.colour", (3, 4), 0.0, 1.0)
    mass = _number(v.get("mass", 0.3), f"{at}.mass", 0.01, 5.0)
    friction = _number(v.get("friction", 0.8), f"{at}.friction", 0.05, 2.0)
    return ObjectType(name, kind, size, (*colour[:3], colour[3] if len(colour) == 4 else 1.0),
                      mass, friction)  # fmt: skip


def _shelf(v: Any, at: str) -> tuple[Shelf, tuple[str, Rect] | None]:
    v = _table(v, at, {"name", "x", "y"}, {"clearance", "wall", "interior", "prepush", "yaw"})
    name = _name(v["name"], f"{at}.name", FIXTURE_NAME)
    x, y = _span(v["x"], f"{at}.x"), _span(v["y"], f"{at}.y")
    yaw = _number(v.get("yaw", 0.0), f"{at}.yaw", -180.0, 180.0)
    turn = shelf_turn(x, y, yaw)
    clearance = _number(v.get("clearance", 0.12), f"{at}.clearance", 0.05, 0.40)
    wall = _number(v.get("wall", 0.02), f"{at}.wall", 0.005, 0.05)
    interior = v.get("interior", True)
    if not isinstance(interior, bool):
        raise _Bad(f"{at}.interior {interior!r}: true or false")
    for axis, (low, high) in (("x", x), ("y", y)):
        if high - low < 2 * wall + 0.05:
            raise _Bad(f"{at}.{axis} {[low, high]}: a shelf spans at least 5 cm between walls")
    prepush = None
    if "prepush" in v:
        if not interior:
            raise _Bad(f"{at}.prepush: a shelf with no interior has nothing to push into")
        p = _table(v["prepush"], f"{at}.prepush", {"name", "x", "y"})
        where = replace(_rect(p, f"{at}.prepush"), **turn)  # in the shelf's frame
        prepush = (_name(p["name"], f"{at}.prepush.name", FIXTURE_NAME), where)
    elif interior:
        (px0, px1), (py0, py1) = derived_prepush_span(x, y, wall)
        derived = Rect(px0, px1, py0, py1, **turn)
        prepush = (derived_prepush_name(name), derived)
    shelf = make_shelf(name, x, y, clearance, wall, interior, prepush[0] if prepush else None, yaw)
    return shelf, prepush


def derived_prepush_span(
    x: tuple[float, float], y: tuple[float, float], wall: float
) -> tuple[list[float], list[float]]:
    """The x and y spans of the prepush region derived for a shelf of these spans (in its
    unturned frame): in front of its open side, inset from its walls; rounded to a micrometre,
    so that a layout's file reads as it was drawn."""
    return (
        [round(x[0] - PREPUSH_GAP - PREPUSH_DEPTH, 6), round(x[0] - PREPUSH_GAP, 6)],
        [round(y[0] + wall, 6), round(y[1] - wall, 6)],
    )


def derived_prepush_name(shelf: str) -> str:
    """The name of the prepush region a scene derives for a shelf it gives none."""
    return "prepush_" + shelf.removeprefix("shelf_")


def _camera(v: Any, at: str) -> View:
    v = _table(v, at, {"width", "height", "eye", "target", "fov"})
    size = [v["width"], v["height"]]
    if any(isinstance(s, bool) or not isinstance(s, int) or not 16 <= s <= 4096 for s in size):
        raise _Bad(f"{at} width and height {size!r}: need whole pixels from 16 to 4096")
    eye = _numbers(v["eye"], f"{at}.eye", 3, -EXTENT, EXTENT)
    target = _numbers(v["target"], f"{at}.target", 3, -EXTENT, EXTENT)
    if eye == target:
        raise _Bad(f"{at}: the eye is where it looks")
    return View(size[0], size[1], eye, target, _number(v["fov"], f"{at}.fov", 1.0, 170.0))


def _each(
    v: Any, at: str, lo: int, hi: int, read: Callable[[Any, str], Any], faults: _Faults
) -> list:
    """Every table of an array read, the bad ones' refusals kept in `faults`."""
    tables = faults.read(_tables, v, at, lo, hi) or []
    read_ones = [faults.read(read, item, f"{at}[{k}]") for k, item in enumerate(tables, 1)]
    return [r for r in read_ones if r is not None]


def _places_problems(
    table: Rect, shelves: list[Shelf], regions: list[tuple[str, Rect]]
) -> list[str]:
    places = [(s.name, s.outer) for s in shelves] + regions
    problems = [
        f"{name} is not wholly on the table"
        for name, rect in places
        if not all(table.contains(x, y) for x, y in rect.corners())
    ]
    for k, (a, ra) in enumerate(places):
        problems += [f"{a} and {b} overlap" for b, rb in places[k + 1 :] if ra.overlaps(rb)]
    return problems


def _names_problems(types: list[ObjectType], fixtures: list[str]) -> list[str]:
    problems, seen = [], set()
    for name in [t.name for t in types] + fixtures:
        if name in seen:
            problems.append(f"the name {name!r} is given twice")
        seen.add(name)
    for name in fixtures:
        head, _, tail = name.rpartition("_")
        if head in {t.name for t in types} and tail.isdigit():
            problems.append(f"the name {name!r} reads as an instance of the object type {head!r}")
    return problems


def world_of(data: Any, source: str = "scene") -> World:
    """A `World` from a scene file's parsed TOML; every bad field refused, one line each
    (`InvalidInputError`), each starting with `source`; a scene whose fields read but that the
    robot cannot work in refused with every reason why, one line each (`unworkable`)."""
    try:
        world = _world(data)
    except _Bad as e:
        lines = str(e).splitlines()
        raise InvalidInputError("\n".join(f"{source}: {line}" for line in lines)) from None
    if problems := unworkable(world):
        raise InvalidInputError("\n".join(f"{source}: {p}" for p in problems))
    return world


def _region(v: Any, at: str) -> tuple[str, Rect]:
    r = _table(v, at, {"name", "x", "y"})
    return _name(r["name"], f"{at}.name", FIXTURE_NAME), _rect(r, at)


def _fixture_room(table: Rect | None) -> int:
    """How many fixtures (regions or shelves) a table holds apart, at most."""
    side = 2 * EXTENT if table is None else None  # a table refused: the largest there may be
    area = side * side if side else table.width_x * table.width_y
    return max(1, math.floor(area / FIXTURE_LEAST**2))


def _world(data: Any) -> World:
    top = _table(data, "the file", {"name", "table", "regions", "objects", "cameras"},
                 {"fixture_friction", "goals", "shelves"})  # fmt: skip
    faults = _Faults()
    name = faults.read(_name, top["name"], "name", SCENE_NAME)
    table = faults.read(lambda: _rect(_table(top["table"], "table", {"x", "y"}), "table"))
    friction = faults.read(_number, top.get("fixture_friction", 0.6), "fixture_friction", 0.05,
                           2.0)  # fmt: skip
    room = _fixture_room(table)
    regions = _each(top["regions"], "regions", 1, room, _region, faults)
    read = _each(top.get("shelves", []), "shelves", 0, room, _shelf, faults)
    types = _each(top["objects"], "objects", 1, MAX_TYPES, _object, faults)
    cameras = tuple(_each(top["cameras"], "cameras", 1, MAX_CAMERAS, _camera, faults))
    goals = faults.read(
        _table, top.get("goals", {}), "goals", set(), {"shelf_tops", "regions", "interior"}
    )
    faults.check()  # what follows reads the fields together
    if OPEN_SPACE not in dict(regions):
        faults.said.append(f"regions: need one named {OPEN_SPACE!r} (where objects are put aside)")
    shelves = [s for s, _ in read]
    regions += [p for _, p in read if p is not None]
    faults.said += _names_problems(types, [s.name for s in shelves] + [r for r, _ in regions])
    faults.said += _places_problems(table, shelves, regions)
    with_interior = [s.name for s in shelves if s.interior is not None]
    names = [s.name for s in shelves]
    tops = goals.get("shelf_tops", names)
    if not isinstance(tops, list) or any(t not in names for t in tops):
        faults.said.append(f"goals.shelf_tops {tops!r}: need a list of the scene's shelves")
        tops = []
    # regions goals may fill besides (or, in a scene of no shelves, instead of) shelf tops
    free = [r for r, _ in regions if r != OPEN_SPACE and r not in {s.prepush for s in shelves}]
    more = goals.get("regions", [])
    if not isinstance(more, list) or any(r not in free for r in more):
        faults.said.append(
            f"goals.regions {more!r}: need a list of the scene's regions other than the open "
            "space and prepush regions"
        )
        more = []
    if not tops + more:
        faults.said.append("goals: need a shelf top or a region for goals to fill")
    elif len(set(tops + more)) < len(tops + more):
        faults.said.append(f"goals: {tops + more!r} names a surface twice")
    interior = goals.get("interior", with_interior[0] if with_interior else None)
    if interior is not None and interior not in with_interior:
        faults.said.append(f"goals.interior {interior!r}: need a shelf with an interior")
    faults.check()
    return World(name, table, tuple(shelves), tuple(regions), tuple(types), (*tops, *more),
                 interior, friction, cameras)  # fmt: skip


@cache
def default_world() -> World:
    """The kitchen of `scenes/kitchen.toml`: the world of whatever names no scene, read the
    first time a run asks for it (never at import: a library module that reads a scene file
    as it is imported fails every command when that file is bad)."""
    return read_world(KITCHEN_SCENE)


def scene_world(scene: Path | str | None) -> World:
    """The world of a scene file, or the default world where none is given."""
    return default_world() if scene is None else read_world(scene)


def read_world(path: Path | str) -> World:
    """The world a scene file describes; everything wrong with it refused, one line each
    (`InvalidInputError`)."""
    return read_world_text(read_text(Path(path), "scene file", MAX_SCENE_BYTES), path)


def read_world_text(text: str, path: Path | str) -> World:
    """The world of a scene file's text (read from `path`, which refusals name)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InvalidInputError(f"scene file '{path}' is not valid TOML ({e})") from None
    return world_of(data, f"scene file '{path}'")


def scene_paths(path: Path | str) -> list[Path]:
    """A scene file, or a folder's scene files in the order work takes turns round them."""
    path = Path(path)
    return sorted(path.glob("*.toml")) if path.is_dir() else [path]


def scene_file_names(path: Path | str) -> list[str]:
    """The names of `scene_paths(path)`, as a collection round a folder records them."""
    return [p.name for p in scene_paths(path)]


def read_worlds(path: Path | str) -> dict[Path, World]:
    """The world of a scene file, or of every `.toml` file in a folder (by name), each read
    (and so checked) before anything runs."""
    path = Path(path)
    paths = scene_paths(path)
    if not paths:
        raise InvalidInputError(f"the folder '{path}' holds no scene file (*.toml)")
    return {p: read_world(p) for p in paths}


def recorded_worlds(scene: object, default: World, folder: Path | str) -> list[World]:
    """The worlds a data folder's metadata says it was made in: its `scene` (a scene file or a
    folder of them, in file order), else `default` (data made without a scene records none). A
    scene that is not found here is refused in one line."""
    if scene is None:
        return [default]
    if not isinstance(scene, str) or not Path(scene).exists():
        raise InvalidInputError(f"'{folder}' was made in scene {scene!r}, not found here")
    return list(read_worlds(scene).values())
