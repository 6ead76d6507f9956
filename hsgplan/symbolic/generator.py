"""Seeded random goals and random initial symbolic states.

The goal distribution, for n objects (2..12):
1. Objects: n distinct types drawn uniformly when n is at most the world's number of types
   (six in the kitchen); otherwise every type once plus duplicates drawn uniformly with
   replacement. Instances are named as in `objects.py`.
2. Each object, in a uniformly shuffled order, gets one literal of the paper's goal kinds, the
   kind drawn uniformly among those still feasible for it:
   - `On(o, top)` for each of the world's goal surfaces (in the kitchen `shelf_a` and
     `shelf_b`): on a shelf top, while the top has room;
   - `In(o, shelf)` for the world's goal interior (shelf A's in the kitchen): for cans, while
     the interior has room;
   - `On(o, b)`: stacked on an object b placed earlier on a shelf top, if b can carry it, is
     still bare and the tower stays within the height limit (b uniform among such objects).
   With `stacking=False` the stacked kind is left out (the paper does so for 2 objects).
Every goal drawn passes `check_literals`, by construction and by a final check.
"""

from __future__ import annotations

import random

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.feasibility import check_literals
from hsgplan.domain.goals import Goal
from hsgplan.domain.objects import draw_objects
from hsgplan.domain.predicates import Literal, inside, on
from hsgplan.domain.room import Room
from hsgplan.domain.scene import MAX_OBJECTS, OPEN_SPACE, Kind, World
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

MIN_OBJECTS = 2


def check_size(n: int) -> None:
    if not MIN_OBJECTS <= n <= MAX_OBJECTS:
        raise InvalidInputError(
            f"{n} object{'' if n == 1 else 's'}: a goal names between {MIN_OBJECTS} and "
            f"{MAX_OBJECTS} objects"
        )


def random_objects(n: int, rng: random.Random, world: World) -> tuple[str, ...]:
    """n object instances as the distribution above draws them, in canonical order."""
    check_size(n)
    return draw_objects(n, rng, world)


def random_goal(n: int, rng: random.Random, stacking: bool = True, *, world: World) -> Goal:
    """One goal over n objects, drawn from the distribution in the module docstring."""
    objects = list(random_objects(n, rng, world))
    rng.shuffle(objects)
    interior = world.goal_interior
    room = Room.left(world.goal_surfaces, () if interior is None else (interior,), world=world)
    literals: list[Literal] = []
    for o in objects:
        kinds: list[str] = room.free_tops()
        if world.object_type(o).kind is Kind.CAN and room.free_interiors(o):
            kinds.append("inside")
        bases = room.bases() if stacking else []
        if bases:
            kinds.append("stack")
        if not kinds:
            raise InvalidInputError(
                f"scene '{world.name}' has no room for a goal of {n} objects as goals are drawn "
                f"(its goal surfaces hold {world.goal_top_room})"
            )
        kind = rng.choice(kinds)
        if kind == "inside":
            literals.append(inside(o, interior))
            room.put_inside(o, interior)
            continue
        where = rng.choice(bases) if kind == "stack" else kind
        literals.append(on(o, where))
        room.put_on(o, where)
    goal = Goal(frozenset(literals), world)
    check_literals(goal.literals, world=world)
    return goal


def random_goals(
    n: int, count: int, seed: int, stacking: bool = True, *, world: World
) -> list[Goal]:
    """`count` goals over n objects; the same seed always gives the same goals."""
    if count < 0:
        raise InvalidInputError(f"count {count}: the number of goals cannot be negative")
    rng = random.Random(f"goals-{n}-{seed}")
    return [random_goal(n, rng, stacking=stacking, world=world) for _ in range(count)]


def random_state(
    objects: tuple[str, ...],
    rng: random.Random,
    p_elsewhere: float = 0.3,
    *,
    world: World,
) -> SymbolicSceneGraph:
    """A random start: most objects on the open space, some stacked or on a shelf top.

    Nothing starts held or inside a shelf, so every goal over these objects stays reachable.
    Each object, in shuffled order, goes elsewhere than the open space with `p_elsewhere`,
    then uniformly onto a shelf top with room or onto a bare object that can carry it.
    """
    order = list(objects)
    rng.shuffle(order)
    room = Room.left(interiors=(), world=world)
    literals = []
    for o in order:
        options: list[str] = []
        if rng.random() < p_elsewhere:
            options = room.free_tops(world.goal_surfaces) + room.bases()
        if not options:
            options = room.free_tops((OPEN_SPACE,)) or room.free_tops()
        target = rng.choice(options)
        literals.append(on(o, target))
        room.put_on(o, target)
    return SymbolicSceneGraph.from_literals(objects, literals, world=world)
