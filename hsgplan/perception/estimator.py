"""f_p: object poses from the fixed cameras' images, with the trained keypoint network.

Each view's image goes through the network; its last stage's maps are decoded into instances
(`perception.maps.decode`), and each instance seen with enough keypoints gets a pose by PnP.
Estimates of one type from different views whose centroids' lines of sight pass within
`RAY_GAP` of one another, at a point on the table, are one object (a single view's depth is its
weak axis, so views are matched by their rays, not by their poses): its pose
is refitted to the keypoints of every view that saw it (`perception.pnp.estimate_pose`), as the
paper fuses its robot's viewpoints. The colour network names each object's type; one whose
centroid's pixel another detection hides is named again by the pixels it keeps in sight
(`perception.visible`). Last, the poses are made to rest on what is under them
(`perception.settle`), unless asked for raw.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import torch

from hsgplan.domain.world import OBJECT_TYPES, TABLE
from hsgplan.paths import shipped
from hsgplan.perception.colour import FOLDER as COLOUR_FOLDER
from hsgplan.perception.colour import ColourNet, features, load_colour, region_features
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.maps import decode
from hsgplan.perception.model import KeypointNet, load_perception_net
from hsgplan.perception.pnp import ViewKeypoints, estimate_pose, robust_cost, upright_fit
from hsgplan.perception.settle import Ray, meeting_point, same_place, settle
from hsgplan.perception.visible import painted, visible_masks
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import Camera

RAY_GAP = 0.02  # m between two views' lines of sight to one object's centroid
# Where two rays meet must be over the table and below this height to be an object's centroid.
TOP_Z = 0.6  # m
TYPES = tuple(OBJECT_TYPES)


@dataclass(frozen=True)
class Detection:
    """An object the cameras saw: its type, pose, and the views and keypoints behind it.

    Attributes:
        rays: each view's line of sight through the object's centroid, (origin, unit
            direction) in the world; where two or more views saw it, `pose` sits where they
            meet.
    """

    type_name: str
    pose: Pose
    score: float
    views: int
    reprojection_px: float
    rays: tuple[Ray, ...] = ()
    type_confidence: float = 1.0  # the colour network's probability of the type (1: no colour)
    keypoints: tuple[ViewKeypoints, ...] = ()  # each view's keypoints behind it


class PoseEstimator:
    """Args:
    net: a trained keypoint network (eval mode).
    settled: make the fused poses rest on their supports (`perception.settle`).
    colour: the colour network that names each object's type (`perception.colour`); without
        it, the keypoint network's type is kept.
    """

    def __init__(
        self, net: KeypointNet, settled: bool = True, colour: ColourNet | None = None
    ) -> None:
        self.net = net
        self.settled = settled
        self.colour = colour

    @staticmethod
    def load(folder: Path, settled: bool = True) -> PoseEstimator:
        """The estimator of a checkpoint folder (the keypoint network, and the colour network
        in its `colour/`)."""
        net = load_perception_net(folder)[0]
        return PoseEstimator(net, settled, load_colour(shipped(folder) / COLOUR_FOLDER))

    def _typed(self, images: np.ndarray, members: list[_Seen]) -> tuple[int, float]:
        """The type of an object its members saw, and its probability: by the colour network
        over the members' views, among the types of the kind (can or box) the keypoint network
        saw, which it tells apart well; else the keypoint network's. (A thin box under a can
        shows the can's colour at its centroid's pixel: it stays a box.)"""
        rows = [features(images[s.view], s.keypoints.pixels[-1]) for s in members]
        rows = [r for r in rows if r is not None]
        if self.colour is None or not rows:
            return members[0].type_index, 1.0
        probs = torch.softmax(self.colour(torch.from_numpy(np.stack(rows))), dim=1).mean(dim=0)
        return _of_kind(probs, TYPES[members[0].type_index])

    def _retyped(
        self, images: np.ndarray, cameras: tuple[Camera, ...], found: list[Detection]
    ) -> list[Detection]:
        """Each detection named again, in the views that found it, by the colour of the pixels
        it keeps in sight once every detection is painted where it was found
        (`perception.visible`) where an object on or before it hides its centroid's pixel (else
        by that pixel's patch, as before); among the types of its kind, and refitted if
        renamed. One in sight nowhere keeps its name."""
        assert self.colour is not None
        types, poses = [d.type_name for d in found], [d.pose for d in found]
        rows: list[list[np.ndarray]] = [[] for _ in found]
        for image, camera in zip(images, cameras, strict=True):
            pinhole = PinholeCamera.of(camera)
            label = painted(types, poses, pinhole)
            masks = visible_masks(label, len(found))
            for i, (d, mask) in enumerate(zip(found, masks, strict=True)):
                if not any(np.allclose(k.camera.eye, pinhole.eye) for k in d.keypoints):
                    continue  # a view that did not find it: a phantom's pixels there are not its
                u, v = np.round(pinhole.project(np.array([d.pose.position]))[0]).astype(int)
                own = 0 <= v < label.shape[0] and 0 <= u < label.shape[1] and label[v, u] == i
                row = features(image, np.array([u, v])) if own else region_features(image, mask)
                if row is not None:
                    rows[i].append(row)
        out = []
        for d, seen in zip(found, rows, strict=True):
            if not seen:
                out.append(d)
                continue
            probs = torch.softmax(self.colour(torch.from_numpy(np.stack(seen))), dim=1).mean(0)
            best, confidence = _of_kind(probs, d.type_name)
            if TYPES[best] == d.type_name:
                out.append(replace(d, type_confidence=confidence))
                continue
            pose, error = _fitted(TYPES[best], list(d.keypoints), list(d.rays))
            if pose is not None:
                d = replace(d, type_name=TYPES[best], pose=pose, reprojection_px=error)
            out.append(replace(d, type_confidence=confidence))
        return out

    @torch.inference_mode()
    def detect(self, images: np.ndarray, cameras: tuple[Camera, ...]) -> list[Detection]:
        """Objects in the views: images [V, H, W, 3] uint8, taken by `cameras`."""
        batch = torch.from_numpy(images).permute(0, 3, 1, 2).float() / 255.0
        beliefs, fields = self.net(batch)[-1]
        found: list[_Seen] = []
        for v, camera in enumerate(cameras):
            pinhole = PinholeCamera.of(camera)
            for inst in decode(beliefs[v].numpy(), fields[v].numpy(), self.net.stride):
                seen = ViewKeypoints(pinhole, inst.pixels)
                single = estimate_pose(TYPES[inst.type_index], [seen])
                if single is not None:
                    found.append(_Seen(inst.type_index, inst.score, v, seen, single.pose))
        fused = _apart(_fuse(found, lambda members: self._typed(images, members)))
        if self.colour is not None:
            fused = _apart(self._retyped(images, cameras, fused))
        if not self.settled:
            return fused
        poses = settle(
            [d.type_name for d in fused], [d.pose for d in fused], [d.rays for d in fused]
        )
        return [replace(d, pose=p) for d, p in zip(fused, poses, strict=True)]


def _of_kind(probs: torch.Tensor, type_name: str) -> tuple[int, float]:
    """The likeliest type of `type_name`'s kind (can or box) by the colour network's
    probabilities [types], and its probability among that kind's."""
    kind = OBJECT_TYPES[type_name].kind
    same = torch.tensor([OBJECT_TYPES[t].kind is kind for t in TYPES])
    probs = torch.where(same, probs, torch.zeros_like(probs))
    probs = probs / probs.sum().clamp(min=1e-12)
    best = int(probs.argmax())
    return best, float(probs[best])


