"""Pictures from a fixed camera with PyBullet's TinyRenderer (no display needed)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
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
