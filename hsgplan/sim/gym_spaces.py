"""The Gymnasium face of the world: its observation and action spaces, what fills the one and
what the other means.

Objects sit in slots, the scene's objects in canonical order (`sort_objects`), padded to
`MAX_OBJECTS`: a scene may hold several instances of one type, so slots, not types, name them
(each slot's type is part of the observation). The symbolic scene graph is a set of binary
arrays over the slots, the shelves and the regions. An action names a primitive, an object
slot, a place target (a slot, a shelf top or a region) and the discrete bins of the paper's
parametrisation (`BINS` in `domain/parameters.py`); the fields a primitive does not use are
ignored, so every sample of the space is an action.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from hsgplan.domain.parameters import (
    BINS,
    MotionPrimitive,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
)
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import MAX_OBJECTS, World
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import SymbolicSceneGraph

# The action's "primitive" indexes this tuple.
PRIMITIVES: tuple[type, ...] = (PickParams, PlaceParams, PushParams)
# A Box needs finite bounds; metres, far beyond the table, so only an object that fell off it
# (and keeps falling: there is no floor) is ever clipped.
POSITION_BOUND = 10.0


def _entities(world: World) -> int:
    return MAX_OBJECTS + len(world.fixtures)  # slots first, then the fixtures as graphs list them


def observation_space(world: World) -> spaces.Dict:
    """A fresh space of a world's scenes (each env seeds its own)."""
    return spaces.Dict(
        {
            # 0: an empty slot; k: an object of the world's k-th type
            "types": spaces.MultiDiscrete([len(world.type_list) + 1] * MAX_OBJECTS),
            # position (m) and quaternion xyzw per slot; zeros for an empty slot
            "poses": spaces.Box(-POSITION_BOUND, POSITION_BOUND, (MAX_OBJECTS, 7), np.float32),
            "on": spaces.MultiBinary([MAX_OBJECTS, _entities(world)]),  # On(slot i, entity j)
            # In(slot i, shelf j); a scene of no shelves keeps one column, always 0
            "inside": spaces.MultiBinary([MAX_OBJECTS, max(1, len(world.shelves))]),
            "in_grasp": spaces.MultiBinary(MAX_OBJECTS),
            "clear": spaces.MultiBinary(MAX_OBJECTS),
        }
    )


def action_space(world: World) -> spaces.Dict:
    """A fresh space of a world's scenes (each env seeds its own)."""
    return spaces.Dict(
        {
            "primitive": spaces.Discrete(len(PRIMITIVES)),
            "object": spaces.Discrete(MAX_OBJECTS),
            # place only: a slot, a shelf top or a region
            "target": spaces.Discrete(_entities(world)),
            "place_bins": spaces.MultiDiscrete(list(BINS[MotionPrimitive.PLACE])),  # x, y
            "push_bins": spaces.MultiDiscrete(list(BINS[MotionPrimitive.PUSH])),  # angle, dist
        }
    )


def entity_names(objects: tuple[str, ...], world: World) -> list[str | None]:
    """The name at every entity index of a scene with these objects (None: an empty slot)."""
    return [*objects, *[None] * (MAX_OBJECTS - len(objects)), *world.fixtures]


def encode(
    objects: tuple[str, ...], sg: GeometricSceneGraph, state: SymbolicSceneGraph
) -> dict[str, np.ndarray]:
    """The numeric observation of a scene (its objects in slot order) in the state's world;
    an object the observer has never seen (not in `sg`) has its type and a zero pose."""
    world = state.world
    index = {name: i for i, name in enumerate(entity_names(objects, world)) if name is not None}
    obs = {k: np.zeros(s.shape, s.dtype) for k, s in observation_space(world).spaces.items()}
    types = list(world.object_types)
    for i, name in enumerate(objects):
        obs["types"][i] = types.index(world.type_of(name)) + 1
        if name not in sg.objects:
            continue
        pose = sg.pose(name)
        values = np.nan_to_num(pose.position + pose.orientation)  # NaN: a physics blow-up
        obs["poses"][i] = np.clip(values, -POSITION_BOUND, POSITION_BOUND)
    for lit in state.literals:
        slot = index[lit.args[0]]
        if lit.predicate is Predicate.ON:
            obs["on"][slot, index[lit.args[1]]] = 1
        elif lit.predicate is Predicate.IN:
            obs["inside"][slot, list(world.shelves).index(lit.args[1])] = 1
        elif lit.predicate is Predicate.IN_GRASP:
            obs["in_grasp"][slot] = 1
        elif lit.predicate is Predicate.CLEAR:
            obs["clear"][slot] = 1
    return obs


def decode(objects: tuple[str, ...], action: dict, world: World) -> PrimitiveParams | str:
    """The typed primitive an action names, or why it names none (an empty slot)."""
    names = entity_names(objects, world)
    obj = names[int(action["object"])]
    if obj is None:
        return f"object slot {int(action['object'])} is empty"
    kind = PRIMITIVES[int(action["primitive"])]
    if kind is PickParams:
        return PickParams(obj)
    if kind is PushParams:
        angle, dist = (int(b) for b in action["push_bins"])
        return PushParams(obj, angle, dist)
    target = names[int(action["target"])]
    if target is None:
        return f"target slot {int(action['target'])} is empty"
    if target in world.fixtures:
        x, y = (int(b) for b in action["place_bins"])
        return PlaceParams(obj, target, x, y)
    return PlaceParams(obj, target)  # stacked: the position comes from the object below
