"""The default world: the kitchen of `scenes/kitchen.toml`, where every published number was
measured.

It is read as this module is imported, so only the commands and the tests import it: library
code takes the `World` it works in, or resolves "no scene given" when a run asks
(`scene_file.default_world`), and never imports this module (an import contract in
pyproject.toml holds this).
"""

from __future__ import annotations

from hsgplan.domain.scene import World
from hsgplan.domain.scene_file import default_world

KITCHEN: World = default_world()
