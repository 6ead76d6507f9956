"""The fixed cameras f_p sees the scene with: their calibration (pose and intrinsics), which
a real robot's cameras would be given by calibrating them."""

from __future__ import annotations

from hsgplan.sim.render import Camera

# Five fixed views at 320 x 240: facing the robot over the table (shelf tops, open space);
# from behind the robot's shoulders on either side, low enough to look into the shelves and
# over the prepush regions past the arm (which hides the middle from straight behind); and,
# from the table's far corners as low, which see the sides of the stacks on the open space and
# the shelf tops that the first three see from one side only (a box under a can or another box
# was often seen by one view alone). The keypoint network was first trained on the first three
# (see `perception.synthetic.ORIGINAL_VIEWS`), then fine-tuned on all five.
VIEWS: tuple[Camera, ...] = (
    Camera(320, 240, (1.15, 0.0, 1.0), (0.42, 0.0, 0.05), 46.0),
    Camera(320, 240, (-0.25, 0.7, 0.55), (0.45, 0.2, 0.06), 50.0),
    Camera(320, 240, (-0.25, -0.7, 0.55), (0.45, -0.2, 0.06), 50.0),
    Camera(320, 240, (1.1, 0.7, 0.55), (0.45, 0.1, 0.06), 50.0),
    Camera(320, 240, (1.1, -0.7, 0.55), (0.45, -0.1, 0.06), 50.0),
)
