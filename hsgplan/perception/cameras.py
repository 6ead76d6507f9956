"""The fixed cameras f_p sees the scene with: their calibration (pose and intrinsics), which
a real robot's cameras would be given by calibrating them."""

from __future__ import annotations

from dataclasses import asdict

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.sim.render import Camera

# The scene's fixed views (in the kitchen, five at 320 x 240: facing the robot over the table;
# from behind the robot's shoulders on either side, low enough to look into the shelves and
# over the prepush regions past the arm, which hides the middle from straight behind; and from
# the table's far corners as low, which see the sides of the stacks on the open space and the
# shelf tops that the first three see from one side only: a box under a can or another box was
# often seen by one view alone). The keypoint network was first trained on the first three
# (see `perception.synthetic.ORIGINAL_VIEWS`), then fine-tuned on all five.
VIEWS: tuple[Camera, ...] = tuple(Camera(**asdict(view)) for view in KITCHEN.cameras)
