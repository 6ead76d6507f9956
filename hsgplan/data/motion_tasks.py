"""Procedurally generated situations for self-supervised motion data, as CAVIN collects it.

A `MotionTask` is one situation drawn from `(primitive, seed, index)` alone, symbolically: which
objects are in the scene, which one is to be placed (already held) or pushed, onto which surface
or into which shelf, and where every other object rests. The physical scene is staged from it
by `hsgplan.sim.staging`; the collector then tries uniformly sampled parameter bins in it.

The draws, for `n` objects (2-6 distinct types, as in the simulated evaluation):
- place: the held object and its target surface are uniform; `crowding` other objects (uniform
  in 0..capacity-1, as many as there are) rest on the target, towers on them allowed, so that
  crowded shelf tops and regions are common; the rest go anywhere else there is room.
- push: the pushed object is a can on shelf A's prepush region (the only pushes the task
  domain makes); `crowding` other cans (uniform in 0..interior capacity-1) are already inside
  shelf A; the rest go anywhere there is room, the prepush region's other cell included.
  With `P_FELL_SHORT` the can starts where a push that fell short leaves it: at the shelf's
  open front, `front_gap` (uniform in `FRONT_GAPS`) short of its interior. Places never put it
  there, but in the loop a short push does, and from there only short pushes keep the hand
  out of the shelf: data without such starts taught the networks to push 10 cm or more from
  there, again and again (README, Table 1).
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from hsgplan.domain.errors import InvalidInputError
from hsgplan.domain.objects import objects_for_types
from hsgplan.domain.parameters import MotionPrimitive
from hsgplan.domain.predicates import Literal, in_grasp, inside, on
from hsgplan.domain.room import Room
from hsgplan.domain.scene import Kind, World
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# at most one object of each type; pushes go only into the goals' interior (`goal_interior`),
# as the task domain pushes only to fill it
MIN_OBJECTS = 2
P_STACK = 0.25  # chance that an object left to place goes on top of a bare one
P_FELL_SHORT = 0.3  # chance that a pushed can starts where a short push left it
# m the can's centre stands short of the interior's front: from just short of where f_m calls
# it inside, back to where the farthest place bin puts a can.
FRONT_GAPS = (0.005, 0.05)


@dataclass(frozen=True)
class MotionTask:
    """One situation to try a primitive in.

    Attributes:
        primitive: place or push.
        seed, index: what it was drawn from (the same pair always gives the same task).
        obj: the object to place (held in `state`) or to push (on the prepush region).
        target: the surface to place on, or the shelf to push into.
        crowding: how many other objects rest on the target surface or are inside the shelf.
        state: the symbolic arrangement the scene is staged in.
        front_gap: for a push, how far short of the shelf's interior the can's centre starts
            (None: wherever the stager puts it on the prepush region).
    """

    primitive: MotionPrimitive
    seed: int
    index: int
    obj: str
    target: str
    crowding: int
    state: SymbolicSceneGraph
    front_gap: float | None = None

    @property
    def subgoal(self) -> Literal:
        """The literal the primitive is meant to make true (the subgoal ĝ it serves)."""
        if self.primitive is MotionPrimitive.PLACE:
            return on(self.obj, self.target)
        return inside(self.obj, self.target)


def draw_task(
    primitive: MotionPrimitive,
    seed: int,
    index: int,
    world: World,
    fell_short: float = P_FELL_SHORT,
) -> MotionTask:
    """The task at `index` of the stream for `(primitive, seed)`, in `world`; a push starts
    where a short push left its can with chance `fell_short`. The draws are the same whatever
    the chance, but for whether a push starts short."""
    if index < 0:
        raise InvalidInputError(f"task index {index} cannot be negative")
    rng = random.Random(f"motion-{primitive.value}-{seed}-{index}")
    if primitive is MotionPrimitive.PLACE:
        return _draw_place(rng, seed, index, world)
    return _draw_push(rng, seed, index, world, fell_short)


def _draw_place(rng: random.Random, seed: int, index: int, world: World) -> MotionTask:
    objects = _objects(rng, world)
    obj = rng.choice(objects)
    target = rng.choice(world.surfaces)
    others = [o for o in objects if o != obj]
    crowding = rng.randint(0, min(world.surface_capacity[target] - 1, len(others)))
    rng.shuffle(others)
    literals = [in_grasp(obj)]
    literals += _arrange(others[:crowding], others[crowding:], target, rng, world, keep_off=target)
    state = SymbolicSceneGraph.from_literals(objects, literals, world=world)
    return MotionTask(MotionPrimitive.PLACE, seed, index, obj, target, crowding, state)


def _draw_push(
    rng: random.Random, seed: int, index: int, world: World, fell_short: float
) -> MotionTask:
    shelf = world.goal_interior
    if shelf is None:
        raise InvalidInputError(f"scene '{world.name}' has no shelf to push into")
    types = world.object_types
    cans = [t for t, k in types.items() if k.kind is Kind.CAN and world.fits_inside(t, shelf)]
    obj = rng.choice(cans)
    rest = [t for t in types if t != obj]
    chosen = [obj] + rng.sample(rest, rng.randint(MIN_OBJECTS, len(types)) - 1)
    objects = objects_for_types(chosen, world)
    others = [o for o in objects if o != obj]
    rng.shuffle(others)
    fitting = [o for o in others if world.object_type(o).name in cans]
    crowding = rng.randint(0, min(world.interior_capacity[shelf] - 1, len(fitting)))
    inside_now = fitting[:crowding]
    prepush = world.shelves[shelf].prepush
    literals = [on(obj, prepush)] + [inside(o, shelf) for o in inside_now]
    left = [o for o in others if o not in inside_now]
    literals += _arrange([], left, prepush, rng, world, taken={prepush: 1})
    state = SymbolicSceneGraph.from_literals(objects, literals, world=world)
    gap = rng.uniform(*FRONT_GAPS) if rng.random() < fell_short else None
    return MotionTask(MotionPrimitive.PUSH, seed, index, obj, shelf, crowding, state, gap)


def _objects(rng: random.Random, world: World) -> list[str]:
    n = rng.randint(MIN_OBJECTS, len(world.object_types))
    return list(objects_for_types(rng.sample(list(world.object_types), n), world))


def _arrange(
    on_target: list[str],
    elsewhere: list[str],
    target: str,
    rng: random.Random,
    world: World,
    keep_off: str | None = None,
    taken: dict[str, int] | None = None,
) -> list[Literal]:
    """On-literals for objects: `on_target` on the target surface, then `elsewhere` on any
    other surface with room or (with `P_STACK`) on a bare object, towers within their limit."""
    room = Room.left(interiors=(), on_top=taken, world=world)
    literals = []

    def put(o: str, where: str) -> None:
        literals.append(on(o, where))
        room.put_on(o, where)

    for o in on_target:
        put(o, target)
    for o in elsewhere:
        bases = room.bases()
        if bases and rng.random() < P_STACK:
            put(o, rng.choice(bases))
            continue
        put(o, rng.choice([s for s in room.free_tops() if s != keep_off]))
    return literals
