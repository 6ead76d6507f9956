"""An object's pose from its keypoints in one or several fixed views (OpenCV's PnP).

DOPE's last step: with the cuboid known (the object type's size), the pose that projects it
onto the detected keypoints is the solution of a perspective-n-point problem. Views are fused
as the paper fuses its real robot's viewpoints: each view's own fit is scored on the keypoints
of every view, and the best is the estimate; `rounds` of Levenberg-Marquardt then refine it
over them all (`PerceptionRules.refine_rounds`; none shipped, as the tune split chose:
configs/decisions.toml). Each view names the keypoints by its own canonical look-alike of the
pose (`perception.keypoints.canonical_rotation`), so a fit projects, for each view, the cuboid
of that view's look-alike of the pose being fitted.
"""

from __future__ import annotations

import functools
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
NUDGE = 1e-6  # rad and m: the forward differences' step
DAMPING, MAX_DAMPING = 1e-3, 1e6  # Levenberg-Marquardt's, relative to the normal equations
# rounds of the fit to every view's keypoints (`PerceptionRules.refine_rounds`)
REFINE_ROUNDS = 0
_TURNS = np.stack([cv2.Rodrigues(np.eye(3)[i] * NUDGE)[0] for i in range(3)])
# the upright yaws' poses at the origin, as `Pose.matrix` makes them: a look fits one per object
_UPRIGHT_YAWS = np.linspace(0.0, np.pi, YAWS, endpoint=False)
_UPRIGHT = np.stack([Pose.from_xyz_yaw(0.0, 0.0, 0.0, float(y)).matrix() for y in _UPRIGHT_YAWS])


@dataclass(frozen=True)
class ViewKeypoints:
    """An object's keypoints as one view saw them.

    Attributes:
        camera: the view.
        pixels: [9, 2] pixel coordinates, NaN where a keypoint was not found.
    """

    camera: PinholeCamera
    pixels: np.ndarray

    # a look fits each view twice, to keep it (`solvable`) and to fuse it (`estimate_pose`):
    # the fit of the view alone, [4, 4] in the camera's frame or None, kept by cuboid size
    @functools.cached_property
    def _fits(self) -> dict[tuple[float, ...], np.ndarray | None]:
        return {}

    # kept once per view: every pose a fit scores asks for them
    @functools.cached_property
    def found(self) -> np.ndarray:
        """Which keypoints the view found: [9] bool."""
        return ~np.isnan(self.pixels).any(axis=1)

    @functools.cached_property
    def found_pixels(self) -> np.ndarray:
        """The found keypoints' pixels: [found, 2]."""
        return self.pixels[self.found]


@dataclass(frozen=True)
class PoseEstimate:
    pose: Pose
    reprojection_px: float  # root mean square over the keypoints used, all views
    points: int  # keypoints used, all views


def estimate_pose(
    t: ObjectType, views: list[ViewKeypoints], rounds: int = REFINE_ROUNDS
) -> PoseEstimate | None:
    """An object of type `t`: its pose in the world from its keypoints in the given views,
    the best view's fit refined by `rounds` rounds over them all; None when no view has
    `MIN_POINTS` keypoints."""
    fits = [
        view.camera.camera_to_world() @ fit
        for view in views
        if (fit := _view_fit(t, view)) is not None
    ]
    if not fits:
        return None
    errors = _errors(t, views, np.stack(fits))  # each view's fit scored on every view at once
    k = int(np.argmin(errors))  # the first of equals, as `min` takes
    best, rms, used = fits[k], float(errors[k]), sum(int(v.found.sum()) for v in views)
    if rounds:  # a refined fit is never worse: a step is taken only where it lowers the cost
        best = _refine(t, views, best, rounds)
        rms, used = _error(t, views, best)
    return PoseEstimate(Pose.from_matrix(best), rms, used)


def solvable(t: ObjectType, view: ViewKeypoints) -> bool:
    """Whether PnP finds a pose of an object of type `t` from this view's keypoints alone
    (`estimate_pose` of the one view is then not None), without refining it: a look asks this
    of every instance every view finds."""
    return _view_fit(t, view) is not None


def _view_fit(t: ObjectType, view: ViewKeypoints) -> np.ndarray | None:
    """The object's pose in the camera's frame from one view's keypoints (EPnP, then refined
    by OpenCV's iterative solver), [4, 4]; None with under `MIN_POINTS` keypoints or no fit."""
    size = tuple(t.size)
    if size not in view._fits:
        view._fits[size] = _fit_alone(cuboid(t), view)
    return view._fits[size]


