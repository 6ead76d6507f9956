"""The symbolic actions: pick, place and push, and their text form.

What they need and what they do is the transition model's business
(`hsgplan.symbolic.transition`); an agent names actions without consulting it.
"""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.scene import EntityKind, World


@dataclass(frozen=True)
class Pick:
    """Grasp a clear object from wherever it rests."""

    obj: str

    def __str__(self) -> str:
        return f"pick({self.obj})"


@dataclass(frozen=True)
class Place:
    """Put the held object on a region, a shelf top, or another object."""

    obj: str
    target: str

    def __str__(self) -> str:
        return f"place({self.obj}, {self.target})"


@dataclass(frozen=True)
class Push:
    """Push an object from a shelf's prepush region into the shelf's interior."""

    obj: str
    shelf: str

    def __str__(self) -> str:
        return f"push({self.obj}, {self.shelf})"


Action = Pick | Place | Push


def parse_action(text: str, world: World) -> Action:
    """`pick(o)`, `place(o, target)` or `push(o, shelf)` back into an action; its names must
    be the world's."""
    name, _, rest = text.strip().partition("(")
    args = [a.strip() for a in rest.rstrip(") ").split(",") if a.strip()]
    kinds = {"pick": (Pick, 1), "place": (Place, 2), "push": (Push, 2)}
    if name.strip() not in kinds or len(args) != kinds[name.strip()][1]:
        raise InvalidInputError(f"'{text}' is not an action (pick(o), place(o, x), push(o, shelf))")
    for a in args:
        world.kind_of(a)
    if world.kind_of(args[0]) is not EntityKind.OBJECT:
        raise InvalidInputError(f"'{text}': the first argument must be an object")
    cls = kinds[name.strip()][0]
    return cls(*args)


def intended_literal(action: Action) -> Literal:
    """The literal an action is taken for: what it holds after a pick, where it rests after a
    place, which shelf it is in after a push."""
    if isinstance(action, Pick):
        return in_grasp(action.obj)
    if isinstance(action, Place):
        return on(action.obj, action.target)
    return inside(action.obj, action.shelf)


def push_after(action: Action, world: World) -> Push | None:
    """The paper's heuristic from subgoal to primitive, one step on: an object placed on a
    shelf's prepush region is there to be pushed into that shelf."""
    if isinstance(action, Place):
        shelves = world.shelves.values()
        return next((Push(action.obj, s.name) for s in shelves if s.prepush == action.target), None)
    return None
