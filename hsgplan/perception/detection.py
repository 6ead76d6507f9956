"""What f_p found of one object: the estimator makes them, the lone-view tests and the observer
read them."""

from __future__ import annotations

from dataclasses import dataclass

from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.settle import Ray
from hsgplan.scene_graph.geometry import Pose


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
    # the colour network's probability of the type, among every type (1: no colour network, or
    # no member view's centroid patch in its image: then it wins `apart.apart` over measured ones)
    type_confidence: float = 1.0
    keypoints: tuple[ViewKeypoints, ...] = ()  # each view's keypoints behind it
    stacked: bool = False  # one of two thin boxes that the views saw as one (`STACK_BAND`)
    measured: Pose | None = None  # the pose before it was made to rest (`PoseEstimator.rest`)
