"""A box's quarter turn, told by its silhouette.

The keypoint network names a box's corners per view by the pose's look-alike canonical for that
view (`keypoints.canonical_rotation`), and from some views a box standing on a can, or lying
among others, gets its corners named a quarter turn round: every view then agrees on a yaw
80 to 90 degrees off. Its position is right, and so is each view's reprojection; a grasp
across its narrow side closes across its long one and holds nothing. On the tuning seeds
(`eval world --protocol paper --perception rgb --sizes 5,6 --goals 40 --seed 901`) every pick
whose fingers closed on nothing had its box believed 80 to 82 degrees off.

What does tell the two apart is where the box's colour is: painted at its yaw and a quarter
turn from it (`visible.painted`, with every other detection, the shelves and the arm where
they were found), the box covers its own pixels far better at the true one. Each view that
found the box names the pixels near it by the colour network (`colour.named_pixels`); the
turn whose painted pixels overlap those named the box's type better, by `MARGIN` in the mean
intersection over union over those views, is kept. Only upright boxes whose footprint is
`ELONGATED` are checked: a square one looks the same turned.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from hsgplan.domain.world import Kind, World
from hsgplan.perception.colour import ColourNet, named_pixels
from hsgplan.perception.detection import Detection
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.visible import Cuboid, furniture, painted
from hsgplan.scene_graph.geometry import Pose, yaw_quat
from hsgplan.sim.render import Camera
from hsgplan.sim.sensing import Box

MARGIN = 0.1  # of the mean intersection over union, for a quarter turn to win
ELONGATED = 1.3  # the footprint's long side over its short side, at least
UPRIGHT = math.radians(10)  # a box tilted more than this is not checked
WINDOW = 4  # pixels around both turns' painted pixels, where the colour is read


def quarter_checked(
    colour: ColourNet,
    types: Sequence[str],
    world: World,
    images: np.ndarray,
    cameras: tuple[Camera, ...],
    found: list[Detection],
    arm: tuple[Box, ...] = (),
) -> list[Detection]:
    """Each upright, elongated box of `found` turned a quarter where its silhouette says so
    (see the module); `types` are the colour network's classes, in order."""
    out = list(found)
    occluders = furniture(world) + tuple(Cuboid.of_box(b) for b in arm)
    pinholes = [PinholeCamera.of(c) for c in cameras]
    for i, d in enumerate(found):
        if not _checked(d, world):
            continue
        turned = _quarter(d.pose)
        gains = []
        for image, pinhole in zip(images, pinholes, strict=True):
            if not any(np.allclose(k.camera.eye, pinhole.eye) for k in d.keypoints):
                continue  # a view that did not find it
            overlaps = _overlaps(colour, types, world, image, pinhole, out, i, turned, occluders)
            if overlaps is not None:
                gains.append(overlaps[1] - overlaps[0])
        if gains and float(np.mean(gains)) > MARGIN:
            out[i] = replace(d, pose=turned)
    return out


def _checked(d: Detection, world: World) -> bool:
    t = world.object_type(d.type_name)
    sx, sy = sorted(t.size[:2])
    return t.kind is Kind.BOX and sy >= ELONGATED * sx and d.pose.tilt <= UPRIGHT


def _quarter(pose: Pose) -> Pose:
    return Pose(pose.position, yaw_quat(pose.yaw + math.pi / 2))


def _overlaps(
    colour: ColourNet,
    types: Sequence[str],
    world: World,
    image: np.ndarray,
    camera: PinholeCamera,
    found: list[Detection],
    i: int,
    turned: Pose,
    occluders: tuple[Cuboid, ...],
) -> tuple[float, float] | None:
    """Intersection over union of the box's painted pixels with those the colour network
    names its type, at its yaw and turned a quarter; None where neither paints a pixel."""
    kinds = [world.object_type(d.type_name) for d in found]
    poses = [d.pose for d in found]
    labels = [
        painted(kinds, poses[:i] + [p] + poses[i + 1 :], camera, occluders, whole={i})
        for p in (found[i].pose, turned)
    ]
    own = [label == i for label in labels]
    both = own[0] | own[1]
    if not both.any():
        return None
    rows, cols = np.nonzero(both)
    h, w = both.shape
    top, bottom = max(0, rows.min() - WINDOW), min(h, rows.max() + WINDOW + 1)
    left, right = max(0, cols.min() - WINDOW), min(w, cols.max() + WINDOW + 1)
    window = (slice(top, bottom), slice(left, right))
    named = named_pixels(colour, image[window]) == types.index(found[i].type_name)
    # pixels another detection shows under both turns are its own, whatever their colour
    others = (labels[0][window] >= 0) & ~own[0][window] & (labels[1][window] >= 0) & ~own[1][window]
    named &= ~others
    out = []
    for mask in own:
        m = mask[window]
        union = int((m | named).sum())
        out.append(int((m & named).sum()) / union if union else 0.0)
    return out[0], out[1]
