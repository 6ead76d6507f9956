"""The estimated cuboids drawn on a camera image: what f_p believes, where a person can check it."""

from __future__ import annotations

import cv2
import numpy as np

from hsgplan.domain.world import ObjectType, World
from hsgplan.perception.keypoints import CORNER_SIGNS, PinholeCamera, in_world
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera

# The cuboid's 12 edges: corner pairs that differ in one sign.
EDGES = tuple(
    (a, b)
    for a in range(8)
    for b in range(a + 1, 8)
    if int((CORNER_SIGNS[a] != CORNER_SIGNS[b]).sum()) == 1
)
COLOR = (40, 220, 60)


def cuboid_pixels(t: ObjectType, pose: Pose, pinhole: PinholeCamera) -> np.ndarray | None:
    """An object of type `t`: its 9 keypoints where `pose` puts it, in `pinhole`'s pixels:
    [9, 2]; None where any of them is behind the camera."""
    points = in_world(t, pose)
    if (pinhole.to_camera(points)[:, 2] <= 0).any():
        return None
    return pinhole.project(points)


def draw_cuboids(
    image: np.ndarray, camera: Camera, poses: dict[str, Pose], world: World
) -> np.ndarray:
    """A copy of `image` (taken by `camera`) with each object's cuboid (its type's in `world`)
    at its pose drawn on it.

    Shapes:
        image: [H, W, 3] uint8; returns the same shape.
    """
    out = np.ascontiguousarray(image).copy()
    pinhole = PinholeCamera.of(camera)
    thickness = max(1, round(camera.height / 240))
    for obj, pose in poses.items():
        projected = cuboid_pixels(world.object_type(obj), pose, pinhole)
        if projected is None:  # behind the camera
            continue
        pixels = np.round(projected).astype(int)
        for a, b in EDGES:
            cv2.line(out, tuple(pixels[a]), tuple(pixels[b]), COLOR, thickness, cv2.LINE_AA)
        cv2.circle(out, tuple(pixels[-1]), thickness + 1, COLOR, -1, cv2.LINE_AA)
    return out
