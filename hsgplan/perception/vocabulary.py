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
