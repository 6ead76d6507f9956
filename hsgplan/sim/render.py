"""Pictures from a fixed camera with PyBullet's TinyRenderer (no display needed)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # a camera's calibration is for perception too, which never sees PyBullet
    from pybullet_utils.bullet_client import BulletClient


@dataclass(frozen=True)
class Camera:
    """A pinhole camera behind and above the robot, looking over it at the workspace, so that
    shelf A (+y) appears on the left, as the paper describes it."""

    width: int = 400
    height: int = 300
    eye: tuple[float, float, float] = (0.2, 0.0, 1.5)
    target: tuple[float, float, float] = (0.5, 0.0, 0.0)
    fov: float = 50.0

    def capture(self, bc: BulletClient) -> np.ndarray:
        """An RGB image, height x width x 3, uint8."""
        view = bc.computeViewMatrix(self.eye, self.target, (0, 0, 1))
        proj = bc.computeProjectionMatrixFOV(self.fov, self.width / self.height, 0.05, 4.0)
        _, _, rgba, _, _ = bc.getCameraImage(
            self.width,
            self.height,
            view,
            proj,
            renderer=bc.ER_TINY_RENDERER,
            lightDirection=(0.6, 0.2, 1.0),
            shadow=0,
        )
        return np.asarray(rgba, dtype=np.uint8).reshape(self.height, self.width, 4)[:, :, :3]


# The demo's two panels, 640 x 480 each: between them every object is in sight whatever the
# arm does. Facing the robot from beyond the table, the arm stays behind the objects: shelf
# tops, the open space and what stands on them (shelf B on the left). From each side of the
# table, low, one shelf's interior through its open front and its prepush region (shelf A's
# above, shelf B's below): the arm is seen from the side, never between the view and the shelf
# (from behind the robot, or in front of its base, it filled the view).
FRONT = Camera(640, 480, (1.3, 0.0, 1.25), (0.38, 0.0, 0.0), 52.0)
SIDE_A = Camera(640, 240, (0.0, 0.80, 0.24), (0.47, 0.36, 0.08), 30.0)
SIDE_B = Camera(640, 240, (0.0, -0.80, 0.24), (0.47, -0.36, 0.08), 30.0)
DEMO_VIEWS: tuple[tuple[str, tuple[Camera, ...]], ...] = (
    ("facing the robot: shelf tops, open space", (FRONT,)),
    (
        "from the sides, low: shelf A's interior and prepush region, then shelf B's",
        (SIDE_A, SIDE_B),
    ),
)
# each camera of the demo by name, as a recording logs them
DEMO_CAMERAS: dict[str, Camera] = {"front": FRONT, "side_a": SIDE_A, "side_b": SIDE_B}
