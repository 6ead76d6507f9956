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

import math
from dataclasses import dataclass

import cv2
import numpy as np

from hsgplan.domain.world import Kind, ObjectType
from hsgplan.perception.keypoints import PinholeCamera, cuboid
from hsgplan.scene_graph.geometry import BOX_SYMMETRIES, Pose

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
    fits = []
    for view in views:
        if (camera_pose := _view_fit(t, view)) is not None:
            world = view.camera.camera_to_world() @ camera_pose
            fits.append((_error(t, views, world), world))
    if not fits:
        return None
    best = min(fits, key=lambda f: f[0][0])[1]
    fused = _refine(t, views, best)
    world = min((best, fused), key=lambda m: _error(t, views, m)[0])
    rms, used = _error(t, views, world)
    return PoseEstimate(Pose.from_matrix(world), rms, used)


def solvable(t: ObjectType, view: ViewKeypoints) -> bool:
    """Whether PnP finds a pose of an object of type `t` from this view's keypoints alone
    (`estimate_pose` of the one view is then not None), without refining it: a look asks this
    of every instance every view finds."""
    return _view_fit(t, view) is not None


def _view_fit(t: ObjectType, view: ViewKeypoints) -> np.ndarray | None:
    """The object's pose in the camera's frame from one view's keypoints (EPnP, then refined
    by OpenCV's iterative solver), [4, 4]; None with under `MIN_POINTS` keypoints or no fit."""
    model = cuboid(t)
    found = ~np.isnan(view.pixels).any(axis=1)
    if found.sum() < MIN_POINTS:
        return None
    ok, rvec, tvec = cv2.solvePnP(
        model[found], view.pixels[found], view.camera.matrix, None, flags=cv2.SOLVEPNP_EPNP
    )
    if not ok:
        return None
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
    return _matrix(rvec, tvec) if ok else None


def robust_cost(t: ObjectType, views: list[ViewKeypoints], pose: Pose) -> float:
    """Squared reprojection error over every view's keypoints, each capped at `OUTLIER_PX`."""
    return float(_robust_costs(t, views, pose.matrix()[None])[0])


def upright_fit(t: ObjectType, views: list[ViewKeypoints], position: tuple[float, ...]) -> Pose:
    """The upright pose at `position` whose yaw best explains every view's keypoints
    (`robust_cost`), over `YAWS` yaws (a can's cuboid is named by the view: any yaw will do).
    The yaws are scored together, as one array per view."""
    yaws = np.linspace(0.0, np.pi, YAWS, endpoint=False)
    poses = [Pose.from_xyz_yaw(*position, float(y)) for y in yaws]
    costs = _robust_costs(t, views, np.stack([p.matrix() for p in poses]))
    return poses[int(np.argmin(costs))]  # the first of equals, as `min` takes


def _robust_costs(t: ObjectType, views: list[ViewKeypoints], worlds: np.ndarray) -> np.ndarray:
    r = _residuals_many(t, views, worlds)
    squared = (r.reshape(len(worlds), -1, 2) ** 2).sum(axis=2)
    return np.minimum(squared, OUTLIER_PX**2).sum(axis=1)


def _matrix(rvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = cv2.Rodrigues(rvec)[0]
    m[:3, 3] = tvec.ravel()
    return m


def _residuals(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> np.ndarray:
    return _residuals_many(t, views, world[None])[0]


def _residuals_many(t: ObjectType, views: list[ViewKeypoints], worlds: np.ndarray) -> np.ndarray:
    """Each pose's reprojection residuals over every view's found keypoints, the cuboid named
    by each view's look-alike of the pose (`keypoints.canonical_rotation`, here for many poses
    at once): [N, 4, 4] -> [N, 2 * keypoints found]."""
    model, positions = cuboid(t), worlds[:, :3, 3]
    rotations = worlds[:, :3, :3].copy()
    upside_down = rotations[:, 2, 2] < 0
    rotations[upside_down] = rotations[upside_down] @ BOX_SYMMETRIES[1]
    out = []
    for view in views:
        found = ~np.isnan(view.pixels).any(axis=1)
        toward = view.camera.eye - positions  # [N, 3]
        r = rotations
        # the operations, and libm's trigonometry, of `canonical_rotation` for one pose, so
        # that a pose scores here exactly as it scores alone
        if t.kind is Kind.CAN:  # turned about its axis to face the view
            local = (r.transpose(0, 2, 1) @ toward[:, :, None])[:, :, 0]
            phi = [math.atan2(a, b) for a, b in local[:, 1::-1]]
            cos, sin = np.array([math.cos(f) for f in phi]), np.array([math.sin(f) for f in phi])
            spin = np.zeros((len(phi), 3, 3))
            spin[:, 0, 0], spin[:, 0, 1], spin[:, 1, 0], spin[:, 1, 1] = cos, -sin, sin, cos
            spin[:, 2, 2] = 1.0
            r = r @ spin
        else:  # its +x face towards the view
            away = (r[:, :, 0] * toward).sum(axis=1) < 0
            r = r.copy()
            r[away] = r[away] @ BOX_SYMMETRIES[3]
        points = model[found] @ r.transpose(0, 2, 1) + positions[:, None, :]
        w = view.camera.world_to_camera
        p = (points @ w[:3, :3].T + w[:3, 3]) @ view.camera.matrix.T
        pixels = p[..., :2] / p[..., 2:3]
        out.append((pixels - view.pixels[found]).reshape(len(worlds), -1))
    return np.concatenate(out, axis=1) if out else np.zeros((len(worlds), 0))


def _error(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> tuple[float, int]:
    r = _residuals(t, views, world)
    return (float(np.sqrt(np.mean(r**2))) if r.size else float("inf")), r.size // 2


def _refine(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> np.ndarray:
    """Gauss-Newton on the pose (rotation vector, translation) over every view's keypoints;
    the pose and its six nudged copies scored together for the forward differences."""
    rvec, tvec = cv2.Rodrigues(world[:3, :3])[0].ravel(), world[:3, 3].copy()
    x = np.concatenate([rvec, tvec])
    nudges = np.vstack([np.zeros(6), np.eye(6) * 1e-6])
    for _ in range(10):
        worlds = np.stack([_matrix(v[:3], v[3:]) for v in x + nudges])
        r_all = _residuals_many(t, views, worlds)
        r = r_all[0]
        jac = ((r_all[1:] - r) / 1e-6).T
        dx = np.linalg.lstsq(jac, -r, rcond=None)[0]
        x = x + dx
        if np.linalg.norm(dx) < 1e-9:
            break
    return _matrix(x[:3], x[3:])
