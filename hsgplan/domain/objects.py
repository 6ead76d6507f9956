"""Names in a scene: object instances, fixtures and regions.

A scene may hold several instances of one object type. The first is named by its type
(`cherries`), later ones get a suffix (`cherries_2`, `cherries_3`, ...).
"""

from __future__ import annotations

import random
import re
from collections.abc import Iterable
from enum import StrEnum

from hsgplan.domain.errors import UnknownNameError
from hsgplan.domain.world import MAX_OBJECTS, OBJECT_TYPES, REGIONS, SHELVES, ObjectType


class EntityKind(StrEnum):
    OBJECT = "object"
    SHELF = "shelf"
    REGION = "region"


_INSTANCE = re.compile(r"^(?P<type>[a-z][a-z_]*?)(?:_(?P<k>[0-9]+))?$")

# Entity types in a fixed order: node-type one-hots and PDDL types index into it.
ENTITY_TYPES: tuple[str, ...] = tuple(OBJECT_TYPES) + tuple(SHELVES) + tuple(REGIONS)


def instance_name(type_name: str, k: int) -> str:
    """The name of the k-th instance (1-based) of an object type."""
    if type_name not in OBJECT_TYPES:
        raise UnknownNameError(f"unknown object type '{type_name}'")
    if not 1 <= k <= MAX_OBJECTS:
        raise ValueError(f"instance number {k} is outside 1..{MAX_OBJECTS}")
    return type_name if k == 1 else f"{type_name}_{k}"


def split_instance(name: str) -> tuple[str, int]:
    """(type, k) of an object instance name; raises UnknownNameError with the reason."""
    if name in OBJECT_TYPES:
        return name, 1
    m = _INSTANCE.match(name)
    if m and m.group("type") in OBJECT_TYPES and m.group("k") is not None:
        k = int(m.group("k"))
        if k < 2 or str(k) != m.group("k"):
            t = m.group("type")
            raise UnknownNameError(
                f"unknown object '{name}' (the first {t} is named '{t}', "
                f"later ones '{t}_2', '{t}_3', ...)"
            )
        if k > MAX_OBJECTS:
            raise UnknownNameError(f"unknown object '{name}' (a scene holds at most {MAX_OBJECTS})")
        return m.group("type"), k
    raise UnknownNameError(f"unknown name '{name}'")


def kind_of(name: str) -> EntityKind:
    """Whether a name is an object, a shelf or a region; raises UnknownNameError otherwise."""
    if name in SHELVES:
        return EntityKind.SHELF
    if name in REGIONS:
        return EntityKind.REGION
    split_instance(name)
    return EntityKind.OBJECT


def type_of(name: str) -> str:
    """The entity type of a name: the object type for instances, the name itself otherwise."""
    return split_instance(name)[0] if kind_of(name) is EntityKind.OBJECT else name


def object_type(name: str) -> ObjectType:
    return OBJECT_TYPES[split_instance(name)[0]]


def sort_objects(names: Iterable[str]) -> tuple[str, ...]:
    """Object names in canonical order: by type as listed in the world, then instance number."""
    order = {t: i for i, t in enumerate(OBJECT_TYPES)}

    def key(n: str) -> tuple[int, int]:
        t, k = split_instance(n)
        return order[t], k

    return tuple(sorted(set(names), key=key))


def objects_for_types(type_names: Iterable[str]) -> tuple[str, ...]:
    """Instance names for a multiset of types, numbered in order of appearance."""
    counts: dict[str, int] = {}
    names = []
    for t in type_names:
        counts[t] = counts.get(t, 0) + 1
        names.append(instance_name(t, counts[t]))
    return tuple(names)


def draw_objects(n: int, rng: random.Random) -> tuple[str, ...]:
    """n object instances, in canonical order: n distinct types drawn uniformly when n is at
    most the number of types, else every type once and the rest uniformly with replacement.
    The goal generator's objects and the reach collector's scenes are drawn this way."""
    types = list(OBJECT_TYPES)
    if n <= len(types):
        chosen = rng.sample(types, n)
    else:
        chosen = types + rng.choices(types, k=n - len(types))
    return sort_objects(objects_for_types(chosen))
