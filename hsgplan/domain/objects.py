"""Names in a scene: object instances, fixtures and regions.

A scene may hold several instances of one object type. The first is named by its type
(`cherries`), later ones get a suffix (`cherries_2`, `cherries_3`, ...).
"""

from __future__ import annotations

import random
from collections.abc import Iterable

from hsgplan.domain.errors import UnknownNameError
from hsgplan.domain.scene import MAX_OBJECTS, EntityKind, World

__all__ = ["EntityKind", "MAX_OBJECTS"]


def instance_name(type_name: str, k: int, world: World) -> str:
    """The name of the k-th instance (1-based) of an object type."""
    if type_name not in world.object_types:
        raise UnknownNameError(f"unknown object type '{type_name}'")
    if not 1 <= k <= MAX_OBJECTS:
        raise ValueError(f"instance number {k} is outside 1..{MAX_OBJECTS}")
    return type_name if k == 1 else f"{type_name}_{k}"


def objects_for_types(type_names: Iterable[str], world: World) -> tuple[str, ...]:
    """Instance names for a multiset of types, numbered in order of appearance."""
    counts: dict[str, int] = {}
    names = []
    for t in type_names:
        counts[t] = counts.get(t, 0) + 1
        names.append(instance_name(t, counts[t], world))
    return tuple(names)


def draw_objects(n: int, rng: random.Random, world: World) -> tuple[str, ...]:
    """n object instances, in canonical order: n distinct types drawn uniformly when n is at
    most the number of types, else every type once and the rest uniformly with replacement.
    The goal generator's objects and the reach collector's scenes are drawn this way."""
    types = list(world.object_types)
    if n <= len(types):
        chosen = rng.sample(types, n)
    else:
        chosen = types + rng.choices(types, k=n - len(types))
    return world.sort_objects(objects_for_types(chosen, world))