@dataclass(frozen=True)
class _Seen:
    """One instance in one view, with its single-view pose."""

    type_index: int
    score: float
    view: int
    keypoints: ViewKeypoints
    pose: Pose


def _fuse(found: list[_Seen], typed: Callable[[list[_Seen]], tuple[int, float]]) -> list[Detection]:
    """One detection per object: the strongest estimate first, with the estimate of that type
    from each other view whose centroid's ray passes closest to its own, if within `RAY_GAP`
    (two of one view are two objects)."""
    order = sorted(found, key=lambda s: -s.score)
    used: set[int] = set()
    out = []
    for first in order:
        if id(first) in used:
            continue
        members = [first]
        for view in sorted({s.view for s in order} - {first.view}):
            near = [
                (_gap(s, first), k)
                for k, s in enumerate(order)
                if s.view == view and s.type_index == first.type_index and id(s) not in used
            ]
            if near and min(near)[0] < RAY_GAP:
                members.append(order[min(near)[1]])
        used.update(id(s) for s in members)
        kind, confidence = typed(members)
        name = TYPES[kind]
        rays = [_ray(s) for s in members]
        views = [s.keypoints for s in members]
        pose, error = _fitted(name, views, rays)
        if pose is None:
            continue
        out.append(
            Detection(
                name, pose, first.score, len(members), error, tuple(rays), confidence, tuple(views)
            )
        )
    return out


