"""Cuboid keypoints, the pinhole model of the renderer's cameras, and PnP: round trips on
synthetic poses, and the model checked against what PyBullet renders."""

import math

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.evaluation.perception_eval import rotation_error
from hsgplan.perception.keypoints import (
    KEYPOINTS,
    PinholeCamera,
    cuboid,
    in_world,
    view_keypoints,
)
from hsgplan.perception.pnp import ViewKeypoints, estimate_pose
from hsgplan.scene_graph.geometry import Pose
from hsgplan.sim.render import FRONT, SIDE_A, Camera

VIEWS = [PinholeCamera.of(FRONT), PinholeCamera.of(SIDE_A)]


def _pose(rng: np.random.Generator, obj: str) -> Pose:
    x, y = rng.uniform(0.3, 0.65), rng.uniform(-0.18, 0.18)
    return Pose.from_xyz_yaw(
        x, y, KITCHEN.object_type(obj).height / 2, rng.uniform(-math.pi, math.pi)
    )


def test_the_cuboid_has_eight_corners_and_its_centroid():
    points = cuboid(KITCHEN.object_type("cream_cheese"))
    assert points.shape == (KEYPOINTS, 3)
    assert np.allclose(points[8], 0) and np.allclose(points[:8].mean(axis=0), 0)
    assert np.allclose(points[:8].max(axis=0) * 2, KITCHEN.object_type("cream_cheese").size)


@pytest.mark.parametrize("obj", ["butter", "popcorn", "tomato_soup"])
def test_pnp_gives_back_the_pose_that_was_projected(obj):
    rng = np.random.default_rng(0)
    for _ in range(5):
        pose = _pose(rng, obj)
        views = [ViewKeypoints(c, view_keypoints(KITCHEN.object_type(obj), pose, c)) for c in VIEWS]
        for used in (views[:1], views[1:], views):
            found = estimate_pose(KITCHEN.object_type(obj), used)
            assert found is not None
            assert np.linalg.norm(np.subtract(found.pose.position, pose.position)) < 1e-4
            assert rotation_error(obj, pose, found.pose, KITCHEN) < 0.05  # up to the look-alikes
            assert found.reprojection_px < 1e-3


@pytest.mark.parametrize(("obj", "turns"), [("butter", (math.pi,)), ("cherries", (0.7, 2.0, 4.0))])
def test_look_alike_poses_have_the_same_keypoints_in_a_view(obj, turns):
    pose = Pose.from_xyz_yaw(0.5, 0.1, KITCHEN.object_type(obj).height / 2, 0.3)
    for c in VIEWS:
        named = view_keypoints(KITCHEN.object_type(obj), pose, c)
        for turn in turns:
            turned = Pose.from_xyz_yaw(*pose.position, 0.3 + turn)
            assert np.allclose(
                view_keypoints(KITCHEN.object_type(obj), turned, c), named, atol=1e-6
            )
        assert np.allclose(
            named[-1], c.project(in_world(KITCHEN.object_type(obj), pose))[-1]
        )  # the centroid


def test_two_views_with_noisy_or_missing_keypoints_still_place_the_object():
    rng = np.random.default_rng(1)
    obj = "cream_cheese"
    errors = []
    for _ in range(10):
        pose = _pose(rng, obj)
        views = []
        for c in VIEWS:
            pixels = view_keypoints(KITCHEN.object_type(obj), pose, c) + rng.normal(
                0.0, 1.0, (KEYPOINTS, 2)
            )
            pixels[rng.choice(KEYPOINTS, 2, replace=False)] = np.nan  # two peaks not found
            views.append(ViewKeypoints(c, pixels))
        found = estimate_pose(KITCHEN.object_type(obj), views)
        assert found is not None and found.points == 2 * (KEYPOINTS - 2)
        errors.append(np.linalg.norm(np.subtract(found.pose.position, pose.position)))
    assert np.median(errors) < 0.01


def test_a_view_with_too_few_keypoints_gives_no_pose():
    c = VIEWS[0]
    pixels = c.project(in_world(KITCHEN.object_type("butter"), Pose.from_xyz_yaw(0.5, 0.0, 0.012)))
    pixels[:5] = np.nan
    assert estimate_pose(KITCHEN.object_type("butter"), [ViewKeypoints(c, pixels)]) is None


def test_the_pinhole_model_projects_where_pybullet_renders():
    from hsgplan.sim.scene import Scene

    obj = "popcorn"
    pose = Pose.from_xyz_yaw(0.5, 0.05, KITCHEN.object_type(obj).height / 2 + 0.001, 0.4)
    with Scene((obj,), seed=0, world=KITCHEN) as scene:
        scene.set_pose(obj, pose)
        # another size and field of view than the demo's, from the side
        side = Camera(320, 240, (0.55, -0.9, 0.7), (0.5, 0.0, 0.05), 45.0)
        for camera in (FRONT, side):
            bc = scene.bc
            view = bc.computeViewMatrix(camera.eye, camera.target, (0, 0, 1))
            proj = bc.computeProjectionMatrixFOV(
                camera.fov, camera.width / camera.height, 0.05, 4.0
            )
            *_, seg = bc.getCameraImage(
                camera.width, camera.height, view, proj, renderer=bc.ER_TINY_RENDERER
            )
            mask = np.asarray(seg).reshape(camera.height, camera.width) == scene.bodies[obj]
            rows, cols = np.nonzero(mask)
            pixels = PinholeCamera.of(camera).project(in_world(KITCHEN.object_type(obj), pose))
            # the silhouette's extent is the projected cuboid's, to a pixel or two
            assert rows.size > 100
            assert abs(cols.min() - pixels[:, 0].min()) < 2.5
            assert abs(cols.max() - pixels[:, 0].max()) < 2.5
            assert abs(rows.max() - pixels[:, 1].max()) < 2.5
