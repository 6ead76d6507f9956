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

from hsgplan.domain.objects import type_of
from hsgplan.domain.parameters import (
    BINS,
    MotionPrimitive,
    PickParams,
    PlaceParams,
    PrimitiveParams,
    PushParams,
)
from hsgplan.domain.predicates import Predicate
from hsgplan.domain.world import MAX_OBJECTS, OBJECT_TYPES, SHELVES
from hsgplan.scene_graph.geometric import GeometricSceneGraph
from hsgplan.scene_graph.symbolic import FIXTURES, SymbolicSceneGraph

# The action's "primitive" indexes this tuple.
PRIMITIVES: tuple[type, ...] = (PickParams, PlaceParams, PushParams)
ENTITIES = MAX_OBJECTS + len(FIXTURES)  # slots first, then the fixtures as the graphs list them
TYPES: tuple[str, ...] = tuple(OBJECT_TYPES)
# A Box needs finite bounds; metres, far beyond the table, so only an object that fell off it
# (and keeps falling: there is no floor) is ever clipped.
POSITION_BOUND = 10.0


def observation_space() -> spaces.Dict:
    """A fresh space (each env seeds its own)."""
    return spaces.Dict(
        {
            # 0: an empty slot; k: an object of type TYPES[k - 1]
            "types": spaces.MultiDiscrete([len(TYPES) + 1] * MAX_OBJECTS),
            # position (m) and quaternion xyzw per slot; zeros for an empty slot
            "poses": spaces.Box(-POSITION_BOUND, POSITION_BOUND, (MAX_OBJECTS, 7), np.float32),
            "on": spaces.MultiBinary([MAX_OBJECTS, ENTITIES]),  # On(slot i, entity j)
            "inside": spaces.MultiBinary([MAX_OBJECTS, len(SHELVES)]),  # In(slot i, shelf j)
            "in_grasp": spaces.MultiBinary(MAX_OBJECTS),
            "clear": spaces.MultiBinary(MAX_OBJECTS),
        }
    )


def action_space() -> spaces.Dict:
    """A fresh space (each env seeds its own)."""
    return spaces.Dict(
        {
            "primitive": spaces.Discrete(len(PRIMITIVES)),
            "object": spaces.Discrete(MAX_OBJECTS),
            "target": spaces.Discrete(ENTITIES),  # place only: a slot, a shelf top or a region
            "place_bins": spaces.MultiDiscrete(list(BINS[MotionPrimitive.PLACE])),  # x, y
            "push_bins": spaces.MultiDiscrete(list(BINS[MotionPrimitive.PUSH])),  # angle, dist
        }
    )


def entity_names(objects: tuple[str, ...]) -> list[str | None]:
    """The name at every entity index of a scene with these objects (None: an empty slot)."""
    return [*objects, *[None] * (MAX_OBJECTS - len(objects)), *FIXTURES]


def encode(
    objects: tuple[str, ...], sg: GeometricSceneGraph, state: SymbolicSceneGraph
) -> dict[str, np.ndarray]:
    """The numeric observation of a scene (its objects in slot order); an object the observer
    has never seen (not in `sg`) has its type and a zero pose."""
    index = {name: i for i, name in enumerate(entity_names(objects)) if name is not None}
    obs = {k: np.zeros(s.shape, s.dtype) for k, s in observation_space().spaces.items()}
    for i, name in enumerate(objects):
        obs["types"][i] = TYPES.index(type_of(name)) + 1
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
            obs["inside"][slot, tuple(SHELVES).index(lit.args[1])] = 1
        elif lit.predicate is Predicate.IN_GRASP:
            obs["in_grasp"][slot] = 1
        elif lit.predicate is Predicate.CLEAR:
            obs["clear"][slot] = 1
    return obs


def decode(objects: tuple[str, ...], action: dict) -> PrimitiveParams | str:
    """The typed primitive an action names, or why it names none (an empty slot)."""
    names = entity_names(objects)
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
    if target in FIXTURES:
        x, y = (int(b) for b in action["place_bins"])
        return PlaceParams(obj, target, x, y)
    return PlaceParams(obj, target)  # stacked: the position comes from the object below
