"""An object's cuboid keypoints and a fixed camera's pinhole model, as DOPE uses them.

DOPE describes every object by the 9 keypoints of its bounding cuboid: the 8 corners and the
centroid. Here a cuboid is the object type's resting box (`ObjectType.size`, centred on the
object's frame, as the simulated bodies are built). The camera is the renderer's
(`hsgplan.sim.render.Camera`: a PyBullet view and vertical field of view), written in OpenCV's
convention (x right, y down, z forward; pixel centres at integer coordinates) so that
`cv2.solvePnP` can invert it.

The objects are plain coloured cuboids and cylinders: a box looks the same turned half way
about any of its axes, a can turned any way about its axis or upside down. A keypoint named by
the pose alone ("the corner at -x, -y, -z") is then not something an image can show, and a
network taught it learns a blur of the look-alike corners. So each view names the keypoints by
the pose's look-alike that is canonical for that camera (`canonical_rotation`): upright, and
its x axis towards the camera (a box: the one of its two upright look-alikes; a can: exactly,
in the horizontal plane). The centroid is the same point in every look-alike.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from hsgplan.domain.world import Kind, ObjectType
from hsgplan.scene_graph.geometry import BOX_SYMMETRIES, Pose
from hsgplan.sim.render import Camera

KEYPOINTS = 9  # 8 corners, then the centroid
# Corner order: x, y, z signs, x slowest; fixed so that a network's maps name the same corner.
CORNER_SIGNS = np.array(
    [(sx, sy, sz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64
)


def cuboid(t: ObjectType) -> np.ndarray:
    """An object of type `t`: its 9 keypoints in its own frame, metres: [9, 3] (read-only)."""
    return _cuboid(tuple(t.size))


@functools.lru_cache(maxsize=256)
def _cuboid(size: tuple[float, ...]) -> np.ndarray:
    # kept once per size: a look asks for it thousands of times (PnP's residuals)
    half = np.asarray(size, dtype=np.float64) / 2
    out = np.vstack([CORNER_SIGNS * half, np.zeros((1, 3))])
    out.setflags(write=False)
    return out


def in_world(t: ObjectType, pose: Pose) -> np.ndarray:
    """An object of type `t`: its 9 keypoints where `pose` puts it: [9, 3]."""
    m = pose.matrix()
    return cuboid(t) @ m[:3, :3].T + m[:3, 3]


def canonical_rotation(
    t: ObjectType, rotation: np.ndarray, position: np.ndarray, eye: np.ndarray
) -> np.ndarray:
    """The look-alike of the object's rotation that a camera at `eye` names keypoints by
    (see the module): [3, 3]."""
    r = np.asarray(rotation, dtype=np.float64)
    if r[2, 2] < 0:  # upside down: the same look turned half way about x
        r = r @ BOX_SYMMETRIES[1]
    toward = np.asarray(eye, dtype=np.float64) - np.asarray(position, dtype=np.float64)
    if t.kind is Kind.CAN:
        local = r.T @ toward
        phi = math.atan2(local[1], local[0])
        c, s = math.cos(phi), math.sin(phi)
        return r @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    if r[:, 0] @ toward < 0:
        r = r @ BOX_SYMMETRIES[3]
    return r


def view_keypoints(t: ObjectType, pose: Pose, camera: PinholeCamera) -> np.ndarray:
    """The object's 9 keypoints as `camera` names them (its canonical look-alike), in pixels:
    [9, 2]."""
    m = pose.matrix()
    r = canonical_rotation(t, m[:3, :3], m[:3, 3], camera.eye)
    return camera.project(cuboid(t) @ r.T + m[:3, 3])


@dataclass(frozen=True)
class PinholeCamera:
    """A camera as OpenCV sees it.

    Attributes:
        matrix: intrinsics K, [3, 3].
        world_to_camera: the extrinsic transform, [4, 4].
        width, height: image size in pixels.
    """

    matrix: np.ndarray
    world_to_camera: np.ndarray
    width: int
    height: int

    @staticmethod
    def of(camera: Camera) -> PinholeCamera:
        """The pinhole model of a renderer camera (square pixels, vertical field of view)."""
        f = (camera.height / 2) / math.tan(math.radians(camera.fov) / 2)
        # A rendered pixel i spans [i, i + 1) in normalised device coordinates: its centre,
        # OpenCV's integer coordinate, is half a pixel in.
        k = np.array(
            [[f, 0.0, camera.width / 2 - 0.5], [0.0, f, camera.height / 2 - 0.5], [0, 0, 1]]
        )
        eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
        forward = (target - eye) / np.linalg.norm(target - eye)
        right = np.cross(forward, (0.0, 0.0, 1.0))
        right /= np.linalg.norm(right)
        down = np.cross(forward, right)
        rotation = np.vstack([right, down, forward])
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = rotation, -rotation @ eye
        return PinholeCamera(k, m, camera.width, camera.height)

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """World points in the camera's frame: [N, 3] -> [N, 3]."""
        return points @ self.world_to_camera[:3, :3].T + self.world_to_camera[:3, 3]

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (u right, v down) of world points: [N, 3] -> [N, 2]."""
        p = self.to_camera(points) @ self.matrix.T
        return p[:, :2] / p[:, 2:3]

    def camera_to_world(self) -> np.ndarray:
        """The inverse extrinsic transform: [4, 4] (read-only)."""
        return self._camera_to_world

    # Both kept once per camera (the extrinsics never change): PnP's residuals ask for the eye
    # for every pose they score.
    @functools.cached_property
    def _camera_to_world(self) -> np.ndarray:
        out = np.linalg.inv(self.world_to_camera)
        out.setflags(write=False)
        return out

    @functools.cached_property
    def eye(self) -> np.ndarray:
        """The camera's position in the world: [3] (read-only)."""
        r, t = self.world_to_camera[:3, :3], self.world_to_camera[:3, 3]
        out = -r.T @ t
        out.setflags(write=False)
        return out

    def at_eye_of(self, other: PinholeCamera) -> bool:
        """Whether this camera stands where `other` does: `np.allclose(self.eye, other.eye)`,
        without its cost (a look asks it of every detection in every view)."""
        return all(
            abs(a - b) <= 1e-8 + 1e-5 * abs(b)
            for a, b in zip(self.eye.tolist(), other.eye.tolist(), strict=True)
        )
