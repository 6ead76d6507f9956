"""Which pixels of a view show which detected object: the detections' cuboids painted far to
near (the painter's algorithm), face by face, with occluders (the shelves' boards, the arm's
links) painted among them where asked (`perception.phantoms`).

The colour network names a type from the colour around the centroid's pixel. Where another
object stands on or in front of the detected one, that pixel shows the other object: a cream
cheese under a butter shows the butter's yellow there, and was named butter (7 of the 28
objects missing from the scene graphs of 100 tuning scenes, seed 2, were named so; 3 with
this module). Painted from the estimated poses, the pixels each detection keeps in sight are
where its own colour is, and a vote of them names it (`colour.pixel_vote`); where its
centroid's pixel is its own, that pixel's patch, which is what the colour network was trained
on, still names it (the region's colour everywhere named a few soups cherries).

Cuboids are shrunk across (`SHRINK`) before painting: a can fills only the middle of its
cuboid, and an estimate is off by a few millimetres; what is left is eroded by a pixel.
"""

from __future__ import annotations

import itertools
from collections.abc import Collection
from dataclasses import dataclass

import cv2
import numpy as np

from hsgplan.domain.world import Board, ObjectType, World, shelf_boards
from hsgplan.perception.keypoints import CORNER_SIGNS, PinholeCamera
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.sensing import Box

SHRINK = 0.8  # of a cuboid's footprint painted


@dataclass(frozen=True)
class Cuboid:
    """A box in the world: its pose and its half extents (m)."""

    pose: Pose
    half: tuple[float, float, float]

    def corners(self) -> np.ndarray:
        """Its 8 corners in the world, [8, 3], in the order of `CORNER_SIGNS`."""
        m = self.pose.matrix()
        return (CORNER_SIGNS * np.asarray(self.half)) @ m[:3, :3].T + m[:3, 3]

    @staticmethod
    def of_object(t: ObjectType, pose: Pose, shrink: float = SHRINK) -> Cuboid:
        """The cuboid of an object of type `t`, its footprint shrunk by `shrink` across."""
        sx, sy, sz = t.size
        return Cuboid(pose, (shrink * sx / 2, shrink * sy / 2, sz / 2))

    @staticmethod
    def of_box(box: Box) -> Cuboid:
        """An axis-aligned box (a link of the arm)."""
        low, high = np.asarray(box.low), np.asarray(box.high)
        centre = tuple(map(float, (low + high) / 2))
        return Cuboid(Pose(centre, (0.0, 0.0, 0.0, 1.0)), tuple(map(float, (high - low) / 2)))

    @staticmethod
    def of_board(board: Board) -> Cuboid:
        """A shelf's board, turned with its shelf."""
        r = board.rect
        box = Cuboid.of_box(Box((r.x_min, r.y_min, board.z_min), (r.x_max, r.y_max, board.z_max)))
        if not r.yaw:
            return box
        centre = (*r.center, box.pose.position[2])
        return Cuboid(Pose.from_xyz_yaw(*centre, r.yaw), box.half)


OCCLUDED = -2  # a pixel an occluder shows (`painted`)


def furniture(world: World) -> tuple[Cuboid, ...]:
    """The shelves' walls and boards: the fixed furniture that hides what stands behind or in
    it."""
    return tuple(Cuboid.of_board(b) for s in world.shelves.values() for b in shelf_boards(s))


def painted(
    types: list[ObjectType],
    poses: list[Pose],
    camera: PinholeCamera,
    occluders: tuple[Cuboid, ...] = (),
    whole: Collection[int] = (),
) -> np.ndarray:
    """Which object (its index; -1 for none) each pixel shows, as painted: [H, W] int32. The
    `occluders` (painted as -2) hide what is behind them. Those indexed in `whole` are painted
    unshrunk: a box's footprint is all its own."""
    cuboids = [
        Cuboid.of_object(t, p, 1.0 if i in whole else SHRINK)
        for i, (t, p) in enumerate(zip(types, poses, strict=True))
    ]
    label = paint(cuboids + list(occluders), camera)
    label[label >= len(cuboids)] = OCCLUDED
    return label


def paint(cuboids: list[Cuboid], camera: PinholeCamera) -> np.ndarray:
    """Which cuboid (its index; -1 for none) each pixel shows, the far faces painted first:
    [H, W] int32. The faces of every cuboid are found and projected together (a look paints
    the shelves' boards and the objects many times over)."""
    label = np.full((camera.height, camera.width), -1, dtype=np.int32)
    if not cuboids:
        return label
    corners = np.stack([c.corners() for c in cuboids])  # [N, 8, 3]
    middles = np.array([c.pose.position for c in cuboids], dtype=np.float64)
    quads = np.stack(
        [corners[:, CORNER_SIGNS[:, a] * s > 0] for a, s in itertools.product(range(3), (-1, 1))],
        axis=1,
    )  # [N, 6, 4, 3]: each cuboid's faces
    centres = quads.mean(axis=2)
    toward = camera.eye - centres
    facing = ((centres - middles[:, None]) * toward).sum(axis=2) > 0  # away: never seen
    distance = np.sqrt((toward**2).sum(axis=2))
    index, face = np.nonzero(facing)
    order = np.argsort(-distance[index, face], kind="stable")  # far first; ties as listed
    quads = quads[index[order], face[order]]  # [M, 4, 3]
    depth = camera.to_camera(quads.reshape(-1, 3))[:, 2].reshape(-1, 4)
    pixels = np.round(camera.project(quads.reshape(-1, 3))).reshape(-1, 4, 2)
    for i, quad, behind in zip(index[order], pixels, (depth <= 0).any(axis=1), strict=True):
        if not behind:
            cv2.fillConvexPoly(label, cv2.convexHull(quad.astype(np.int32)), int(i))
    return label


def visible_masks(label: np.ndarray, count: int, apart: int = 0) -> list[np.ndarray]:
    """Each of `count` objects' pixels in sight in a painted view, less a pixel around and
    those within `apart` pixels of another object's: N bool masks [H, W].

    Painted from estimates, an edge between two objects is off by a pixel or two, more where
    the two are not turned alike (a box stacked askew on another, painted with the stack's one
    yaw): the lower box's strip of side then shows the upper one's colour along that edge, and
    named a butter under a cream cheese cream cheese (4 of the 6 look-alikes on 300 tuning
    scenes, seeds 900 to 902; all four named right at 2 pixels apart, not all at 4)."""
    kernel = np.ones((3, 3), np.uint8)
    grow = np.ones((2 * apart + 1, 2 * apart + 1), np.uint8)
    out = []
    for i in range(count):
        own = cv2.erode((label == i).astype(np.uint8), kernel).astype(bool)
        if apart > 0:
            other = ((label != i) & (label >= 0)).astype(np.uint8)
            own &= ~cv2.dilate(other, grow).astype(bool)
        out.append(own)
    return out
