"""The default world: the kitchen of `scenes/kitchen.toml`, where every published number was
measured.

Library code takes the `World` it works in and never imports this module (an import contract
in pyproject.toml holds this); the entry points (commands, evaluation configurations,
collectors, benchmarks) resolve "no scene given" to it here, and tests build in it.
"""

from __future__ import annotations

from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import read_world
from hsgplan.paths import KITCHEN_SCENE

KITCHEN: World = read_world(KITCHEN_SCENE)
