"""Fusing the views' detections of one object into one, fitted to all of their keypoints."""

from __future__ import annotations

import math
from collections.abc import Callable

from hsgplan.domain.world import ObjectType, World
from hsgplan.perception.detection import Detection
from hsgplan.perception.fusion import Seen, grouped, line_of_sight
from hsgplan.perception.pnp import (
    REFINE_ROUNDS,
    ViewKeypoints,
    estimate_pose,
    robust_cost,
    upright_fit,
)
from hsgplan.perception.rules import SHIPPED, PerceptionRules
from hsgplan.perception.settle import Ray, meeting_point
from hsgplan.scene_graph.geometry import Pose

# A free (tilted) fit stands for a toppled object only where its reprojection cost is at most
# this fraction of the best upright fit's. At 1 (no preference for upright), a thin box half
# hidden under a can was often fitted a little better tilted, was no carrier to settle on,
# and the can fell onto the table: symbolic match on 100 tuning scenes (seed 2) 0.66 at 1,
# 0.69 at 0.5 and at 0.25, and 0.69 always upright. One view alone never says toppled: a can
# under a box seen by one view was fitted tilted and carried nothing (seed 4's scene 43; on
# 500 scenes of seeds 1 to 5, 1 scene better on seed 3, none worse).
TOPPLED_COST = 0.5


def fuse(
    found: list[Seen],
    typed: Callable[[list[Seen]], tuple[str, float]],
    world: World,
    rules: PerceptionRules = SHIPPED,
) -> list[Detection]:
    """One detection per object that the views' lines of sight group (`fusion.grouped`, by
    `rules`' gap and cliques), named by `typed` and fitted to every member's keypoints (its
    type's cuboid in `world`)."""
    out = []
    for members in grouped(found, world.table, rules.ray_gap, rules.cliques):
        name, confidence = typed(members)
        rays = [line_of_sight(s) for s in members]
        views = [s.keypoints for s in members]
        pose, error = fitted(world.object_type(name), views, rays, rules.refine_rounds)
        if pose is None:
            continue
        score = members[0].score
        out.append(
            Detection(name, pose, score, len(members), error, tuple(rays), confidence, tuple(views))
        )
    return out


def fitted(
    t: ObjectType, views: list[ViewKeypoints], rays: list[Ray], rounds: int = REFINE_ROUNDS
) -> tuple[Pose | None, float]:
    """The pose of an object of type `t` from the keypoints of the views that saw it (PnP's
    fit refined by `rounds` rounds over them all), and its RMS reprojection error (pixels);
    None if PnP finds none."""
    fused = estimate_pose(t, views, rounds)
    if fused is None:
        return None, math.inf
    pose = fused.pose
    if len(rays) > 1:  # the centroid where the views' lines of sight meet
        pose = Pose(tuple(map(float, meeting_point(rays))), pose.orientation)
    # Objects here rest upright: the best upright yaw, unless a free pose explains several
    # views' keypoints much better (a toppled object; see `TOPPLED_COST`).
    level = upright_fit(t, views, pose.position)
    cost = robust_cost(t, views, level)
    if len(views) > 1 and (free := robust_cost(t, views, pose)) < TOPPLED_COST * cost:
        cost = free
    else:
        pose = level
    points = sum(int(v.found.sum()) for v in views)
    return pose, math.sqrt(cost / max(points, 1))