def _fitted(name: str, views: list[ViewKeypoints], rays: list[Ray]) -> tuple[Pose | None, float]:
    """The pose of an object of type `name` from the keypoints of the views that saw it, and
    its RMS reprojection error (pixels); None if PnP finds none."""
    fused = estimate_pose(name, views)
    if fused is None:
        return None, math.inf
    pose = fused.pose
    if len(rays) > 1:  # the centroid where the views' lines of sight meet
        pose = Pose(tuple(map(float, meeting_point(rays))), pose.orientation)
    # Objects here rest upright: the best upright yaw, unless a free pose explains the
    # keypoints better (a toppled object).
    level = upright_fit(name, views, pose.position)
    if robust_cost(name, views, level) <= robust_cost(name, views, pose):
        pose = level
    points = sum(int((~np.isnan(v.pixels).any(axis=1)).sum()) for v in views)
    return pose, math.sqrt(robust_cost(name, views, pose) / max(points, 1))


def _apart(detections: list[Detection]) -> list[Detection]:
    """Two objects cannot fill one space. Detections that fill one (`settle.same_place`) are
    one object found twice,
    mostly once in each look-alike type's maps; the one whose type the colour network is surest
    of is kept (then the stronger)."""
    kept: list[Detection] = []
    for d in sorted(detections, key=lambda d: (-d.type_confidence, -d.score)):
        if not any(same_place(d.type_name, d.pose, k.type_name, k.pose) for k in kept):
            kept.append(d)
    return kept


def _ray(s: _Seen) -> Ray:
    """The line of sight through the instance's centroid: origin and unit direction."""
    camera = s.keypoints.camera
    u, v = s.keypoints.pixels[-1]
    local = np.linalg.solve(camera.matrix, np.array([u, v, 1.0]))
    direction = camera.world_to_camera[:3, :3].T @ local
    return camera.eye, direction / np.linalg.norm(direction)


def _gap(a: _Seen, b: _Seen) -> float:
    """How far apart two instances' centroid rays pass (m); infinite when they meet behind a
    camera or where no object can be (off the table, under it, high above it)."""
    (pa, da), (pb, db) = _ray(a), _ray(b)
    w = pa - pb
    cross = da @ db
    denom = 1.0 - cross**2
    if denom < 1e-9:  # parallel lines of sight
        return float("inf")
    ta = (cross * (db @ w) - (da @ w)) / denom
    tb = ((db @ w) - cross * (da @ w)) / denom
    qa, qb = pa + ta * da, pb + tb * db
    meet = (qa + qb) / 2
    plausible = TABLE.contains(meet[0], meet[1]) and TABLE.z - 0.05 < meet[2] < TOP_Z
    if ta <= 0 or tb <= 0 or not plausible:
        return float("inf")
    return float(np.linalg.norm(qa - qb))
