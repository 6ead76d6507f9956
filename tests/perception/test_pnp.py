"""PnP's scoring of many poses at once: each pose scores exactly as the keypoints a camera
names for it alone (`keypoints.view_keypoints`), so batching changes no estimate."""

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.perception.keypoints import PinholeCamera, cuboid, view_keypoints
from hsgplan.perception.pnp import (
    MIN_POINTS,
    ViewKeypoints,
    _residuals_many,
    estimate_pose,
    robust_cost,
    solvable,
    upright_fit,
)
from hsgplan.perception.vocabulary import Vocabulary
from hsgplan.scene_graph.geometry import Pose

CAMERAS = [PinholeCamera.of(c) for c in Vocabulary(KITCHEN).views]
POSES = [
    Pose.from_xyz_yaw(0.45, 0.1, 0.05, 0.7),
    Pose.from_xyz_yaw(0.30, -0.2, 0.15, -2.9),
    Pose((0.5, 0.0, 0.1), (0.0, 1.0, 0.0, 0.0)),  # upside down
    Pose((0.4, 0.3, 0.2), (0.3, -0.2, 0.5, 0.787)),
]


@pytest.mark.parametrize("type_name", ["cherries", "butter", "popcorn"])
def test_many_poses_score_exactly_as_each_alone(type_name):
    t = KITCHEN.object_type(type_name)
    rng = np.random.default_rng(3)
    views = []
    for camera in CAMERAS[:3]:
        pixels = rng.uniform(0, 240, size=(9, 2))
        pixels[rng.random(9) < 0.3] = np.nan
        views.append(ViewKeypoints(camera, pixels))
    many = _residuals_many(t, views, np.stack([p.matrix() for p in POSES]))
    for pose, row in zip(POSES, many, strict=True):
        alone = [
            (view_keypoints(t, pose, v.camera) - v.pixels)[~np.isnan(v.pixels).any(axis=1)]
            for v in views
        ]
        assert np.array_equal(row, np.concatenate([a.ravel() for a in alone]))


def test_the_upright_fit_finds_the_yaw_the_keypoints_were_made_at():
    t = KITCHEN.object_type("butter")
    truth = Pose.from_xyz_yaw(0.45, 0.1, 0.012, 0.7)
    views = [ViewKeypoints(c, view_keypoints(t, truth, c)) for c in CAMERAS[:3]]
    fit = upright_fit(t, views, truth.position)
    assert robust_cost(t, views, fit) < 1.0


@pytest.mark.parametrize("found", [MIN_POINTS - 1, MIN_POINTS, 9])
def test_a_view_is_solvable_exactly_where_its_estimate_is_found(found):
    t = KITCHEN.object_type("popcorn")
    pixels = view_keypoints(t, POSES[0], CAMERAS[0])
    pixels[found:] = np.nan
    view = ViewKeypoints(CAMERAS[0], pixels)
    assert solvable(t, view) == (estimate_pose(t, [view]) is not None) == (found >= MIN_POINTS)


def test_the_kept_cuboid_cannot_be_changed_by_a_caller():
    with pytest.raises(ValueError):
        cuboid(KITCHEN.object_type("butter"))[0, 0] = 1.0


def test_the_fit_to_every_view_lowers_the_error_of_the_best_views_own_fit():
    t = KITCHEN.object_type("popcorn")
    rng = np.random.default_rng(2)
    views = [
        ViewKeypoints(c, view_keypoints(t, POSES[0], c) + rng.normal(0, 2.0, (9, 2)))
        for c in CAMERAS[:3]
    ]
    alone = estimate_pose(t, views, rounds=0)
    refined = estimate_pose(t, views, rounds=3)
    assert alone is not None and refined is not None
    assert refined.points == alone.points == 27
    assert refined.reprojection_px < alone.reprojection_px
    # without rounds, the estimate is one view's own fit
    assert any(
        np.allclose(estimate_pose(t, [v], rounds=0).pose.matrix(), alone.pose.matrix())
        for v in views
    )


def test_a_camera_is_at_anothers_eye_as_allclose_says():
    a = CAMERAS[0]
    for shift, same in ((0.0, True), (1e-9, True), (1e-3, False)):
        moved = PinholeCamera(a.matrix, a.world_to_camera.copy(), a.width, a.height)
        moved.world_to_camera[0, 3] += shift
        assert moved.at_eye_of(a) == np.allclose(moved.eye, a.eye) == same
