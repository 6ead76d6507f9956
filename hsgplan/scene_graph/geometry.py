"""Rigid poses in SE(3): position and unit quaternion (x, y, z, w, PyBullet's order)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def quat_to_matrix(q: tuple[float, float, float, float]) -> np.ndarray:
    x, y, z, w = q
    n = x * x + y * y + z * z + w * w
    s = 2.0 / n if n > 0 else 0.0
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def matrix_to_quat(m: np.ndarray) -> tuple[float, float, float, float]:
    """Shepperd's method: numerically safe for every rotation."""
    t = np.trace(m)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = (s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s)
    w = q[3]
    sign = -1.0 if w < 0 else 1.0  # one of the two equal quaternions, w >= 0, for stable output
    return tuple(float(sign * c) for c in q)  # type: ignore[return-value]


# The rotations that leave a box's cuboid where it was: half turns about its axes.
BOX_SYMMETRIES = (
    np.eye(3),
    np.diag([1.0, -1.0, -1.0]),
    np.diag([-1.0, 1.0, -1.0]),
    np.diag([-1.0, -1.0, 1.0]),
)


def rotation_apart(a: Pose, b: Pose, round_about_z: bool) -> float:
    """Degrees between two orientations of one object, up to what its shape cannot tell
    apart: a cuboid's half turns, and with `round_about_z` (a can) any turn about its axis,
    either way up."""
    ra, rb = a.rotation, b.rotation
    if round_about_z:
        return math.degrees(math.acos(min(1.0, abs(float(ra[:, 2] @ rb[:, 2])))))
    best = max(np.trace(ra.T @ rb @ s) for s in BOX_SYMMETRIES)
    return math.degrees(math.acos(float(np.clip((best - 1) / 2, -1.0, 1.0))))


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


@dataclass(frozen=True)
class Pose:
    """A pose in the world frame (or in another pose's frame, after `relative_to`)."""

    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    @staticmethod
    def from_xyz_yaw(x: float, y: float, z: float, yaw: float = 0.0) -> Pose:
        return Pose((float(x), float(y), float(z)), yaw_quat(yaw))

    @property
    def rotation(self) -> np.ndarray:
        return quat_to_matrix(self.orientation)

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.position
        return m

    @staticmethod
    def from_matrix(m: np.ndarray) -> Pose:
        return Pose(tuple(float(v) for v in m[:3, 3]), matrix_to_quat(m[:3, :3]))  # type: ignore[arg-type]

    def relative_to(self, frame: Pose) -> Pose:
        """This pose expressed in `frame`'s coordinates."""
        return Pose.from_matrix(np.linalg.inv(frame.matrix()) @ self.matrix())

    def inverse(self) -> Pose:
        return Pose.from_matrix(np.linalg.inv(self.matrix()))

    def compose(self, local: Pose) -> Pose:
        """A pose given in this pose's frame, expressed in the world."""
        return Pose.from_matrix(self.matrix() @ local.matrix())

    @property
    def tilt(self) -> float:
        """Angle (rad) between the body's z axis and the world's z axis."""
        return math.acos(max(-1.0, min(1.0, float(self.rotation[2, 2]))))

    @property
    def yaw(self) -> float:
        r = self.rotation
        return math.atan2(r[1, 0], r[0, 0])

    def distance(self, other: Pose) -> float:
        return float(np.linalg.norm(np.subtract(self.position, other.position)))