def _fit_alone(model: np.ndarray, view: ViewKeypoints) -> np.ndarray | None:
    found = view.found
    if found.sum() < MIN_POINTS:
        return None
    ok, rvec, tvec = cv2.solvePnP(
        model[found], view.found_pixels, view.camera.matrix, None, flags=cv2.SOLVEPNP_EPNP
    )
    if not ok:
        return None
    ok, rvec, tvec = cv2.solvePnP(
        model[found],
        view.found_pixels,
        view.camera.matrix,
        None,
        rvec,
        tvec,
        useExtrinsicGuess=True,
        flags=cv2.SOLVEPNP_ITERATIVE,
    )
    if not ok:
        return None
    fit = _matrix(rvec, tvec)
    fit.setflags(write=False)
    return fit


def robust_cost(t: ObjectType, views: list[ViewKeypoints], pose: Pose) -> float:
    """Squared reprojection error over every view's keypoints, each capped at `OUTLIER_PX`."""
    return float(_robust_costs(t, views, pose.matrix()[None])[0])


def upright_fit(t: ObjectType, views: list[ViewKeypoints], position: tuple[float, ...]) -> Pose:
    """The upright pose at `position` whose yaw best explains every view's keypoints
    (`robust_cost`), over `YAWS` yaws (a can's cuboid is named by the view: any yaw will do).
    The yaws are scored together, as one array per view."""
    worlds = _UPRIGHT.copy()
    worlds[:, :3, 3] = position
    costs = _robust_costs(t, views, worlds)
    # the first of equals, as `min` takes
    return Pose.from_xyz_yaw(*position, float(_UPRIGHT_YAWS[int(np.argmin(costs))]))


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
        found = view.found
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
        out.append((pixels - view.found_pixels).reshape(len(worlds), -1))
    return np.concatenate(out, axis=1) if out else np.zeros((len(worlds), 0))


def _error(t: ObjectType, views: list[ViewKeypoints], world: np.ndarray) -> tuple[float, int]:
    r = _residuals(t, views, world)
    return (float(np.sqrt(np.mean(r**2))) if r.size else float("inf")), r.size // 2


def _errors(t: ObjectType, views: list[ViewKeypoints], worlds: np.ndarray) -> np.ndarray:
    """Each pose's root mean square reprojection error over every view's keypoints: [N]."""
    r = _residuals_many(t, views, worlds)
    return np.sqrt(np.mean(r**2, axis=1)) if r.shape[1] else np.full(len(worlds), np.inf)


def _refine(
    t: ObjectType, views: list[ViewKeypoints], world: np.ndarray, rounds: int
) -> np.ndarray:
    """Levenberg-Marquardt on the pose over every view's keypoints, for `rounds` rounds: the
    rotation nudged about the world's axes (a rotation vector of the whole rotation made
    Gauss-Newton step by radians, then diverge), the pose and its six nudged copies scored
    together for the forward differences; a step is taken only where it lowers the cost."""
    rotation, position = world[:3, :3], world[:3, 3]
    r = _residuals_many(t, views, world[None])[0]
    cost, damping = float(r @ r), DAMPING
    for _ in range(rounds):
        nudged = np.tile(world, (7, 1, 1))
        nudged[1:4, :3, :3] = _TURNS @ rotation
        nudged[4:7, :3, 3] += np.eye(3) * NUDGE
        r_all = _residuals_many(t, views, nudged)
        jac = ((r_all[1:] - r_all[0]) / NUDGE).T
        normal, gradient = jac.T @ jac, jac.T @ r_all[0]
        while damping <= MAX_DAMPING:
            step = np.linalg.solve(normal + damping * np.diag(np.diag(normal) + 1e-12), -gradient)
            tried = np.eye(4)
            tried[:3, :3] = cv2.Rodrigues(step[:3])[0] @ rotation
            tried[:3, 3] = position + step[3:]
            r = _residuals_many(t, views, tried[None])[0]
            if (c := float(r @ r)) < cost:
                world, rotation, position, cost = tried, tried[:3, :3], tried[:3, 3], c
                damping = max(damping / 10, 1e-9)
                break
            damping *= 10
        else:
            break  # no step lowers the cost: a minimum
    return world
