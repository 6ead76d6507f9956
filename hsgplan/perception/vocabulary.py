"""What the shipped f_p was trained on: scenes staged in the kitchen, its object types seen
through its fixed cameras.

Its training images are rendered in `TRAINING_WORLD` (`perception.synthetic`), the networks'
type channels are indexed by `TYPES` (their order is the checkpoints'), and the images were
taken by `VIEWS`. Everything else f_p knows of a scene (the types'
sizes and kinds, the table, the shelves) it is given as the scene's `World` when it looks, so
that it sees in any scene whose objects are of these types, seen through these cameras.
"""

from __future__ import annotations

from dataclasses import asdict

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.domain.world import World
from hsgplan.sim.render import Camera

TRAINING_WORLD = KITCHEN
TYPES: tuple[str, ...] = tuple(TRAINING_WORLD.object_types)

# The fixed views (in the kitchen, five at 320 x 240: facing the robot over the table; from
# behind the robot's shoulders on either side, low enough to look into the shelves and over the
# prepush regions past the arm, which hides the middle from straight behind; and from the
# table's far corners as low, which see the sides of the stacks on the open space and the shelf
# tops that the first three see from one side only: a box under a can or another box was often
# seen by one view alone). The keypoint network was first trained on the first three (see
# `perception.synthetic.ORIGINAL_VIEWS`), then fine-tuned on all five.
VIEWS: tuple[Camera, ...] = tuple(Camera(**asdict(view)) for view in TRAINING_WORLD.cameras)


def unseen_looks(world: World) -> str | None:
    """Why f_p cannot see a scene of `world`, or None when it can: it has learned the looks
    (name, kind and colour) of the training world's object types, seen through `VIEWS`. Their
    sizes, the table and the shelves it takes from `world`, so a scene of moved shelves and
    resized groceries is one it can look at."""
    trained = TRAINING_WORLD.object_types
    for t in world.type_list:
        known = trained.get(t.name)
        if known is None or known.kind != t.kind or known.color != t.color:
            return f"it has not learned the look of '{t.name}'"
    if tuple(world.cameras) != tuple(TRAINING_WORLD.cameras):
        return "its cameras are not the ones f_p was trained with"
    return None
