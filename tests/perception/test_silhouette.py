"""A box's yaw checked by its silhouette (`perception.silhouette`), on rendered scenes with the
shipped colour network: detections at the true poses stay within f_p's target, a box turned a
quarter or 21 degrees off is turned back within it, and what is not checked is left alone."""

import math
from dataclasses import replace

import numpy as np
import pytest

from hsgplan.domain.kitchen import KITCHEN
from hsgplan.paths import PERCEPTION_CHECKPOINT
from hsgplan.perception.colour import FOLDER, load_colour
from hsgplan.perception.detection import Detection
from hsgplan.perception.keypoints import PinholeCamera
from hsgplan.perception.pnp import ViewKeypoints
from hsgplan.perception.silhouette import yaw_checked
from hsgplan.perception.synthetic import render_sample
from hsgplan.perception.train import MIN_VISIBLE
from hsgplan.perception.vocabulary import kitchen_vocabulary
from hsgplan.scene_graph.geometry import Pose, rotation_apart, yaw_quat
from hsgplan.sim.outcome import BELIEF_TURNED

SEEN_BY = 2  # views that see a box well, for it to be checked here


def _turned(pose: Pose, degrees: float) -> Pose:
    return Pose(pose.position, yaw_quat(pose.yaw + math.radians(degrees)))


@pytest.fixture(scope="module")
def colour():
    return load_colour(PERCEPTION_CHECKPOINT / FOLDER)


def _detections(sample):
    """Each object of a rendered sample detected at its true pose by the views it is in sight
    in."""
    out = []
    for i, name in enumerate(sample.objects):
        p = sample.poses[i]
        pose = Pose(tuple(map(float, p[:3])), tuple(map(float, p[3:])))
        views = tuple(
            ViewKeypoints(PinholeCamera.of(c), sample.keypoints[v, i])
            for v, c in enumerate(sample.cameras)
            if sample.visible[v, i] >= MIN_VISIBLE
        )
        out.append(Detection(KITCHEN.type_of(name), pose, 1.0, len(views), 0.0, keypoints=views))
    return out


def _boxes(found):
    return [
        k
        for k, d in enumerate(found)
        if d.type_name in ("butter", "cream_cheese", "popcorn")
        and d.pose.tilt < 0.1
        and len(d.keypoints) >= SEEN_BY
    ]


@pytest.mark.parametrize("index", [1, 2, 3])
@pytest.mark.parametrize("turn", [90.0, 21.0])
def test_true_poses_stay_and_a_box_turned_off_turns_back(colour, index, turn):
    sample = render_sample(0, index, KITCHEN)
    assert sample is not None
    found = _detections(sample)
    boxes = _boxes(found)
    if not boxes:
        pytest.skip("no upright box in sight of two views in this sample")
    types = kitchen_vocabulary().types
    checked = yaw_checked(colour, types, KITCHEN, sample.images, sample.cameras, found)
    for a, b in zip(checked, found, strict=True):
        assert a.pose.position == b.pose.position
        assert rotation_apart(a.pose, b.pose, False) <= BELIEF_TURNED  # within f_p's target
    k = boxes[0]
    wrong = [*found[:k], replace(found[k], pose=_turned(found[k].pose, turn)), *found[k + 1 :]]
    back = yaw_checked(colour, types, KITCHEN, sample.images, sample.cameras, wrong)
    assert rotation_apart(wrong[k].pose, found[k].pose, False) > 2 * BELIEF_TURNED
    assert rotation_apart(back[k].pose, found[k].pose, False) <= BELIEF_TURNED


def test_cans_tilted_boxes_and_boxes_no_view_found_are_not_checked(colour):
    sample = render_sample(0, 1, KITCHEN)
    found = _detections(sample)
    turned = [replace(d, pose=_turned(d.pose, 90.0)) for d in found]
    unseen = [replace(d, keypoints=()) for d in turned]
    types = kitchen_vocabulary().types
    # no view found any: nothing is read, nothing turns
    kept = yaw_checked(colour, types, KITCHEN, sample.images, sample.cameras, unseen)
    assert [d.pose for d in kept] == [d.pose for d in unseen]
    tilted = Pose((0.5, 0.0, 0.05), (math.sin(0.3), 0.0, 0.0, math.cos(0.3)))
    lying = [replace(d, pose=tilted) if d.type_name == "popcorn" else d for d in found]
    kept = yaw_checked(colour, types, KITCHEN, sample.images, sample.cameras, lying)
    assert all(d.pose == tilted for d in kept if d.type_name == "popcorn") and all(
        np.allclose(a.pose.orientation, b.pose.orientation)
        for a, b in zip(kept, lying, strict=True)
        if KITCHEN.object_type(a.type_name).kind.value == "can"
    )
