"""The vocabulary of the "names" encodings: the kitchen's names, in the order the one-hot
columns of the networks trained on them (the shipped `checkpoints/task` and `checkpoints/motion`)
and of their motion data index them.

The vocabulary is part of those checkpoints' format, so it is written here rather than read from
`scenes/kitchen.toml`: editing the scene file cannot shift a column under a trained network, and
importing the planner reads no file (a test holds these names to the scene file's). A network of
these encodings reads a scene whose objects, shelves and regions bear these names (a layout of
the kitchen's groceries); one of the "geometry" encodings reads any scene
(`planning.regression.features`, `scene_graph.grounding`).
"""

from __future__ import annotations

from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world

TYPE_NAMES: tuple[str, ...] = (
    "cherries",
    "alphabet_soup",
    "tomato_soup",
    "popcorn",
    "cream_cheese",
    "butter",
)
SHELF_NAMES: tuple[str, ...] = ("shelf_a", "shelf_b")
REGION_NAMES: tuple[str, ...] = ("open_space", "prepush_a", "prepush_b")
ENTITY_NAMES: tuple[str, ...] = TYPE_NAMES + SHELF_NAMES + REGION_NAMES


def names_world() -> World:
    """The world whose names they are, where the motion data of the names encodings was staged:
    the kitchen, read when first asked for."""
    return default_world()


def unnamed(world: World) -> list[str]:
    """Entity types of `world` that the vocabulary lacks (what a network of the names encodings
    cannot read)."""
    return [n for n in world.entity_types if n not in ENTITY_NAMES]
