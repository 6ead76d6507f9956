"""The vocabulary of the "names" encodings: the kitchen's names, in the order the one-hot
columns of the networks trained on them (the shipped `checkpoints/task` and `checkpoints/motion`)
and of their motion data index them.

A network of these encodings reads a scene whose objects, shelves and regions bear these names
(a layout of the kitchen's groceries); one of the "geometry" encodings reads any scene
(`planning.regression.features`, `scene_graph.grounding`).
"""

from __future__ import annotations

from hsgplan.domain.kitchen import KITCHEN

# the world whose names they are (its motion data's scenes are staged in it too)
NAMES_WORLD = KITCHEN
ENTITY_NAMES: tuple[str, ...] = tuple(NAMES_WORLD.entity_types)
TYPE_NAMES: tuple[str, ...] = tuple(NAMES_WORLD.object_types)
