"""An object's pose from its keypoints in one or several fixed views (OpenCV's PnP).

DOPE's last step: with the cuboid known (the object type's size), the pose that projects it
onto the detected keypoints is the solution of a perspective-n-point problem. Views are fused
as the paper fuses its real robot's viewpoints: each view's estimate is refined by minimising
the reprojection error over the keypoints of every view at once, starting from the view whose
own fit is best. Each view names the keypoints by its own canonical look-alike of the pose
(`perception.keypoints.canonical_rotation`), so the refit projects, for each view, the cuboid of
that view's look-alike of the pose being fitted.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from hsgplan.domain.world import ObjectType
from hsgplan.perception.keypoints import PinholeCamera, canonical_rotation, cuboid
from hsgplan.scene_graph.geometry import Pose

MIN_POINTS = 5  # solvePnP's iterative solver needs 4; one more guards against a bad peak
# A keypoint further than this from where a pose projects it counts as this far: one wrong
# peak should not outweigh the keypoints that agree.
OUTLIER_PX = 8.0
YAWS = 90  # upright yaws tried, over the half turn a box looks the same after


@dataclass(frozen=True)
class ViewKeypoints:
    """An object's keypoints as one view saw them.

    Attributes:
        camera: the view.
        pixels: [9, 2] pixel coordinates, NaN where a keypoint was not found.
    """

    camera: PinholeCamera
    pixels: np.ndarray


@dataclass(frozen=True)
class PoseEstimate:
    pose: Pose
    reprojection_px: float  # root mean square over the keypoints used, all views
    points: int  # keypoints used, all views


def estimate_pose(t: ObjectType, views: list[ViewKeypoints]) -> PoseEstimate | None:
    """An object of type `t`: its pose in the world from its keypoints in the given views;
    None when no view has `MIN_POINTS` keypoints."""
    model = cuboid(t)
    fits = []
    for view in views:
        found = ~np.isnan(view.pixels).any(axis=1)
        if found.sum() < MIN_POINTS:
            continue
        ok, rvec, tvec = cv2.solvePnP(
            model[found], view.pixels[found], view.camera.matrix, None, flags=cv2.SOLVEPNP_EPNP
        )
        if not ok:
            continue
        ok, rvec, tvec = cv2.solvePnP(
            model[found],
            view.pixels[found],
            view.camera.matrix,
            None,
            rvec,
            tvec,
            useExtrinsicGuess=True,
            flags=cv2.SOLVEPNP_ITERATIVE,
        )
        if ok:
            world = view.camera.camera_to_world() @ _matrix(rvec, tvec)
            fits.append((_error(t, views, world), world))
    if not fits:
        return None
    best = min(fits, key=lambda f: f[0][0])[1]
    fused = _refine(t, views, best)
    world = min((best, fused), key=lambda m: _error(t, views, m)[0])
    rms, used = _error(t, views, world)
    return PoseEstimate(Pose.from_matrix(world), rms, used)


def robust_cost(t: ObjectType, views: list[ViewKeypoints], pose: Pose) -> float:
    """Squared reprojection error over every view's keypoints, each capped at `OUTLIER_PX`."""
    r = _residuals(t, views, pose.matrix()).reshape(-1, 2)
    return float(np.minimum((r**2).sum(axis=1), OUTLIER_PX**2).sum())


def upright_fit(t: ObjectType, views: list[ViewKeypoints], position: tuple[float, ...]) -> Pose:
    """The upright pose at `position` whose yaw best explains every view's keypoints
    (`robust_cost`), over `YAWS` yaws (a can's cuboid is named by the view: any yaw will do)."""
    yaws = np.linspace(0.0, np.pi, YAWS, endpoint=False)
    return min(
        (Pose.from_xyz_yaw(*position, float(y)) for y in yaws),
        key=lambda p: robust_cost(t, views, p),
    )


def _matrix(rvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = cv2.Rodrigues(rvec)[0]
    m[:3, 3] = tvec.ravel()
    return m


def _residuals(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> np.ndarray:
    model, position = cuboid(t), world[:3, 3]
    out = []
    for view in views:
        found = ~np.isnan(view.pixels).any(axis=1)
        rotation = canonical_rotation(t, world[:3, :3], position, view.camera.eye)
        points = model[found] @ rotation.T + position
        out.append((view.camera.project(points) - view.pixels[found]).ravel())
    return np.concatenate(out) if out else np.zeros(0)


def _error(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> tuple[float, int]:
    r = _residuals(t, views, world)
    return (float(np.sqrt(np.mean(r**2))) if r.size else float("inf")), r.size // 2


def _refine(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> np.ndarray:
    """Gauss-Newton on the pose (rotation vector, translation) over every view's keypoints."""
    rvec, tvec = cv2.Rodrigues(world[:3, :3])[0].ravel(), world[:3, 3].copy()
    x = np.concatenate([rvec, tvec])
    for _ in range(10):
        r = _residuals(t, views, _matrix(x[:3], x[3:]))
        jac = np.empty((r.size, 6))
        for i in range(6):
            step = np.zeros(6)
            step[i] = 1e-6
            jac[:, i] = (_residuals(t, views, _matrix(*np.split(x + step, 2))) - r) / 1e-6
        dx = np.linalg.lstsq(jac, -r, rcond=None)[0]
        x = x + dx
        if np.linalg.norm(dx) < 1e-9:
            break
    return _matrix(x[:3], x[3:])
