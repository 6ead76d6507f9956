"""A `World` written as a scene file: its TOML data (`scene_data`, what `scene_file.world_of`
reads back as an equal world) and that data as TOML text (`to_toml`)."""

from __future__ import annotations

import json
import re
from typing import Any

from hsgplan.domain.scene import ObjectType, Rect, World


def _span_out(r: Rect) -> dict:
    return {"x": [r.x_min, r.x_max], "y": [r.y_min, r.y_max]}


def object_data(t: ObjectType) -> dict:
    """An object type as a scene file's `[[objects]]` table."""
    return {"name": t.name, "kind": str(t.kind), "size": list(t.size), "colour": list(t.color),
            "mass": t.mass, "friction": t.friction}  # fmt: skip


def scene_data(world: World) -> dict:
    """A world as a scene file's TOML data (what `world_of` reads back as an equal world)."""
    prepush = {s.prepush for s in world.shelf_list}
    shelves = []
    for s in world.shelf_list:
        entry = {"name": s.name, **_span_out(s.outer), "clearance": s.clearance, "wall": s.wall,
                 "interior": s.interior is not None}  # fmt: skip
        if s.yaw_degrees:
            entry["yaw"] = s.yaw_degrees
        if s.prepush is not None:
            entry["prepush"] = {"name": s.prepush, **_span_out(world.regions[s.prepush])}
        shelves.append(entry)
    return {
        "name": world.name,
        "fixture_friction": world.fixture_friction,
        "table": _span_out(world.table),
        "regions": [{"name": n, **_span_out(r)} for n, r in world.region_list if n not in prepush],
        "shelves": shelves,
        "objects": [object_data(t) for t in world.type_list],
        "goals": _goals_data(world),
        "cameras": [
            {
                "width": c.width,
                "height": c.height,
                "eye": list(c.eye),
                "target": list(c.target),
                "fov": c.fov,
            }  # fmt: skip
            for c in world.cameras
        ],
    }


def _goals_data(world: World) -> dict:
    tops = [s for s in world.goal_surfaces if s in world.shelves]
    goals: dict[str, Any] = {"shelf_tops": tops}
    if regions := [r for r in world.goal_surfaces if r in world.regions]:
        goals["regions"] = regions
    if world.goal_interior is not None:
        goals["interior"] = world.goal_interior
    return goals


def _inline(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(map(_inline, v)) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_inline(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"no TOML for {v!r}")


def _key(k: str) -> str:
    return k if re.match(r"^[A-Za-z0-9_-]+$", k) else json.dumps(k)


def to_toml(data: dict) -> str:
    """A scene file's data as TOML: plain values first, then each table, then each list of
    tables; lists and nested tables inline, so a shelf or an object reads as one block."""
    plain = {k: v for k, v in data.items() if not isinstance(v, dict) and not _tables_list(v)}
    lines = [f"{_key(k)} = {_inline(v)}" for k, v in plain.items()]
    for k, v in data.items():
        if isinstance(v, dict):
            lines += ["", f"[{_key(k)}]", *(f"{_key(a)} = {_inline(b)}" for a, b in v.items())]
    for k, v in data.items():
        if _tables_list(v):
            for item in v:
                lines += [
                    "",
                    f"[[{_key(k)}]]",
                    *(f"{_key(a)} = {_inline(b)}" for a, b in item.items()),
                ]
    return "\n".join(lines) + "\n"


def _tables_list(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)
