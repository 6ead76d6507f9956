"""A box's yaw checked by its silhouette.

The keypoint network names a box's corners per view by the pose's look-alike canonical for
that view (`keypoints.canonical_rotation`), and its upright fit (`pnp.upright_fit`) is only as
good as those corners. Two errors are left that a grasp does not forgive. From some views a box
standing on a can, or lying among others, gets its corners named a quarter turn round: every
view agrees on a yaw 80 to 90 degrees off, with its position right. A grasp across its narrow
side then closes across its long one and holds nothing. On the tuning seeds (`eval world
--protocol paper --perception rgb --sizes 5,6 --goals 40 --seed 901`) every pick whose fingers
closed on nothing had its box believed 80 to 82 degrees off. And a standing popcorn's yaw is
often 13 to 17 degrees off (staged scenes of tuning seed 2).

What tells the yaw is where the box's colour is. The box is drawn at candidate yaws (`OFFSETS`
round its estimate and round a quarter turn from it, an elongated box only for the latter) at
its estimated position, behind what stands nearer the camera (every other detection, the
shelves and the arm, as found). Each view that found it names the pixels near it by the colour
network (`colour.named_pixels`), and each candidate is scored by the intersection over union
of its drawn pixels with those named the box's type, averaged over those views. The best
candidate replaces the estimate where it scores at least `MIN_IOU` and beats the estimate by
`MARGIN`. A box mostly hidden shows too little to say (low scores), and a square one looks the
same turned a quarter.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import cv2
import numpy as np

from hsgplan.domain.world import Kind, World
from hsgplan.perception.colour import ColourNet, named_pixels
from hsgplan.perception.detection import Detection
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.visible import Cuboid, furniture, paint
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.sim.render import Camera
from hsgplan.sim.sensing import Box

OFFSETS = np.radians(np.arange(-30, 31, 3))  # yaws tried round the estimate (and a quarter on)
MARGIN = 0.02  # of the mean intersection over union, for a candidate to replace the estimate
MIN_IOU = 0.5  # the least a candidate must score: below, too little of the box is in sight
ELONGATED = 1.3  # the footprint's long side over its short side, for a quarter turn to be tried
UPRIGHT = math.radians(10)  # a box tilted more than this is not checked
WINDOW = 4  # pixels round the candidates' drawn pixels, where the colour is read


def yaw_checked(
    colour: ColourNet,
    types: Sequence[str],
    world: World,
    images: np.ndarray,
    cameras: tuple[Camera, ...],
    found: list[Detection],
    arm: tuple[Box, ...] = (),
) -> list[Detection]:
    """Each upright box of `found` at the yaw its silhouette says (see the module); `types`
    are the colour network's classes, in order."""
    out = list(found)
    occluders = furniture(world) + tuple(Cuboid.of_box(b) for b in arm)
    pinholes = [PinholeCamera.of(c) for c in cameras]
    for i, d in enumerate(found):
        if not _checked(d, world):
            continue
        candidates = _candidates(d, world)
        t = world.object_type(d.type_name)
        # the candidates' corners, [candidates, 8, 3], once for every view that scores them
        corners = np.stack([Cuboid.of_object(t, p, 1.0).corners() for p in candidates])
        scores = [
            s
            for image, pinhole in zip(images, pinholes, strict=True)
            if any(k.camera.at_eye_of(pinhole) for k in d.keypoints)
            and (s := _scores(colour, types, world, image, pinhole, out, i, corners, occluders))
            is not None
        ]
        if not scores:
            continue
        mean = np.mean(scores, axis=0)
        best = int(np.argmax(mean))
        if mean[best] >= MIN_IOU and mean[best] - mean[0] > MARGIN:
            out[i] = replace(d, pose=candidates[best])
    return out


def _checked(d: Detection, world: World) -> bool:
    t = world.object_type(d.type_name)
    return t.kind is Kind.BOX and d.pose.tilt <= UPRIGHT


def _candidates(d: Detection, world: World) -> list[Pose]:
    """The estimate first, then its yaw turned by each offset (and a quarter more, for an
    elongated box)."""
    sx, sy = sorted(world.object_type(d.type_name).size[:2])
    turns = (0.0, math.pi / 2) if sy >= ELONGATED * sx else (0.0,)
    yaw, at = d.pose.yaw, d.pose.position
    tried = [yaw + turn + off for turn in turns for off in OFFSETS if turn or off]
    return [d.pose] + [Pose(at, yaw_quat(y)) for y in tried]


def _scores(
    colour: ColourNet,
    types: Sequence[str],
    world: World,
    image: np.ndarray,
    camera: PinholeCamera,
    found: list[Detection],
    i: int,
    corners: np.ndarray,
    occluders: tuple[Cuboid, ...],
) -> list[float] | None:
    """Each candidate's (its cuboid's `corners`) intersection over union with the pixels named
    the box's type in one view; None where no candidate is drawn in it."""
    hulls = _hulls(corners, camera)
    if hulls is None:
        return None  # partly behind the camera
    points = np.concatenate(hulls)
    h, w = image.shape[:2]
    left, top = np.maximum(points.min(axis=0) - WINDOW, 0)
    right, bottom = np.minimum(points.max(axis=0) + WINDOW + 1, (w, h))
    if right <= left or bottom <= top:
        return None
    window = (slice(top, bottom), slice(left, right))
    # what stands nearer the camera than the box hides it, whatever its yaw
    eye = np.asarray(camera.eye)
    reach = np.linalg.norm(np.asarray(found[i].pose.position) - eye)
    nearer = [
        Cuboid.of_object(world.object_type(d.type_name), d.pose)
        for k, d in enumerate(found)
        if k != i and np.linalg.norm(np.asarray(d.pose.position) - eye) < reach
    ]
    front = (paint(nearer + list(occluders), camera) != -1)[window]
    named = (named_pixels(colour, image[window]) == types.index(found[i].type_name)) & ~front
    in_sight, named_count = ~front, int(np.count_nonzero(named))
    drawn = np.zeros((bottom - top, right - left), np.uint8)
    out = []
    for hull in hulls:
        drawn[:] = 0
        cv2.fillConvexPoly(drawn, hull - (left, top), 1)
        mask = drawn.view(bool) & in_sight
        both = int(np.count_nonzero(mask & named))
        union = int(np.count_nonzero(mask)) + named_count - both
        out.append(both / union if union else 0.0)
    return out


def _hulls(corners: np.ndarray, camera: PinholeCamera) -> list[np.ndarray] | None:
    """Cuboids' outlines in the image from their corners [N, 8, 3]: each one's convex hull,
    [K, 2] int32 pixels; None where a corner is behind the camera."""
    seen = camera.to_camera(corners.reshape(-1, 3))
    if (seen[:, 2] <= 0).any():
        return None
    p = seen @ camera.matrix.T  # `camera.project`, from the points it has in its frame
    pixels = np.round(p[:, :2] / p[:, 2:3]).astype(np.int32).reshape(len(corners), -1, 2)
    return [cv2.convexHull(c).reshape(-1, 2) for c in pixels]
