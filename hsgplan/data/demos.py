"""The paper's 18 short demonstrations: which tasks they are and their format on disk (the
recorder is `hsgplan.collect.demos`).

Tasks (fixed, so that the dataset is the same everywhere): place one object on a shelf top
(each of the six types once, shelves alternating), stack two objects on a shelf top (nine
pairs, each base a type that can carry), put one can into shelf A (each of the three cans).
None of them is an evaluation task: evaluation goals name 2 to 12 objects and leave stacking out
at 2 objects, while these name one object, or two stacked.

Each demonstration is an oracle episode (Fast Downward's plan, executed in simulation); the
symbolic scene graph is read by f_m from the simulator at every state. An episode that failed,
had a primitive fail on the way, or whose goal held from the start is retried with the next
seed; the seed that was kept is recorded.

On disk (`FORMAT`): a folder with `meta.json` (version, command, seed, and the scene file a set
was recorded in when it was not the kitchen's: `scene`) and `demos.jsonl`, one
demonstration per line: {"task", "goal", "seed", "objects", "actions": [str],
"states": [[literal, ...], ...]} with len(states) == len(actions) + 1; literals and actions are
in the goal / action text syntax.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, fields
from pathlib import Path

from hsgplan.domain.actions import Action, parse_action
from hsgplan.domain.checks import read_json, read_text
from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.goals import Goal, parse_goal
from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import recorded_worlds
from hsgplan.paths import shipped
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

VERSION = 1
FORMAT = "hsgplan-demos"
DEMOS = "demos.jsonl"
META = "meta.json"

_PLACE = [
    ("cherries", "shelf_a"),
    ("alphabet_soup", "shelf_b"),
    ("tomato_soup", "shelf_a"),
    ("popcorn", "shelf_b"),
    ("cream_cheese", "shelf_a"),
    ("butter", "shelf_b"),
]
_STACK = [  # (base, top, shelf)
    ("cherries", "butter", "shelf_a"),
    ("alphabet_soup", "cream_cheese", "shelf_b"),
    ("tomato_soup", "cherries", "shelf_a"),
    ("cream_cheese", "tomato_soup", "shelf_b"),
    ("butter", "alphabet_soup", "shelf_a"),
    ("cherries", "popcorn", "shelf_b"),
    ("cream_cheese", "butter", "shelf_a"),
    ("alphabet_soup", "tomato_soup", "shelf_b"),
    ("butter", "cherries", "shelf_a"),
]
_INSIDE = ["cherries", "alphabet_soup", "tomato_soup"]

TASKS: tuple[tuple[str, str], ...] = (
    tuple((f"place-{o}-{s}", f"On({o}, {s})") for o, s in _PLACE)
    + tuple((f"stack-{t}-on-{b}-{s}", f"On({b}, {s}) & On({t}, {b})") for b, t, s in _STACK)
    + tuple((f"inside-{o}-shelf_a", f"In({o}, shelf_a)") for o in _INSIDE)
)


@dataclass(frozen=True)
class Demo:
    """One demonstration: the goal, the seed of its scene, and its symbolic trajectory, in the
    world it was recorded in (not written: a dataset's world is its reader's to give)."""

    task: str
    goal: str
    seed: int
    objects: tuple[str, ...]
    actions: tuple[str, ...]
    states: tuple[tuple[str, ...], ...]
    world: World = field(kw_only=True, compare=False, repr=False)

    def to_json(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "world"}

    def goal_literals(self) -> Goal:
        return parse_goal(self.goal, world=self.world)

    def symbolic_states(self) -> list[SymbolicSceneGraph]:
        return [
            SymbolicSceneGraph.from_literals(
                self.objects,
                parse_goal(" & ".join(s), validate=False, world=self.world).literals,
                limits=False,
                world=self.world,
            )
            for s in self.states
        ]

    def symbolic_actions(self) -> list[Action]:
        return [parse_action(a, self.world) for a in self.actions]


def demos_world(folder: Path, default: World) -> World:
    """The world a demonstration set was recorded in: its `meta.json`'s scene file, else
    `default` (a set recorded without a scene records none)."""
    folder = shipped(folder)
    scene = read_json(folder / META, "demonstration metadata").get("scene")
    return recorded_worlds(scene, default, folder)[0]


def load_demos(folder: Path, world: World) -> list[Demo]:
    """The demonstrations of a dataset folder (found as `hsgplan.paths.shipped` finds it),
    recorded in `world`, checked; bad input raises InvalidInputError."""
    folder = shipped(folder)
    meta = read_json(folder / META, "demonstration metadata")
    if meta.get("format") != FORMAT or meta.get("version") != VERSION:
        raise InvalidInputError(f"'{folder}' is not a version {VERSION} demonstration dataset")
    demos = read_demos(folder / DEMOS, world, tolerate_cut=False)
    if not demos:
        raise InvalidInputError(f"'{folder / DEMOS}' holds no demonstration")
    return demos


def read_demos(path: Path, world: World, tolerate_cut: bool) -> list[Demo]:
    if not path.exists():
        return []
    demos = []
    for n, line in enumerate(read_text(path, "demonstrations").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            d = json.loads(line)
            demo = Demo(
                d["task"],
                d["goal"],
                int(d["seed"]),
                tuple(d["objects"]),
                tuple(d["actions"]),
                tuple(tuple(s) for s in d["states"]),
                world=world,
            )
            if len(demo.states) != len(demo.actions) + 1:
                raise ValueError("states and actions do not match")
        except (json.JSONDecodeError, KeyError, TypeError, ValueError) as e:
            if tolerate_cut:
                continue
            raise InvalidInputError(f"{path}:{n}: not a demonstration ({e})") from None
        demos.append(demo)
    return demos
